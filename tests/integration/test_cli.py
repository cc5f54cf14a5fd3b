"""The command line of canopen-sensor (no CAN needed)."""
import subprocess

from conftest import BINARY

VARIANTS = ["xy10", "xy15", "xy20", "xy30", "xy45", "xy60", "xy90", "z360"]
PRODUCT_IDS = [f"dst-{m}-{v}" for m in ("x730", "x710") for v in VARIANTS] + [
    "inx360d", "iny360d"]


def run(*args, stdin=None):
    return subprocess.run([BINARY, *args], capture_output=True, text=True, timeout=10,
                          input=stdin)


def test_list_products():
    r = run("--list-products")
    assert r.returncode == 0
    ids = [line.split()[0] for line in r.stdout.splitlines()]
    for pid in PRODUCT_IDS:
        assert pid in ids
    assert all(len(line.split(None, 1)) == 2 for line in r.stdout.splitlines())


def test_help():
    r = run("--help")
    assert r.returncode == 0
    for word in ("--product", "--iface", "--nvm", "--log", "--list-products", "--led-chip",
                 "--eds", "set x=<deg> y=<deg>", "fault NAME on|off", "quit"):
        assert word in r.stdout


def test_usage_errors():
    assert run().returncode == 2
    r = run("--product", "nope", "--iface", "vcan0")
    assert r.returncode == 2 and "unknown product 'nope'" in r.stderr
    r = run("--product", "dst-x730-xy30")
    assert r.returncode == 2 and "usage:" in r.stderr
    r = run("--product", "dst-x730-xy30", "--iface", "vcan0,vcan1")
    assert r.returncode == 2 and "one interface" in r.stderr


def test_missing_interface_is_a_clear_error(tmp_path):
    r = run("--product", "dst-x730-xy30", "--iface", "nosuchcan0", "--nvm",
            str(tmp_path / "e.bin"))
    assert r.returncode == 1
    assert "nosuchcan0" in r.stderr or "CAN socket" in r.stderr
