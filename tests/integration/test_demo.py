"""The README's demo command runs and shows what it promises, for one
product of each family: the decoded lines show the values the simulator
was set to (the steps of tools/demo.py's FAMILIES table)."""
import os
import re
import subprocess
import sys

import pytest

from conftest import BINARY, ROOT

sys.path.insert(0, str(ROOT / "tools"))
import demo  # noqa: E402  (tools/demo.py, for its FAMILIES table)

from test_eds import product_ids  # noqa: E402


def start_demo(product, step, tmp, iface="vcan0"):
    # TMPDIR: the demo's directory (sensor log, EDS) inside pytest's.
    return subprocess.Popen([sys.executable, str(ROOT / "tools" / "demo.py"), product,
                             "--step", str(step), "--iface", iface],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, CANOPEN_SENSOR=BINARY, TMPDIR=str(tmp)))


def demo_output(p):
    out, err = p.communicate(timeout=90)
    assert p.returncode == 0, out + err
    assert "Traceback" not in err, err
    assert "demo: done" in out
    return out


def run_demo(product, step, tmp):
    return demo_output(start_demo(product, step, tmp))


def test_demo_session(network, tmp_path):  # network: fails loudly without vcan0
    out = run_demo("dst-x730-xy30", 1.6, tmp_path)  # the README's session
    assert "boot-up" in out
    assert "device type: 0x0008019A" in out
    assert "device name: 'GIB'" in out
    assert "TPDO1  X= +12.50 deg  Y=  -3.00 deg" in out
    assert "TPDO1  X= -20.00 deg  Y=  +7.25 deg" in out
    assert "EMCY 1000h, 0x4001 = 0x01" in out
    assert "TPDO1  X= +33.00 deg" in out  # stopped at the limit of the +-30 variant
    assert "EMCY error reset" in out


# Per family, regular expressions the output must match: the node's boot-up,
# its identity, and a decoded TPDO (or EMCY) line for what each step set.
FAMILY_CASES = {
    "dst-x730-z360": [r"77F  00 +boot-up", r"device name: 'GIB'",
                      r"1FF  .*TPDO1  Z= \+90\.00 deg", r"1FF  .*TPDO1  Z=-135\.50 deg",
                      r"0FF  .*EMCY 1000h, 0x4001 = 0x01", r"0FF  .*EMCY error reset",
                      r"1FF  .*TPDO1  Z=\+179\.25 deg"],
    # Both nodes: channel 2 counts backwards (stroke - length, 360 - angle).
    "gsh-a-redundant": [r"713  00 +boot-up", r"714  00 +boot-up", r"device name: 'GSHA'",
                        r"193  .*length= 1234 mm  angle= 12\.5 deg  no alarm  #\d+ checksum ok",
                        r"194  .*length= 6766 mm  angle=347\.5 deg  no alarm  #\d+ checksum ok",
                        r"193  .*length= 8000 mm  angle= 90\.0 deg  over-extension ",
                        r"193  .*length= 2500 mm  angle= 90\.0 deg  field low  ",
                        r"193  .*field low, tilt element ",
                        r"193  .*length=  500 mm  angle=359\.9 deg  no alarm"],
    "jd1xxx": [r"70A  00 +boot-up", r"device name: 'JD1xxx'", r"SYNC .*every 100 ms",
               r"18A  E2 04 +TPDO1  Z=  12\.50 deg", r"18A  .*Z=  90\.00 deg",
               r"18A  .*Z= 270\.25 deg", r"18A  .*Z= 359\.90 deg"],
    "inx360d": [r"701  00 +boot-up", r"device name: 'INX360D-F99-B16-V15'",
                r"181  7D 00 +TPDO1  X=  12\.5 deg", r"181  .*X= 340\.0 deg",
                r"081  10 50 .*EMCY 5010h", r"081  .*EMCY error reset",
                r"181  .*X= 180\.0 deg"],
}


# Two at a time, one on each bus (each demo takes the node-IDs of the
# boot-ups on its bus): half the time.
@pytest.mark.parametrize("pair", [("dst-x730-z360", "gsh-a-redundant"), ("jd1xxx", "inx360d")])
def test_demo_of_each_family(pair, network, tmp_path):
    runs = [start_demo(product, 1.0, tmp_path, iface)
            for product, iface in zip(pair, ("vcan0", "vcan1"))]
    outs = [demo_output(p) for p in runs]
    for product, out in zip(pair, outs):
        for pattern in FAMILY_CASES[product]:
            assert re.search(pattern, out), f"{product}: no line matches {pattern!r} in:\n{out}"
        assert "checksum BAD" not in out


def test_every_product_has_a_demo():
    ids = product_ids()
    assert len(ids) >= 20
    for pid in ids:
        assert demo.family_of(pid) is not None, f"tools/demo.py has no FAMILIES entry for {pid}"


def test_demo_refuses_an_unknown_product():
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "demo.py"), "nope"],
                       capture_output=True, text=True, timeout=30,
                       env=dict(os.environ, CANOPEN_SENSOR=BINARY))
    assert r.returncode == 1 and "no demo for product 'nope'" in r.stderr
    assert "Traceback" not in r.stderr
