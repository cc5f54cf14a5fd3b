"""Every product ID boots on vcan, answers its identity as its EDS says,
and sends PDOs once operational (the per-family tests go deeper)."""
import subprocess

import canopen
import pytest

from conftest import BINARY
from test_eds import product_ids


@pytest.mark.parametrize("pid", product_ids())
def test_boots_and_answers(pid, sensor_factory, network, bus, tmp_path):
    eds = tmp_path / f"{pid}.eds"
    eds.write_text(subprocess.run([BINARY, "--product", pid, "--eds"], check=True,
                                  capture_output=True, text=True).stdout)
    sensor = sensor_factory(pid)
    bus.clear()
    sensor.start()
    m = bus.wait_for_any(lambda m: 0x701 <= m.arbitration_id <= 0x77F and bytes(m.data) == b"\0",
                         timeout=3)
    assert m is not None, "no boot-up"
    node_id = m.arbitration_id - 0x700
    od = canopen.import_od(str(eds), node_id)
    node = network.add_node(node_id, od)
    assert node.sdo[0x1000].raw == od[0x1000].default
    assert node.sdo[0x1018][1].raw == od[0x1018][1].default
    node.nmt.state = "OPERATIONAL"
    if od[0x1800][2].default <= 240:
        network.sync.transmit()  # synchronous by default (P+F, JD)
    tpdo_cob = od[0x1800][1].default & 0x7FF
    assert bus.wait_for(tpdo_cob, timeout=1) is not None, "no PDO"
    assert sensor.stop() == 0
