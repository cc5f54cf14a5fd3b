"""ifm JD1xxx / JD2xxx end to end on vcan: the canopen package's LSS master
(CiA 305 services, Fastscan included), its node guarding, the heartbeat
consumer, change-of-state PDOs and the TPDO2 remapping example of the
manual, decoded through the product's EDS. Factory node-ID 10."""
import time

import canopen
import pytest
from canopen.lss import CS_INQUIRE_SERIAL_NUMBER, CS_INQUIRE_VENDOR_ID
from canopen.sdo.exceptions import SdoAbortedError

from conftest import eds_od
from conftest import boot as start_node

NODE = 10
VENDOR, PRODUCT, REVISION = 0x0069666D, 0, 0x00010000  # the serial (1018h:04) is per unit




def boot(sensor, network, bus, node_id=NODE):
    return start_node(sensor, network, bus, node_id)


def test_lss_configure_store_and_activate(sensor_factory, network, bus):
    sensor = sensor_factory("jd2xxx")
    node = boot(sensor, network, bus)
    serial = node.sdo["Identity object"]["Serial number"].raw
    lss = network.lss
    assert lss.send_switch_state_selective(VENDOR, PRODUCT, REVISION, serial)
    assert lss.inquire_lss_address(CS_INQUIRE_VENDOR_ID) == VENDOR
    assert lss.inquire_lss_address(CS_INQUIRE_SERIAL_NUMBER) == serial
    assert lss.inquire_node_id() == NODE
    lss.configure_node_id(32)
    lss.configure_bit_timing(2)  # 500 kbit/s
    with pytest.raises(canopen.lss.LssError):
        lss.configure_bit_timing(8)  # 10 kbit/s: not supported
    lss.store_configuration()
    lss.activate_bit_timing(10)
    # The port is told after the 10 ms switch delay (vcan has no bit rate:
    # the program logs it).
    deadline = time.monotonic() + 2
    while "node 0: bit rate now 500 kbit/s" not in sensor.log_text():
        assert time.monotonic() < deadline, "activate bit timing did not reach the port"
        time.sleep(0.02)
    lss.send_switch_state_global(lss.WAITING_STATE)
    del network[NODE]
    bus.clear()
    network.nmt.send_command(0x82)  # reset communication, all nodes
    assert bus.wait_for(0x720, timeout=2, pred=lambda m: bytes(m.data) == b"\0")
    node = network.add_node(32, eds_od("jd2xxx", sensor.log.parent, 32))
    assert node.sdo["Node number"].raw == 31
    assert node.sdo["Baud rate"].raw == 5  # 500 kbit/s in ifm's code
    sensor.stop()
    del network[32]
    boot(sensor, network, bus, node_id=32)  # stored: survives a power cycle
    assert "node-ID 0x20 on vcan0, bit-rate code 5 = 500 kbit/s" in sensor.log_text()


def test_lss_fastscan_finds_an_unconfigured_node(sensor_factory, network, bus):
    sensor = sensor_factory("jd1xxx")
    serial = boot(sensor, network, bus).sdo["Identity object"]["Serial number"].raw
    lss = network.lss
    lss.send_switch_state_global(lss.CONFIGURATION_STATE)
    lss.configure_node_id(0xFF)  # unconfigured from the next reset
    lss.send_switch_state_global(lss.WAITING_STATE)
    bus.clear()
    network.nmt.send_command(0x82)
    assert bus.wait_for(0x70A, timeout=0.5) is None  # no node-ID: no boot-up
    bus.clear()
    lss.send_identify_non_configured_remote_slave()  # returns nothing: see the bus
    m = bus.wait_for(0x7E4, timeout=1)
    assert m is not None and m.data[0] == 0x50
    found, address = lss.fast_scan()
    assert found and address == [VENDOR, PRODUCT, REVISION, serial]
    lss.configure_node_id(7)  # fastscan left it selected
    bus.clear()
    lss.send_switch_state_global(lss.WAITING_STATE)
    assert bus.wait_for(0x707, timeout=2, pred=lambda m: bytes(m.data) == b"\0")
    bus.clear()
    lss.send_identify_remote_slave(VENDOR, PRODUCT, 0, 0xFFFFFFFF, 0, 0xFFFFFFFF)
    m = bus.wait_for(0x7E4, timeout=1)
    assert m is not None and m.data[0] == 0x4F


def test_guarding_and_heartbeat_consumer(sensor_factory, network, bus):
    node = boot(sensor_factory("jd2xxx"), network, bus)
    node.sdo["Guard time"].raw = 100
    node.sdo["Life time factor"].raw = 3
    node.nmt.state = "OPERATIONAL"
    node.nmt.start_node_guarding(0.1)
    time.sleep(0.5)
    assert node.nmt.state == "OPERATIONAL"
    node.nmt.stop_node_guarding()
    m = bus.wait_for(0x8A, timeout=2)
    assert m is not None and m.data[0:2] == b"\x30\x81"
    assert node.sdo[0x1003][1].raw & 0xFFFF == 0x8130  # the error history
    # One guard request ends the life-guard error (error reset), then guarding
    # is switched off: heartbeat and guarding events share EMCY 8130h.
    bus.clear()
    network.send_message(0x70A, b"", remote=True)
    m = bus.wait_for(0x8A, timeout=1)
    assert m is not None and bytes(m.data) == bytes(8)
    node.sdo["Guard time"].raw = 0
    # Heartbeat consumer: watch node 5 every 200 ms.
    node.sdo[0x1016][1].raw = (5 << 16) | 200
    node.nmt.state = "OPERATIONAL"
    for _ in range(5):
        network.send_message(0x705, b"\x05")
        time.sleep(0.1)
    assert node.nmt.state == "OPERATIONAL"
    bus.clear()
    m = bus.wait_for(0x8A, timeout=1)  # the heartbeats stopped
    assert m is not None and m.data[0:2] == b"\x30\x81"


def test_tpdo2_remap_and_change_of_state(sensor_factory, network, bus):
    sensor = sensor_factory("jd2xxx")
    node = boot(sensor, network, bus)
    # The manual's example B (its misprinted frames corrected): gyro X + accel X.
    node.tpdo.read()
    tpdo2 = node.tpdo[2]
    tpdo2.clear()
    tpdo2.add_variable("Gyro X axis 16")
    tpdo2.add_variable("Acceleration X axis 16")
    tpdo2.trans_type = 1
    tpdo2.enabled = True
    tpdo2.save()  # canopen follows the CiA 301 procedure (invalidate, map, validate)
    node.tpdo[1].trans_type = 254
    node.tpdo[1].event_timer = 0
    node.tpdo[1].save()
    node.sdo[0x1010][1].raw = 0x65766173  # "save"
    sensor.send("set x=30 y=-10")
    node.nmt.state = "OPERATIONAL"
    time.sleep(0.2)
    network.sync.transmit()
    tpdo2.wait_for_reception(timeout=1)
    assert tpdo2["Acceleration X axis 16"].raw == 500
    # Change of state: TPDO1 goes out when the angle changes, not otherwise.
    bus.clear()
    assert bus.wait_for(0x18A, timeout=0.5) is None
    sensor.send("set x=31 y=-10")
    node.tpdo[1].wait_for_reception(timeout=1)
    assert node.tpdo[1]["Slope long16"].raw == 3100
    assert node.tpdo[1]["Slope lateral16"].raw == -1000
    with pytest.raises(SdoAbortedError) as e:
        node.sdo[0x1800][3].raw = 10  # inhibit time while valid (R21)
    assert e.value.code == 0x06090030
