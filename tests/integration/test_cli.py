"""The command line of canopen-sensor (no CAN needed)."""
import os
import re
from pathlib import Path
import subprocess

import pytest

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
                          "default_bitrate_kbps", "lss", "inputs", "faults", "template",
                          "mcu_image", "mcu_config"}
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
    # From the declarations: the program lists no template, and every
    # product it lists has an MCU image with its config fixed, but for a
    # device of two nodes (two configs).
    assert all(p["template"] is False and p["mcu_image"] is True for p in products)
    assert (dst["mcu_config"], by_id["dst-x710-z360"]["mcu_config"]) == ("dst_x730_cfg",
                                                                         "dst_x710_cfg")
    assert (by_id["gsh-a"]["mcu_config"], by_id["gsh-a-redundant"]["mcu_config"]) \
        == ("gsh_ch1_cfg", None)
    od = Path(__file__).resolve().parents[2] / "od"
    assert all((od / p["family"] / "family.cmake").is_file() for p in products)
    assert all(p["mcu_config"] for p in products if p["nodes"] == 1)
    one_line(run("--json"), 2, "--json goes with --list-products")


def test_help():
    r = run("--help")
    assert r.returncode == 0
    for word in ("--product", "--iface", "--nvm", "--log", "--list-products", "--led-chip",
                 "--eds", "--on-eof quit|run", "--json", "set NAME=VALUE", "fault NAME on|off",
                 "can bus-off [SECONDS] | passive | warning | active", "quit", "SIGHUP",
                 "Exit status"):
        assert word in r.stdout


def help_verbs():
    """The verbs --help lists (the program's table), in its order."""
    lines = run("--help").stdout.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("Commands,"))
    rows = lines[start + 1:lines.index("", start)]
    return [line.split()[0] for line in rows if line.startswith("  ") and not line.startswith("   ")]


def test_verbs_agree_with_the_python_package_and_the_readme():
    """One language: the verbs of the program's table (--help), the Python
    package's list (a SimBus method each) and docs/control.md's command table are
    the same, in the same order."""
    from canopen_sensor_sim import VERBS, SimBus
    assert help_verbs() == list(VERBS)
    for verb in VERBS:
        assert callable(getattr(SimBus, verb, None)), verb
    readme = (Path(__file__).resolve().parents[2] / "docs" / "control.md").read_text()
    table = [m.group(1) for m in re.finditer(r"^\| `([a-z]+)[ `]", readme, re.M)]
    assert list(dict.fromkeys(table)) == list(VERBS)


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
    one_line(run("--product", "nope", "--iface", "vcan0"), 2,
             "unknown product 'nope' (see --list-products)")
    assert "--help" not in run("--product", "nope", "--iface", "vcan0").stderr  # one hint
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


@pytest.mark.parametrize("serial", ["1", "0xFFFFFFFF", "4294967295", "0000000000000000000001",
                                    "0x00000000000000000000FFFFFFFF"])
def test_serial_accepted(serial):
    """Past the command line: the interface is what stops it (exit 1)."""
    r = run("--product", "dst-x730-xy30", "--iface", "nosuchcan0", "--serial", serial)
    assert r.returncode == 1, r.stderr


@pytest.mark.parametrize("serial", ["0", "4294967296", "0x100000000", "-1", "+1", " 1", "",
                                    "0x", "1e3", "12x", "0x0000000000000000000100000000"])
def test_serial_refused(serial):
    one_line(run("--product", "jd2xxx", "--iface", "vcan0", "--serial", serial), 2,
             f"--serial takes a serial number 1..0xFFFFFFFF (decimal or 0x hex), not '{serial}' "
             "(see --help)")


def test_serial_range_of_several_nodes():
    """Node i takes serial + i: the last one must fit too (the range in
    the refusal computed wide enough on any host)."""
    one_line(run("--product", "gsh-a-redundant", "--iface", "vcan0", "--serial", "0xFFFFFFFF"), 2,
             "--serial 0xFFFFFFFF: 2 nodes take 0xFFFFFFFF..0x100000000, past 0xFFFFFFFF")
    assert "--serial N" in run("--help").stdout


def test_one_hint_chosen_by_the_message_not_its_words():
    """A word of the command line that looks like a hint chooses nothing."""
    one_line(run("--product", "dst-x730-xy30", "--iface", "vcan0", "oops (see --list-products)"),
             2, "unexpected argument 'oops (see --list-products)' (see --help)")
    one_line(run("--node", "dst-x730-xy30@(see 1", "--iface", "vcan0"), 2,
             "is not 1..127 (e.g. 0x21 or 33) (see --help)")


def test_nvm_not_a_regular_file(tmp_path):
    """Refused before anything is opened: a FIFO must not hang the start."""
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    base = ["--product", "jd1xxx", "--iface", "vcan0", "--nvm"]
    # Each with the hint, as the options' other refusals (it was on
    # --nvm-dir's and not on these).
    one_line(run(*base, str(fifo)), 2, f"--nvm {fifo}: a FIFO, not a regular file (see --help)")
    one_line(run(*base, str(tmp_path)), 2,
             f"--nvm {tmp_path}: a directory, not a regular file (see --help)")
    one_line(run(*base, "/dev/zero"), 2,
             "--nvm /dev/zero: a character device, not a regular file (see --help)")
    missing = tmp_path / "no" / "e.bin"
    one_line(run(*base, str(missing)), 2,
             f"directory {missing.parent} does not exist (see --help)")
    assert not missing.parent.exists()
    d = tmp_path / "d"
    d.mkdir()
    os.mkfifo(d / "jd1xxx-0x0A-vcan0.nvm")
    one_line(run("--product", "jd1xxx", "--iface", "vcan0", "--nvm-dir", str(d)), 2,
             f"--nvm-dir {d}: {d}/jd1xxx-0x0A-vcan0.nvm: a FIFO, not a regular file (see --help)")


@pytest.mark.parametrize("node, bad", [
    ("jd1xxx@0x0B/", ""), ("gsh-a-redundant/vcan0,", ""), ("gsh-a-redundant/,vcan1", ""),
    ("jd1xxx/a-name-longer-than-ifnamsiz", "a-name-longer-than-ifnamsiz")])
def test_node_interface_refusal_names_the_node(node, bad):
    """--node's own /IFACE refused: the message names that --node value,
    not --iface (which was blamed, given or not)."""
    for extra in ([], ["--iface", "vcan1"]):
        r = run("--node", node, *extra)
        one_line(r, 2, f"--node {node}: '{bad}' is not an interface name (see --help)")
        assert "--iface" not in r.stderr


def test_missing_interface_is_a_clear_error(tmp_path):
    r = run("--product", "dst-x730-xy30", "--iface", "nosuchcan0", "--nvm",
            str(tmp_path / "e.bin"))
    assert r.returncode == 1
    last = r.stderr.strip().splitlines()[-1]
    assert "nosuchcan0: no such network interface" in last or "CAN socket" in last
    assert not (tmp_path / "e.bin").exists()  # nothing written before a save


@pytest.mark.parametrize("iface, cause", [
    ("udp_multicast:[ff15::1]", "an IPv6 group: only IPv4 groups"),
    ("udp_multicast:10.0.0.1", "10.0.0.1 is not a multicast group (224.0.0.0/4)"),
    ("udp_multicast:239.1.2.3:0", "'0' is not a UDP port (1-65535)"),
    ("udp_multicast:239.1.2.3:65536", "'65536' is not a UDP port (1-65535)"),
    ("udp_multicast:239.1.2.3:x1", "'x1' is not a UDP port (1-65535)"),
    ("udp_multicast:239.1.2.3%nosuchif0", "nosuchif0: no such network interface"),
    ("udp_multicast:239.1.2.3%", "'' after % is not an interface name"),
    ("udp_multicast:239.1.2.300", "'239.1.2.300' is not an IPv4 address"),
])
def test_udp_multicast_refusals(tmp_path, iface, cause):
    """A udp_multicast bus that cannot be: the start fails (as a missing
    CAN interface does), naming the option, the form and the cause; nothing
    is sent and no file is written."""
    r = run("--product", "gsh-a", "--iface", iface, "--nvm", str(tmp_path / "e.bin"))
    assert r.returncode == 1
    last = r.stderr.strip().splitlines()[-1]
    assert last.startswith(f"canopen-sensor: --iface {iface}: {cause}"), last
    assert not (tmp_path / "e.bin").exists()


def test_udp_multicast_name_length():
    """The form is longer than a kernel's interface name (15 characters):
    taken up to 63, refused beyond, in --iface and in --node's /IFACE."""
    taken = "udp_multicast:239.1.2.3:43113%" + "x" * 33  # 63 characters
    for args in (["--product", "gsh-a", "--iface", taken + "x"], ["--node", f"gsh-a/{taken}x"]):
        r = run(*args)
        one_line(r, 2, f"{' '.join(args[-2:])}: '{taken}x' is not an interface name (see --help)")
    r = run("--node", f"gsh-a/{taken}")
    assert r.returncode == 1 and "'" + "x" * 33 + "' after % is not an interface name" in r.stderr, \
        r.stderr


def test_every_option_once_but_node():
    """One rule for every option: given twice, it is a wrong command line
    naming it (the last one silently won for --iface, --nvm, ...); only
    --node repeats."""
    base = ["--product", "jd1xxx", "--iface", "vcan0"]
    twice = {
        "--product": ["jd1xxx"], "--iface": ["vcan1"], "--nvm": ["/tmp/a.nvm"],
        "--nvm-dir": ["/tmp"], "--control": ["tcp:5000"], "--log": ["/tmp/x.log"],
        "--log-time": ["wall"], "--led-chip": ["gpiochip0"], "--led-green": ["2"],
        "--led-red": ["3"], "--on-eof": ["run"], "--seed": ["7"],
    }
    for opt, val in twice.items():
        args = [*base, opt, *val, opt, *val] if opt not in ("--product", "--iface") \
            else [*base, opt, *val]
        one_line(run(*args), 2, f"{opt[2:]} given twice (every option but --node at most once)")
    for flag in ("--eds", "--list-products", "--json"):
        one_line(run("--product", "jd1xxx", flag, flag), 2, f"--{flag[2:]} given twice")


def test_list_products_of_one_product():
    """--list-products with --product: that product alone (it was ignored)."""
    import json
    r = run("--list-products", "--json", "--product", "inx360d")
    assert r.returncode == 0, r.stderr
    assert [p["id"] for p in json.loads(r.stdout)] == ["inx360d"]
    r = run("--list-products", "--product", "inx360d")
    assert [line.split()[0] for line in r.stdout.splitlines()] == ["inx360d"]
    one_line(run("--list-products", "--product", "nope"), 2, "unknown product 'nope'")


def test_eds_to_a_full_output():
    """--eds whose output cannot be written says why (it exited 1 silently)."""
    with open("/dev/full", "w") as full:
        r = subprocess.run([BINARY, "--product", "jd2xxx", "--eds"], stdout=full,
                           stderr=subprocess.PIPE, text=True, timeout=10)
    assert r.returncode == 1
    assert r.stderr.strip() == \
        "canopen-sensor: --eds: standard output: No space left on device"


@pytest.mark.parametrize("args, opt", [
    (["--list-products"], "--list-products"),
    (["--list-products", "--product", "gsh-a"], "--list-products"),
    (["--help"], "--help"),
])
def test_list_and_help_to_a_full_output(args, opt):
    """--list-products (plain) and --help whose output cannot be written
    exit 1 with the cause, as --eds does (they exited 0 silently)."""
    with open("/dev/full", "w") as full:
        r = subprocess.run([BINARY] + args, stdout=full, stderr=subprocess.PIPE, text=True,
                           timeout=10)
    assert r.returncode == 1
    assert r.stderr.strip() == f"canopen-sensor: {opt}: standard output: No space left on device"


def test_directory_as_standard_input(tmp_path):
    """read() fails (EISDIR): it was taken for the end of input (exit 0, no word)."""
    fd = os.open(tmp_path, os.O_RDONLY)
    try:
        r = subprocess.run([BINARY, "--product", "jd2xxx", "--iface", "vcan0"], stdin=fd,
                           capture_output=True, text=True, timeout=10)
    finally:
        os.close(fd)
    one_line(r, 2, "standard input is a directory (give the commands on a pipe, a terminal or "
                   "a file, or < /dev/null)")


def test_nvm_link_to_nothing(tmp_path):
    """A link into a missing directory was taken, and the first save
    replaced the link by a file: refused at start, the link kept."""
    link = tmp_path / "e.nvm"
    link.symlink_to(tmp_path / "gone" / "e.nvm")
    one_line(run("--product", "jd1xxx", "--iface", "vcan0", "--nvm", str(link)), 2,
             f"--nvm {link}: a symbolic link to {tmp_path}/gone/e.nvm, which does not exist")
    assert link.is_symlink()


def test_nvm_dir_former_name_not_a_file(tmp_path):
    """The former name (before the interface was in it) as a directory or
    FIFO: refused, and nothing renamed (it was renamed, then refused)."""
    for make in (os.mkdir, os.mkfifo):
        d = tmp_path / make.__name__
        d.mkdir()
        former = d / "jd2xxx-0x0A.nvm"
        make(former)
        one_line(run("--product", "jd2xxx", "--iface", "vcan0", "--nvm-dir", str(d)), 2,
                 f"--nvm-dir {d}: {former} (the former name of {d}/jd2xxx-0x0A-vcan0.nvm) is not "
                 "a regular file: move it away")
        assert sorted(os.listdir(d)) == ["jd2xxx-0x0A.nvm"]


def test_a_failed_start_renames_nothing(tmp_path):
    """A stored set under the former name is renamed only by a start that
    works: one that fails later (no such interface) leaves it."""
    former = tmp_path / "jd2xxx-0x0A-nosuchcan0.nvm"
    (tmp_path / "jd2xxx-0x0A.nvm").write_bytes(b"\xff" * 768)
    r = run("--product", "jd2xxx", "--iface", "nosuchcan0", "--nvm-dir", str(tmp_path))
    assert r.returncode == 1, r.stderr
    assert sorted(os.listdir(tmp_path)) == ["jd2xxx-0x0A.nvm"]
    assert not former.exists()


def test_one_eeprom_file_for_two_instances(tmp_path):
    """--nvm D/x.nvm and --nvm-dir D naming one file: two users of one
    EEPROM would overwrite each other's saves."""
    path = tmp_path / "jd2xxx-0x0B-vcan0.nvm"
    r = run("--product", "jd1xxx", "--iface", "vcan0", "--nvm", str(path), "--nvm-dir",
            str(tmp_path), "--node", "jd2xxx@0x0B")
    assert r.returncode == 2  # (the log, on stderr without --log, comes first)
    assert r.stderr.strip().splitlines()[-1] == \
        f"canopen-sensor: --nvm-dir {tmp_path}: {path}: the EEPROM file of jd1xxx too (one " \
        "file, one instance) (see --help)"


def test_log_time_stamps(tmp_path):
    """The log's time stamps count from the program's start (they were the
    kernel's uptime), or are the UTC wall clock with --log-time wall."""
    import datetime
    import re
    log = tmp_path / "start.log"
    r = run("--product", "jd2xxx", "--iface", "nosuchcan0", "--log", str(log))
    assert r.returncode == 1
    stamps = [float(m) for m in re.findall(r"^\[ *(\d+\.\d{3})\] ", log.read_text(), re.M)]
    assert stamps and all(0 <= t < 5 for t in stamps), log.read_text()
    log = tmp_path / "wall.log"
    before = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
    r = run("--product", "jd2xxx", "--iface", "nosuchcan0", "--log", str(log),
            "--log-time", "wall")
    assert r.returncode == 1
    m = re.match(r"^\[(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d)\.\d{3}\] ", log.read_text())
    assert m, log.read_text()
    when = datetime.datetime.strptime(m[1], "%Y-%m-%d %H:%M:%S").replace(
        tzinfo=datetime.timezone.utc)
    assert before <= when <= before + datetime.timedelta(seconds=5)
    one_line(run("--product", "jd2xxx", "--iface", "vcan0", "--log-time", "boot"), 2,
             "--log-time takes start or wall, not 'boot'")


@pytest.mark.parametrize("spec,text", [
    ("foo:1", "--control foo:1: give unix:PATH or tcp:PORT"),
    ("tcp:99999", "--control tcp:99999: not a port 1..65535"),
    ("tcp:0", "--control tcp:0: not a port 1..65535"),
    ("unix:", "--control unix:: empty or longer than 107 bytes"),
    ("unix:" + "d/" * 60, "empty or longer than 107 bytes"),
])
def test_control_form_checked_with_the_command_line(spec, text):
    """A --control that has neither form is a wrong command line (2), found
    before anything opens: the same answer with or without CAN."""
    one_line(run("--product", "jd2xxx", "--iface", "vcan0", "--control", spec), 2, text)


CTL = str(Path(__file__).resolve().parents[2] / "tools" / "ctl")


@pytest.mark.parametrize("port", ["\u0668\u0660", "\u0968\u0966", "\uff18\uff10", "\u00b2",
                                  "8\u0660", "+80", " 80", "80 ", "0x50", "", "0", "65536"])
def test_ctl_port_ascii_digits_only(port):
    """tools/ctl tcp:PORT: ASCII 0-9 only. Arabic-Indic, Devanagari or
    full-width digits were taken (str.isdigit and int() accept them) and
    a connection to port 80 tried; now a wrong command line, sent nowhere."""
    r = subprocess.run([CTL, f"tcp:{port}", "get"], capture_output=True, text=True, timeout=10)
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith(f"ctl: tcp:{port}: not a port 1..65535 (usage: tools/ctl"), \
        r.stderr
