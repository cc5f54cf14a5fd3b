"""The EDS of every product: printed by canopen-sensor --eds from the
firmware's own tables, accepted by dcfchk (dcf-tools) with no error or
warning, and loaded by the canopen package with the values the firmware
answers (checked live in the product integration tests)."""
import pathlib
import subprocess
import sys

import canopen
import pytest

from conftest import BINARY


def product_ids():
    out = subprocess.run([BINARY, "--list-products"], capture_output=True, text=True,
                         check=True).stdout
    return [line.split()[0] for line in out.splitlines()]


def eds_of(pid, tmp_path):
    path = tmp_path / f"{pid}.eds"
    r = subprocess.run([BINARY, "--product", pid, "--eds"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    path.write_text(r.stdout)
    return path


@pytest.mark.parametrize("pid", product_ids())
def test_dcfchk_accepts_the_eds(pid, tmp_path):
    path = eds_of(pid, tmp_path)
    dcfchk = pathlib.Path(sys.executable).with_name("dcfchk")
    r = subprocess.run([str(dcfchk), "-n", "5", "-p", str(path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Warning" not in r.stderr and "Error" not in r.stderr, r.stderr


@pytest.mark.parametrize("pid", product_ids())
def test_canopen_loads_the_eds(pid, tmp_path):
    od = canopen.import_od(str(eds_of(pid, tmp_path)), 5)
    # CiA 410, or CiA 406 first for the GSH-A (a multiple logical device).
    assert od[0x1000].default & 0xFFFF in (0x019A, 0x0196)
    assert 0x1018 in od and 0x1800 in od and 0x1A00 in od
    assert od[0x1800][1].default & 0x7FF == 0x185  # $NODEID resolved
    mapped = [od[0x1A00][s].default for s in range(1, od[0x1A00][0].default + 1)]
    for m in mapped:
        assert od[m >> 16].pdo_mappable


def test_unknown_product_eds():
    r = subprocess.run([BINARY, "--product", "nope", "--eds"], capture_output=True, text=True)
    assert r.returncode == 2 and "unknown product" in r.stderr
