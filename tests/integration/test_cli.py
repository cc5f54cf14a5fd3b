"""The command line of canopen-sensor (no CAN needed)."""
import os
import subprocess

from conftest import BINARY

VARIANTS = ["xy10", "xy15", "xy20", "xy30", "xy45", "xy60", "xy90", "z360"]
PRODUCT_IDS = [f"dst-{m}-{v}" for m in ("x730", "x710") for v in VARIANTS] + [
    "inx360d", "iny360d"]


def run(*args, stdin=None):
    return subprocess.run([BINARY, *args], capture_output=True, text=True, timeout=10,
                          input=stdin)


def one_line(r, code, text):
    """A refusal: exit status code, and one line on stderr saying why."""
    assert r.returncode == code, (r.returncode, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and text in lines[0], r.stderr


def test_list_products():
    r = run("--list-products")
    assert r.returncode == 0
    ids = [line.split()[0] for line in r.stdout.splitlines()]
    for pid in PRODUCT_IDS:
        assert pid in ids
    assert all(len(line.split(None, 1)) == 2 for line in r.stdout.splitlines())


def test_list_products_json():
    """--list-products --json: valid JSON, the same products in the same
    order as the text list, and what the products declare."""
    import json
    r = run("--list-products", "--json")
    assert r.returncode == 0, r.stderr
    products = json.loads(r.stdout)
    text_ids = [line.split()[0] for line in run("--list-products").stdout.splitlines()]
    assert [p["id"] for p in products] == text_ids
    assert run("--json", "--list-products").stdout == r.stdout  # either order
    by_id = {p["id"]: p for p in products}
    for p in products:
        assert set(p) == {"id", "family", "summary", "vendor", "nodes", "default_node_ids",
                          "default_bitrate_kbps", "lss", "inputs", "faults"}
        assert len(p["default_node_ids"]) == p["nodes"]
        assert all(1 <= n <= 127 for n in p["default_node_ids"])
        assert p["inputs"] and all(set(i) == {"name", "unit", "limit", "initial"}
                                   for i in p["inputs"])
    dst = by_id["dst-x730-xy30"]
    assert (dst["family"], dst["default_node_ids"], dst["default_bitrate_kbps"], dst["lss"]) \
        == ("dst", [0x7F], 250, False)
    assert dst["inputs"] == [{"name": "x", "unit": "deg", "limit": 3600, "initial": 0},
                             {"name": "y", "unit": "deg", "limit": 3600, "initial": 0}]
    assert dst["faults"] == ["sensor"]
    assert by_id["gsh-a-redundant"]["family"] == "gsh"
    assert by_id["gsh-a-redundant"]["default_node_ids"] == [0x13, 0x14]
    assert by_id["jd2xxx"]["lss"] is True and by_id["jd2xxx"]["faults"] == []
    assert by_id["jd2xxx"]["default_node_ids"] == [10]
    assert by_id["inx360d"]["family"] == "pf"
    assert by_id["inx360d"]["faults"] == ["range-x", "range-y", "undervoltage"]
    one_line(run("--json"), 2, "--json goes with --list-products")


def test_help():
    r = run("--help")
    assert r.returncode == 0
    for word in ("--product", "--iface", "--nvm", "--log", "--list-products", "--led-chip",
                 "--eds", "--on-eof quit|run", "--json", "set NAME=VALUE", "fault NAME on|off",
                 "can bus-off [SECONDS]", "can passive|warning|active", "quit", "SIGHUP",
                 "Exit status"):
        assert word in r.stdout


def test_help_lists_every_products_inputs_and_faults():
    ids = [line.split()[0] for line in run("--list-products").stdout.splitlines()]
    rows = {line.split()[0]: line for line in run("--help").stdout.splitlines()
            if line.startswith("  ") and line.split()[0] in ids}
    assert sorted(rows) == sorted(ids)
    assert rows["dst-x730-xy30"].split(None, 1)[1] == "set x=<deg> y=<deg>; fault sensor"
    assert rows["dst-x710-z360"].split(None, 1)[1] == "set z=<deg>; fault sensor"
    assert rows["inx360d"].split(None, 1)[1] == "set x=<deg>; fault range-x|range-y|undervoltage"
    assert "set length=<mm> angle=<deg> field=<%>; fault extension-element|tilt-element" in \
        rows["gsh-a-redundant"]
    assert rows["jd2xxx"].endswith("; no faults")


def test_usage_errors():
    one_line(run(), 2, "--product is missing (see --help)")
    one_line(run("--product", "nope", "--iface", "vcan0"), 2, "unknown product 'nope'")
    one_line(run("--product", "dst-x730-xy30"), 2, "--iface is missing (see --help)")
    one_line(run("--product", "dst-x730-xy30", "--iface", "vcan0,vcan1"), 2,
             "dst-x730-xy30 has one node: give one interface")
    one_line(run("--product", "gsh-a-redundant", "--iface", "vcan0,vcan1,vcan2"), 2,
             "gsh-a-redundant has 2 nodes: give one interface, or one per node (A,B)")
    one_line(run("--product", "gsh-a-redundant", "--iface", "vcan0,"), 2,
             "'' is not an interface name")
    one_line(run("--product", "jd1xxx", "--iface", "vcan0", "--led-green", "4"), 2,
             "--led-green needs --led-chip")
    one_line(run("--product", "jd1xxx", "--iface", "vcan0", "--led-red", "4"), 2,
             "--led-red needs --led-chip")
    one_line(run("--product", "jd1xxx", "--iface", "vcan0", "--frobnicate"), 2,
             "unknown option '--frobnicate' (see --help)")
    one_line(run("--product", "jd1xxx", "--iface"), 2, "option --iface needs a value")
    one_line(run("--product", "jd1xxx", "--iface", "vcan0", "extra"), 2,
             "unexpected argument 'extra'")
    one_line(run("--product", "jd1xxx", "--iface", "vcan0", "--on-eof", "later"), 2,
             "--on-eof takes quit or run, not 'later'")


def test_nvm_not_a_regular_file(tmp_path):
    """Refused before anything is opened: a FIFO must not hang the start."""
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    base = ["--product", "jd1xxx", "--iface", "vcan0", "--nvm"]
    one_line(run(*base, str(fifo)), 2, f"--nvm {fifo}: a FIFO, not a regular file")
    one_line(run(*base, str(tmp_path)), 2, f"--nvm {tmp_path}: a directory, not a regular file")
    one_line(run(*base, "/dev/zero"), 2, "--nvm /dev/zero: a character device, not a regular file")
    missing = tmp_path / "no" / "e.bin"
    one_line(run(*base, str(missing)), 2, f"directory {missing.parent} does not exist")
    assert not missing.parent.exists()


def test_missing_interface_is_a_clear_error(tmp_path):
    r = run("--product", "dst-x730-xy30", "--iface", "nosuchcan0", "--nvm",
            str(tmp_path / "e.bin"))
    assert r.returncode == 1
    last = r.stderr.strip().splitlines()[-1]
    assert "nosuchcan0: no such network interface" in last or "CAN socket" in last
    assert not (tmp_path / "e.bin").exists()  # nothing written before a save
