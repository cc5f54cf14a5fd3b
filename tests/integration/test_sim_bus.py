"""The Python helper for machine tests (tools/python/canopen_sensor_sim,
installed into the venv by tools/setup): its pytest fixture starts a
simulated bus of several nodes in one canopen-sensor process and drives
them through the control socket, while the canopen master sees them on
vcan0, or on python-can's udp_multicast bus where there is no vcan0 (the
fixture's default; integration.udp_bus runs this file so, in a private
network namespace) - the way a machine builder's own test would use it."""
import time

import canopen
import pytest

from canopen_sensor_sim import SimBus, SimError


def test_two_sensors_driven_from_the_test(sensor_bus, sensor_can_args):
    sim = sensor_bus(["inx360d@0x30", "jd2xxx@0x31"])
    net = canopen.Network()
    net.connect(**sensor_can_args)
    try:
        inx = net.add_node(0x30)
        jd = net.add_node(0x31)
        assert int.from_bytes(inx.sdo.upload(0x1000, 0), "little") & 0xFFFF == 410
        assert int.from_bytes(jd.sdo.upload(0x1000, 0), "little") & 0xFFFF == 410
        sim.set(0x30, x=12.5)
        time.sleep(0.1)
        # P+F: 0.1 deg a unit, no filter: the slope follows the input at once.
        assert int.from_bytes(inx.sdo.upload(0x6010, 0), "little", signed=True) == 125
        assert sim.get(0x30)["x"] == pytest.approx(12.5)
        assert sim.get(0x31)["nmt"] == "pre-operational"
        net.nmt.send_command(0x01)  # start every node
        time.sleep(0.1)
        assert sim.get(0x31)["nmt"] == "operational"
        with pytest.raises(SimError):
            sim.set(0x30, nosuchinput=1)
        with pytest.raises(SimError):
            sim.get(0x55)  # no such node
    finally:
        net.disconnect()


def test_restart_keeps_the_stored_set(sensor_bus, sensor_can_args):
    sim = sensor_bus(["inx360d@0x30"])
    net = canopen.Network()
    net.connect(**sensor_can_args)
    try:
        node = net.add_node(0x30)
        node.sdo.download(0x1017, 0, (250).to_bytes(2, "little"))  # P+F: stored at once
        sim.stop()
        sim.start()
        time.sleep(0.2)
        assert int.from_bytes(node.sdo.upload(0x1017, 0), "little") == 250
    finally:
        net.disconnect()


def test_misuse_is_refused(sensor_interface):
    with pytest.raises(SimError, match="a list of"):
        SimBus("jd1xxx@0x42", interface=sensor_interface)
    bus = SimBus(["jd1xxx@0x41"], interface=sensor_interface)
    try:
        bus.start()
        first = bus.proc
        with pytest.raises(SimError, match="running already"):
            bus.start()
        assert bus.proc is first and first.poll() is None
    finally:
        bus.close()
    assert first.poll() is not None  # no orphan left


def test_messages_that_misled(sensor_bus, sensor_interface):
    """An empty node list is named as such (it said "--product is
    missing"); a huge value is "not a number within" its limit (it said
    "line longer than 255 characters": 1e300 written out in full)."""
    with pytest.raises(SimError, match="nodes: an empty list"):
        sensor_bus([])
    sim = sensor_bus(["jd1xxx@0x43"])
    with pytest.raises(SimError, match=r"'z=1e\+300': not a number within \+-"):
        sim.set(0x43, z=1e300)
    with pytest.raises(SimError, match=r"'z=inf': not a number within \+-"):
        sim.set(0x43, z=float("inf"))
    sim.set(0x43, z=12.5)
    assert sim.get(0x43)["z"] == 12.5
