"""canopen-sensor --program-download without CAN: its command line, and
the EDS that shows the objects of program download only with it (off
keeps exactly the manual's dictionary). On the bus: test_progdl.py."""
import pathlib
import struct
import subprocess
import sys

import canopen
import pytest

from conftest import BINARY

OBJECTS = ("[1F50]", "[1F50sub1]", "[1F51sub1]", "[1F56sub1]", "[1F57sub1]")


def run(*args):
    return subprocess.run([BINARY, *args], capture_output=True, text=True, timeout=10)


def test_help_names_the_option():
    r = run("--help")
    assert r.returncode == 0 and "--program-download" in r.stdout


@pytest.mark.parametrize("args", [
    ("--product", "jd2xxx", "--iface", "vcan0"),
    ("--node", "jd2xxx", "--iface", "vcan0"),
    ("--product", "jd2xxx", "--nvm", "x.nvm", "--node", "inx360d", "--iface", "vcan0"),
])
def test_needs_an_eeprom_file_for_every_instance(args):
    r = run(*args, "--program-download")
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "--program-download needs an EEPROM file for every instance" \
        in lines[0], r.stderr


def test_given_twice():
    r = run("--product", "jd2xxx", "--eds", "--program-download", "--program-download")
    assert r.returncode == 2 and "--program-download given twice" in r.stderr


def product_ids():
    out = subprocess.run([BINARY, "--list-products"], capture_output=True, text=True,
                         check=True).stdout
    return [line.split()[0] for line in out.splitlines()]


@pytest.mark.parametrize("pid", product_ids())
def test_eds(pid, tmp_path):
    plain = run("--product", pid, "--eds")
    with_pd = run("--product", pid, "--eds", "--program-download")
    assert plain.returncode == 0 and with_pd.returncode == 0, plain.stderr + with_pd.stderr
    assert not any(o in plain.stdout for o in OBJECTS)
    assert all(o in with_pd.stdout for o in OBJECTS)
    path = tmp_path / "pd.eds"
    path.write_text(with_pd.stdout)
    dcfchk = pathlib.Path(sys.executable).with_name("dcfchk")
    r = subprocess.run([str(dcfchk), "-n", "5", "-p", str(path)], capture_output=True, text=True)
    assert r.returncode == 0 and "Warning" not in r.stderr and "Error" not in r.stderr, \
        r.stdout + r.stderr
    od = canopen.import_od(str(path), 5)
    assert od[0x1F51][1].access_type == "rw" and od[0x1F56][1].access_type == "ro"
    assert od[0x1F50][1].data_type == 0x0F and od[0x1F50][1].access_type == "wo"
    # Everything else as without the option.
    assert len(with_pd.stdout.splitlines()) > len(plain.stdout.splitlines())
    for line in plain.stdout.splitlines():
        if line.startswith("[") or line.startswith("ParameterName"):
            assert line in with_pd.stdout, line


def test_lely_dcfgen_takes_the_bus_yml_of_the_docs(tmp_path):
    """docs/program-download.md's bus.yml: Lely's dcfgen (dcf-tools) takes
    it with the EDS of --program-download without a warning, and writes
    the update into the master's configuration (1F55h, 1F58h's
    UploadFile, 1F81h bits 5 and 6); with the manual's EDS it warns that
    1F56h:1 is missing."""
    dcfgen = pathlib.Path(sys.executable).with_name("dcfgen")
    (tmp_path / "x730.img").write_bytes(b"")  # dcfgen only names it
    bus = ('options:\n  dcf_path: "."\nmaster:\n  node_id: 1\nx730:\n  dcf: "x730.eds"\n'
           '  node_id: 0x7F\n  software_file: "x730.img"\n  software_version: 0x10001\n')
    (tmp_path / "bus.yml").write_text(bus)
    for args, warns in ((("--eds", "--program-download"), False), (("--eds",), True)):
        r = run("--product", "dst-x730-xy30", *args)
        (tmp_path / "x730.eds").write_text(r.stdout)
        g = subprocess.run([str(dcfgen), "-r", "bus.yml"], cwd=tmp_path, capture_output=True,
                           text=True, timeout=60)
        assert g.returncode == 0, g.stderr
        assert ("sub-object 0x1F56/1 does not exist" in g.stderr) == warns, g.stderr
        if not warns:
            dcf = (tmp_path / "master.dcf").read_text()
            assert "UploadFile=x730.img" in dcf
            assert "127=0x00000365" in dcf  # 1F81h: boot, check (bit 5), update (bit 6)
            # 1F55h:7Fh = 10001h among the master's own SDO writes (concise DCF)
            concise = struct.pack("<HBII", 0x1F55, 0x7F, 4, 0x10001)
            assert concise in (tmp_path / "master.bin").read_bytes()
