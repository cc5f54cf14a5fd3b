"""Gefran GSH-A end to end on vcan: single (node 0x13) and redundant (0x13 +
0x14, on one bus or one bus each), against the canopen master, which reads
the PDO mapping through SDO and decodes with the product's EDS."""
import time

import can
import canopen

from conftest import eds_od
from targets import period_fault




def checksum(d):
    return (sum(d[:7]) + 254) % 255


def test_single_autostart_pdo_and_mapping(sensor_factory, network, bus):
    sensor = sensor_factory("gsh-a")
    bus.clear()
    sensor.start()
    assert bus.wait_for(0x713, timeout=3, pred=lambda m: bytes(m.data) == b"\0")
    sensor.send("set length=52 angle=3.4")
    node = canopen.RemoteNode(0x13, eds_od("gsh-a", sensor.log.parent, 0x13))
    network.add_node(node)
    node.tpdo.read()  # the master reads 0x1800/0x1A00 over SDO
    pdo = node.tpdo[1]
    assert pdo.cob_id == 0x193 and pdo.trans_type == 254
    time.sleep(0.3)
    pdo.wait_for_reception(timeout=1)
    # Decoded through the EDS mapping as a CiA 301 master does: 0x6004 is
    # UNSIGNED16 as the manual's PDO text and mapping length say, and the
    # mapping covers all 8 bytes (alarm word, counter, checksum).
    assert [v.od.index for v in pdo.map] == [0x6004, 0x6810, 0x2110, 0x2111, 0x2112]
    assert pdo.length == 64
    assert pdo["Position value"].raw == 52
    assert pdo["Slope long16"].raw == 34
    assert pdo["Alarm"].raw == 0
    assert pdo["Checksum"].raw == checksum(pdo.data)
    assert pdo["Counter"].raw == pdo.data[6]
    bus.clear()
    frames = bus.collect(0x193, 1.05)
    # 100 ms, no NMT start needed; the period judged as test_targets does
    # (targets.period_fault: the median gap, a loose count).
    times = [f.timestamp for f in frames]
    assert period_fault(times, 100, 1.05) is None, period_fault(times, 100, 1.05)
    for a, b in zip(frames, frames[1:]):
        assert b.data[6] == (a.data[6] + 1) % 256
    for f in frames:
        assert len(f.data) == 8 and f.data[7] == checksum(f.data)
        assert bytes(f.data[:6]) == bytes.fromhex("340022000000")
    sensor.send("set field=30")
    time.sleep(0.2)
    m = bus.wait_for(0x193, timeout=1)
    assert m.data[4] == 0x20  # magnet field too low
    # The manual's table says wo; CiA 301's rw: 1 = saves on command.
    assert node.sdo.upload(0x1010, 1) == b"\x01\0\0\0"


def test_node_id_change_saved_and_power_cycled(sensor_factory, network, bus):
    sensor = sensor_factory("gsh-a")
    bus.clear()
    sensor.start()
    assert bus.wait_for(0x713, timeout=3)
    node = network.add_node(0x13, canopen.ObjectDictionary())
    node.sdo.download(0x3001, 0, b"\x06")
    node.sdo.download(0x1010, 1, b"save")
    assert sensor.stop() == 0
    bus.clear()
    sensor.start()
    assert bus.wait_for(0x706, timeout=3, pred=lambda m: bytes(m.data) == b"\0")
    assert bus.wait_for(0x186, timeout=1) is not None


def test_redundant_on_one_bus(sensor_factory, network, bus):
    sensor = sensor_factory("gsh-a-redundant")
    bus.clear()
    sensor.start()
    sensor.send("set length=52 angle=3.4")
    assert bus.wait_for(0x713, timeout=3) and bus.wait_for(0x714, timeout=3)
    time.sleep(0.3)
    bus.clear()
    f1 = bus.wait_for(0x193, timeout=1)
    f2 = bus.wait_for(0x194, timeout=1)
    assert int.from_bytes(f1.data[0:2], "little") == 52
    assert int.from_bytes(f2.data[0:2], "little") == 8000 - 52  # backwards
    assert int.from_bytes(f1.data[2:4], "little") == 34
    assert int.from_bytes(f2.data[2:4], "little") == 3600 - 34
    # Both nodes decoded through their EDS mapping give the manual's values.
    decoded = {}
    for nid in (0x13, 0x14):
        node = canopen.RemoteNode(nid, eds_od("gsh-a-redundant", sensor.log.parent, nid))
        network.add_node(node)
        node.tpdo.read()
        pdo = node.tpdo[1]
        pdo.wait_for_reception(timeout=1)
        assert len(pdo.data) * 8 == pdo.length == 64
        decoded[nid] = (pdo["Position value"].raw, pdo["Slope long16"].raw, pdo["Alarm"].raw)
    assert decoded == {0x13: (52, 34, 0), 0x14: (8000 - 52, 3600 - 34, 0)}
    n13 = network.add_node(0x13, canopen.ObjectDictionary())
    n14 = network.add_node(0x14, canopen.ObjectDictionary())
    n13.sdo.download(0x1800, 5, (200).to_bytes(2, "little"))
    assert int.from_bytes(n14.sdo.upload(0x1800, 5), "little") == 100
    n13.nmt.state = "STOPPED"
    time.sleep(0.3)
    bus.clear()
    assert bus.wait_for(0x193, timeout=0.5) is None
    assert bus.wait_for(0x194, timeout=0.5) is not None


def test_redundant_on_two_buses(sensor_factory, network, bus):
    other = can.Bus(interface="socketcan", channel="vcan1")
    try:
        sensor = sensor_factory("gsh-a-redundant", iface="vcan0,vcan1")
        bus.clear()
        sensor.start()
        assert bus.wait_for(0x713, timeout=3) is not None
        got = {}
        end = time.monotonic() + 1.5
        while time.monotonic() < end:
            m = other.recv(timeout=0.2)
            if m is not None:
                got.setdefault(m.arbitration_id, m)
        assert 0x714 in got and 0x194 in got  # channel 2 on its own bus
        assert bus.wait_for(0x194, timeout=0.5) is None  # and not on vcan0
        # SDO on the second bus reaches channel 2 only.
        other.send(can.Message(arbitration_id=0x614, data=bytes.fromhex("4001300000000000"),
                               is_extended_id=False))
        end = time.monotonic() + 1
        reply = None
        while time.monotonic() < end and reply is None:
            m = other.recv(timeout=0.2)
            if m is not None and m.arbitration_id == 0x594:
                reply = m
        assert reply is not None and bytes(reply.data) == bytes.fromhex("4F01300014000000")
    finally:
        other.shutdown()
