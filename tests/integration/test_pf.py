"""P+F INX360D / INY360D end to end on vcan0 against the canopen master,
which knows the sensor only from its EDS. Factory node-ID 1."""
import time

import pytest
from canopen.sdo.exceptions import SdoAbortedError

from conftest import boot as start_node

NODE = 1




def boot(sensor, network, bus, node_id=NODE):
    return start_node(sensor, network, bus, node_id)


def test_identity_segmented_name(sensor_factory, network, bus):
    node = boot(sensor_factory("iny360d"), network, bus)
    assert node.sdo["Manufacturer device name"].raw == "INY360D-F99-B16-V15"  # segmented
    assert node.sdo[0x1000].raw & 0xFFFF == 0x019A
    assert node.sdo[0x1010][1].raw == 3  # stores on command and by itself
    with pytest.raises(SdoAbortedError) as e:
        node.sdo.upload(0x1200, 0)  # the SDO COB-IDs are fixed: no 0x1200
    assert e.value.code == 0x06020000


def test_node_guarding_and_life_guarding(sensor_factory, network, bus):
    node = boot(sensor_factory("inx360d"), network, bus)
    node.tpdo.read()
    node.sdo[0x100C].raw = 100  # guard time, ms
    node.sdo[0x100D].raw = 3    # life time factor
    node.nmt.state = "OPERATIONAL"
    node.nmt.start_node_guarding(0.1)
    time.sleep(0.5)
    assert node.nmt.state == "OPERATIONAL"  # from the guard answers
    answers = [m for m in bus.collect(0x701, 0.5) if not m.is_remote_frame]
    toggles = [m.data[0] & 0x80 for m in answers]
    assert len(answers) >= 3 and all(a != b for a, b in zip(toggles, toggles[1:]))
    node.nmt.stop_node_guarding()
    err = node.emcy.wait(0x8130, timeout=2)  # life guard event after 300 ms
    assert err is not None and err.register == 0x11
    node.nmt.start_node_guarding(0.1)
    time.sleep(0.4)
    assert node.nmt.state == "PRE-OPERATIONAL"  # it went there by itself
    node.nmt.stop_node_guarding()


def test_rtr_pdo_decoded_through_eds(sensor_factory, network, bus):
    sensor = sensor_factory("iny360d")
    node = boot(sensor, network, bus)
    node.sdo[0x1800][2].raw = 0xFD  # on request only
    node.tpdo.read()
    pdo = node.tpdo[1]
    assert pdo.trans_type == 0xFD and len(pdo.map) == 2
    sensor.send("set x=131.7 y=231.2")
    node.nmt.state = "OPERATIONAL"
    time.sleep(0.2)
    bus.clear()
    assert bus.wait_for(0x181, timeout=0.3) is None
    pdo.remote_request()
    pdo.wait_for_reception(timeout=1)
    assert pdo["Slope long16"].raw == 1317
    assert pdo["Slope lateral16"].raw == 2312
    m = bus.wait_for(0x181, timeout=1)
    assert bytes(m.data) == bytes.fromhex("25050809")  # the manual's V11 frame


def test_zero_point_and_autostore_over_power_cut(sensor_factory, network, bus):
    sensor = sensor_factory("inx360d")
    node = boot(sensor, network, bus)
    sensor.send("set x=131.7")
    time.sleep(0.1)
    node.sdo["Slope long16 operating parameter"].raw = 2
    node.sdo["Slope long16 preset value"].raw = 0
    assert node.sdo["Slope long16 offset"].raw == 2283
    node.sdo["Differential slope long16 offset"].raw = -200
    assert node.sdo["Slope long16"].raw == 3400
    assert sensor.kill() == -9  # no save command was sent
    del network[node.id]
    node = boot(sensor, network, bus)
    sensor.send("set x=131.7")  # a new process: the simulated tilt starts at 0
    time.sleep(0.1)
    assert node.sdo["Slope long16"].raw == 3400


def test_node_id_and_bitrate_objects(sensor_factory, network, bus):
    sensor = sensor_factory("inx360d")
    node = boot(sensor, network, bus)
    node.sdo[0x2000].raw = 15
    node.sdo[0x2001].raw = 0x04
    with pytest.raises(SdoAbortedError) as e:
        node.sdo[0x2001].raw = 0x03
    assert e.value.code == 0x06090030
    node.nmt.state = "RESET COMMUNICATION"  # keeps the active ID (C8)
    assert bus.wait_for(0x701, timeout=2) is not None
    node.nmt.state = "RESET"
    assert bus.wait_for(0x70F, timeout=2) is not None
    del network[node.id]
    sensor.stop()
    node = boot(sensor, network, bus, node_id=15)
    assert node.sdo[0x2001].raw == 0x04
    assert "bit-rate code 4" in sensor.log_text()


def test_emcy_codes(sensor_factory, network, bus):
    sensor = sensor_factory("iny360d")
    node = boot(sensor, network, bus)
    bus.clear()
    sensor.send("fault range-y on")
    m = bus.wait_for(0x81, timeout=2)
    assert m is not None and bytes(m.data) == bytes.fromhex("2050110000000000")
    sensor.send("fault undervoltage on")
    m = bus.wait_for(0x81, timeout=2)
    assert m is not None and bytes(m.data) == bytes.fromhex("0031150000000000")
    # The canopen master's EMCY consumer saw both.
    assert {e.code for e in node.emcy.active} >= {0x5020, 0x3100}
    assert node.sdo[0x1001].raw == 0x15
    sensor.send("fault range-y off")
    sensor.send("fault undervoltage off")
    m = bus.wait_for(0x81, timeout=2, pred=lambda m: bytes(m.data) == bytes(8))
    assert m is not None
    bus.clear()
    answer = sensor.command("fault sensor on")  # not a P+F fault: refused, nothing changes
    assert answer == "error: usage: fault range-x|range-y|undervoltage on|off", answer
    assert bus.wait_for(0x81, timeout=0.5) is None
    assert node.sdo[0x1001].raw == 0
    assert sensor.stop() == 0


def test_sdo_block_transfer(sensor_factory, network, bus):
    node = boot(sensor_factory("iny360d"), network, bus)
    with node.sdo.open(0x1008, 0, "rb", block_transfer=True) as f:
        assert f.read() == b"INY360D-F99-B16-V15"
    with node.sdo.open(0x6014, 0, "wb", size=2, block_transfer=True) as f:
        f.write((-200).to_bytes(2, "little", signed=True))
    assert node.sdo["Differential slope long16 offset"].raw == -200
    with pytest.raises(SdoAbortedError) as e:
        with node.sdo.open(0x6014, 0, "wb", size=2, block_transfer=True) as f:
            f.write((5000).to_bytes(2, "little", signed=True))
    assert e.value.code == 0x06090031  # the object's own check, through a block
