"""tools/update against the rv32-virt bootloader and its DST X730
application in QEMU, over the serial line (SLCAN: --interface slcan
--channel socket://127.0.0.1:PORT): where vcan cannot run, this is the
tool's end-to-end test (test_progdl.py runs it against the Linux program
on vcan). An update through the hand-over to the bootloader; a node up to
date is skipped; an image whose program identification is not the one
the application reports is caught after the start (a master would update
it at every boot); a power cut during the download leaves a bootloader
that the next run updates.

Images: build-rv32-virt (CO_RV32_BUILD: another build directory),
bin/boot.elf and bin/fw-dst-x730-xy30-app.elf, wrapped here by
tools/mkimage with the program identification the application reports."""
import os
import pathlib
import signal
import subprocess
import sys
import time

import pytest
from targets import free_port

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("CO_RV32_BUILD", ROOT / "build-rv32-virt")) / "bin"
PRODUCT = "dst-x730-xy30"
NODE = 0x7F


def program():
    return os.environ.get("CANOPEN_SENSOR", str(ROOT / "build" / "bin" / "canopen-sensor"))


def image(tmp_path, pid):
    elf = BUILD / f"fw-{PRODUCT}-app.elf"
    if not elf.exists():
        pytest.fail(f"{elf} is missing: build the rv32-virt images (docs/emulator.md)")
    out = tmp_path / f"app-{pid:x}.img"
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "mkimage"), "--product", PRODUCT,
                        "--board", "rv32-virt", "--program-id", hex(pid), "--other-program-id",
                        "--elf", str(elf),
                        "--program", program(), "-o", str(out)],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return out


class Emu:
    """tools/emu --boot with its flash file kept across starts."""

    def __init__(self, tmp_path):
        self.flash = tmp_path / "flash.bin"
        self.log = open(tmp_path / "emu.log", "a")
        self.proc = None
        self.port = None

    def start(self, install=None):
        boot = BUILD / "boot.elf"
        if not boot.exists():
            pytest.fail(f"{boot} is missing: build the rv32-virt images (docs/emulator.md)")
        self.port = free_port()
        cmd = [sys.executable, str(ROOT / "tools" / "emu"), "--board", "rv32-virt", "--product",
               PRODUCT, "--port", str(self.port), "--flash", str(self.flash), "--boot",
               "--image", str(boot)]
        if install is not None:
            cmd += ["--install", str(install)]
        self.proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=self.log,
                                     stderr=subprocess.PIPE, text=True, start_new_session=True)
        for line in self.proc.stderr:
            self.log.write(line)
            if line.startswith("emu: ready"):
                return
        pytest.fail(f"tools/emu did not start: see {self.log.name}")

    def cut(self):
        if self.proc is not None and self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()

    def update(self, *args, wait=True):
        cmd = [sys.executable, "-u", "-X", "faulthandler", str(ROOT / "tools" / "update"), "--interface", "slcan",
               "--channel", f"socket://127.0.0.1:{self.port}", "--node", hex(NODE),
               "--timeout", "20", *map(str, args)]
        if not wait:
            return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                    text=True)
        return subprocess.run(cmd, capture_output=True, text=True, timeout=300)


@pytest.fixture
def emu(tmp_path):
    e = Emu(tmp_path)
    yield e
    e.cut()


def reported(stdout):
    """1F56h:1 as the identity line of tools/update's output gives it."""
    for line in stdout.splitlines():
        if "identity:" in line and "1F56h:1" in line:
            return int(line.rsplit(" ", 1)[1], 16)
    raise AssertionError(f"no identity line in {stdout!r}")


def test_update_through_the_bootloader(emu, tmp_path):
    """The running application reports its build's program identification;
    an image of that number is up to date; --force updates it through the
    stop's hand-over, by block SDO, and the application boots again."""
    probe = image(tmp_path, 0x7E570001)
    emu.start(install=probe)
    r = emu.update(probe)
    own = reported(r.stdout)
    assert own != 0x7E570001, "the application reports the image's number: pick another"
    # The probe's number is not what the application reports: after the
    # start the tool finds the application's own and says so (a master
    # comparing 1F56h:1 would download it again at every boot).
    assert r.returncode == 1, r.stdout + r.stderr
    assert f"start: after the boot-up 1F56h:1 reads {own:#010x}" in r.stderr, r.stderr
    assert "stop: 1F51h:1 reads 0 (stopped), after a boot-up" in r.stdout, r.stdout
    good = image(tmp_path, own)
    r = emu.update(good)
    assert r.returncode == 0 and "up to date" in r.stdout, r.stdout + r.stderr
    r = emu.update("--force", good)
    assert r.returncode == 0, r.stdout + r.stderr
    for step in ("by block SDO", "flash: 1F57h:1 reads 0x00000000 (ok)",
                 f"verify: 1F56h:1 reads {own:#010x}", "start: boot-up",
                 f"started: 1F56h:1 reads {own:#010x}, 1F51h:1 reads 1"):
        assert step in r.stdout, (step, r.stdout)


def test_power_cut_during_the_download(emu, tmp_path):
    """A power cut in the middle of tools/update's download: the tool fails
    naming the step; the device comes back as its bootloader with no valid
    program (1F56h:1 0), and the next run updates it by segmented SDO."""
    probe = image(tmp_path, 0x7E570002)
    emu.start(install=probe)
    # Another product's image: refused before anything is stopped; the
    # identity line gives the number the application reports.
    payload = tmp_path / "other.bin"
    payload.write_bytes(bytes(256))
    other = tmp_path / "other.img"
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "mkimage"), "--product", "jd1xxx",
                        "--board", "rv32-virt", "--program-id", "1", "--payload", str(payload),
                        "--load-addr", "0x80020000", "--program", program(), "-o", str(other)],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    r = emu.update(other)
    assert r.returncode == 1 and "identity: no IMAGE" in r.stderr, r.stdout + r.stderr
    assert "pre-op" not in r.stdout
    own = reported(r.stdout)
    good = image(tmp_path, own)
    p = emu.update("--force", good, wait=False)
    seen = ""
    end = time.monotonic() + 120
    while "25%" not in seen and time.monotonic() < end and p.poll() is None:
        seen += p.stdout.readline()
    assert "25%" in seen, seen
    emu.cut()
    try:
        out, err = p.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        p.send_signal(signal.SIGABRT)  # -X faulthandler: where it waits
        out, err = p.communicate(timeout=10)
        pytest.fail("tools/update did not end within 60 s of the power cut:\n" + out + err)
    assert p.returncode == 1 and "download (1F50h:1)" in err, seen + out + err
    emu.start()
    r = emu.update("--segmented", good)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "1F56h:1 0x00000000" in r.stdout and "1F51h:1 reads 3 (no valid program)" in r.stdout, \
        r.stdout
    assert "by segmented SDO" in r.stdout and \
        f"started: 1F56h:1 reads {own:#010x}, 1F51h:1 reads 1" in r.stdout, r.stdout
