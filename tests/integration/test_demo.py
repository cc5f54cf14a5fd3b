"""The README's demo command runs and shows what it promises."""
import os
import subprocess
import sys

from conftest import BINARY, ROOT


def test_demo_session(network):  # network: fails loudly without vcan0
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "demo.py"), "dst-x730-xy30"],
                       capture_output=True, text=True, timeout=60,
                       env=dict(os.environ, CANOPEN_SENSOR=BINARY))
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert "boot-up" in out
    assert "device type: 0x0008019A" in out
    assert "device name: 'GIB'" in out
    assert "TPDO1  X= +12.50 deg  Y=  -3.00 deg" in out
    assert "TPDO1  X= -20.00 deg  Y=  +7.25 deg" in out
    assert "EMCY 1000h, 0x4001 = 0x01" in out
    assert "TPDO1  X= +33.00 deg" in out  # stopped at the limit of the +-30 variant
    assert "EMCY error reset" in out
