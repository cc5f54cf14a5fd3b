"""The EDS of every product: printed by canopen-sensor --eds from the
firmware's own tables, accepted by dcfchk (dcf-tools) with no error or
warning, and loaded by the canopen package with the values the firmware
answers (checked live in the product integration tests)."""
import pathlib
import subprocess
import sys

import canopen
import pytest

from conftest import BINARY, ROOT


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


@pytest.mark.parametrize("pid", ["gsh-a", "gsh-a-redundant"])
def test_gsh_eds_event_timer_as_the_manual_asks(pid, tmp_path):
    """GSH-A manual: "In the EDS file this default value must be set to 0,
    otherwise errors will be generated" (section 12, the 0x1800 table); the
    device keeps 100 ms (read live in test_gsh.py). The EDS says why, in a comment line."""
    path = eds_of(pid, tmp_path)
    od = canopen.import_od(str(path), 0x13)
    assert od[0x1800][5].default == 0
    assert od[0x1800][3].default == 4  # the others stay the device's
    section = path.read_text().split("[1800sub5]\n")[1].split("\n\n")[0]
    comment = [l for l in section.splitlines() if l.startswith(";")]
    assert len(comment) == 1 and "device's default is 0x64" in comment[0], section
    assert "otherwise errors will be generated" in comment[0]


@pytest.mark.parametrize("pid", product_ids())
def test_eds_comments_only_explain_overrides(pid, tmp_path):
    """A comment line in an EDS stands right before the DefaultValue it explains."""
    lines = eds_of(pid, tmp_path).read_text().splitlines()
    for i, line in enumerate(lines):
        if line.startswith(";"):
            assert lines[i + 1].startswith("DefaultValue="), line


def test_readme_dcfchk_commands(tmp_path):
    """The README's EDS check, run as written (binaries from this build)."""
    readme = (ROOT / "README.md").read_text()
    blocks = [b.split("```")[0] for b in readme.split("```sh\n")[1:]]
    block = next(b for b in blocks if "dcfchk" in b)
    dcfchk = pathlib.Path(sys.executable).with_name("dcfchk")
    for line in block.splitlines():
        cmd = line.replace("build/bin/canopen-sensor", BINARY)
        cmd = cmd.replace("build/venv/bin/dcfchk", str(dcfchk))
        r = subprocess.run(cmd, shell=True, cwd=tmp_path, capture_output=True, text=True)
        assert r.returncode == 0, f"{line}\n{r.stdout}{r.stderr}"
        assert "Error" not in r.stderr and "Warning" not in r.stderr, r.stderr
    assert "dcfchk -n " in block


def test_unknown_product_eds():
    r = subprocess.run([BINARY, "--product", "nope", "--eds"], capture_output=True, text=True)
    assert r.returncode == 2 and "unknown product" in r.stderr


@pytest.mark.parametrize("pid", product_ids())
def test_serial_number_has_no_default(pid, tmp_path):
    """1018h:04 is each unit's own (its LSS address): the EDS gives no
    DefaultValue for it (CiA 306 lets an entry omit one), so that a master
    checking the serial at boot (1F88h) from a DCF of this EDS rejects no
    unit; the canopen package loads it with no default."""
    path = eds_of(pid, tmp_path)
    section = path.read_text().split("[1018sub4]\n")[1].split("\n\n")[0]
    assert "AccessType=ro" in section and "DefaultValue" not in section, section
    od = canopen.import_od(str(path), 5)
    assert od[0x1018][4].default is None and od[0x1018][3].default is not None
