"""The micro:bit bootloader (boards/common/boot_main.c built for the
nRF51822 in its 4 KiB) in QEMU's microbit machine, over the serial line
(SLCAN), with the `canopen` master: it takes the product's image by block
SDO into the application area and runs it; from the running application
a stop hands over to it, and a second image goes in by segmented SDO and
runs; another product's image is refused, and the product's own goes in
after a new clear.

QEMU keeps the nRF51 flash in memory and re-applies the images it loaded
at every system reset, so the machine is given the bootloader and its
boot-info page (the product's identity, as an update from the factory
image leaves it: docs/program-download.md, "Bootloaders and flash
layouts") and no application: what the bootloader writes into the
application area is not a loaded image and survives the start's reset,
as on silicon. The bootloader and the images come from build-microbit
(ctest's fixture emu.images_microbit builds them)."""
import os
import pathlib
import struct
import subprocess
import time
import zlib

import can
import canopen
import pytest
from targets import free_port, slcan_bus

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("CO_MICROBIT_BUILD", ROOT / "build-microbit")) / "bin"
PRODUCT = "dst-x730-xy30"
NODE = 0x7F
INFO_ADDR = 0x1000  # layout.ld: the boot-info page
EEPROM = (0x3E000, 8 << 10)  # layout.ld: after the application area
BOOT_INFO_MAGIC = 0x464E4942  # boot.h


def need(path):
    if not path.exists():
        pytest.fail(f"{path} is missing: build the micro:bit images (docs/emulator.md)")
    return path


def image(tmp_path, program_id, product=PRODUCT):
    """The product's application wrapped by tools/mkimage for this board."""
    out = tmp_path / f"{product}-{program_id:x}.img"
    subprocess.run([str(ROOT / "tools" / "mkimage"), "--product", product, "--board", "microbit",
                    "--program-id", str(program_id), "--other-program-id",
                    "--elf", str(need(BUILD / f"fw-{product}-app.elf")), "-o", str(out)],
                   check=True, capture_output=True,
                   env={**os.environ, "CANOPEN_SENSOR": os.environ.get(
                       "CANOPEN_SENSOR", str(ROOT / "build" / "bin" / "canopen-sensor"))})
    return out


def boot_info(img):
    """The boot-info record (boot.h's boot_ident_t) of the image's product
    at node NODE, 250 kbit/s: 1000h and 1018h:1-3 and the product ID from
    its header, its CRC-32 last."""
    data = img.read_bytes()
    ident = struct.unpack_from("<4I", data, 20)
    rec = struct.pack("<6IBBH", BOOT_INFO_MAGIC, *ident, 0, NODE, 0, 250) + data[48:64]
    return rec + struct.pack("<I", zlib.crc32(rec))


class Microbit:
    def __init__(self, tmp_path):
        self.tmp = tmp_path
        self.proc = None

    def start(self, info):
        (self.tmp / "info.bin").write_bytes(info)
        (self.tmp / "ee.bin").write_bytes(b"\xff" * EEPROM[1])
        port = free_port()
        self.log = open(self.tmp / "qemu.log", "w")
        self.proc = subprocess.Popen(
            ["qemu-system-arm", "-M", "microbit", "-display", "none", "-monitor", "none",
             "-serial", f"tcp:127.0.0.1:{port},server=on,wait=on,nodelay=on",
             "-kernel", str(need(BUILD / "boot.elf")),
             "-device", f"loader,file={self.tmp / 'info.bin'},addr={INFO_ADDR:#x},force-raw=on",
             "-device", f"loader,file={self.tmp / 'ee.bin'},addr={EEPROM[0]:#x},force-raw=on"],
            stdin=subprocess.DEVNULL, stdout=self.log, stderr=subprocess.STDOUT)
        end = time.monotonic() + 10
        while True:  # QEMU listens a moment after it starts
            try:
                self.bus = slcan_bus(port)
                break
            except Exception:
                if time.monotonic() > end or self.proc.poll() is not None:
                    pytest.fail(f"qemu-system-arm did not listen: see {self.log.name}")
                time.sleep(0.1)
        self.bootups = []
        self.answers = []
        self.net = canopen.Network(self.bus)
        self.net.notifier = can.Notifier(self.bus, self.net.listeners, 0.1)
        self.net.subscribe(0x700 + NODE, lambda i, d, t: self.bootups.append(bytes(d)))
        self.net.subscribe(0x580 + NODE, lambda i, d, t: self.answers.append(bytes(d)))
        self.node = self.net.add_node(NODE, canopen.ObjectDictionary())
        self.node.sdo.RESPONSE_TIMEOUT = 1.0
        self.wait_bootup()

    def wait_bootup(self, timeout=5.0):
        end = time.monotonic() + timeout
        while not self.bootups and time.monotonic() < end:
            time.sleep(0.05)
        assert self.bootups == [b"\x00"], f"boot-ups seen: {self.bootups}"
        self.bootups.clear()

    def stop(self):
        if self.proc is not None and self.proc.poll() is None:
            self.net.notifier.stop()
            self.bus.shutdown()
            self.proc.kill()
            self.proc.wait()
            self.log.close()

    def u32(self, index, sub):
        return int.from_bytes(self.node.sdo.upload(index, sub), "little")

    def control(self, value):
        self.node.sdo.download(0x1F51, 1, bytes([value]))

    def download(self, path, block):
        data = path.read_bytes()
        with self.node.sdo.open(0x1F50, 1, "wb", size=len(data), block_transfer=block) as f:
            f.write(data)
        end = time.monotonic() + 10
        while self.u32(0x1F57, 1) & 1:  # busy: the image re-read from flash
            assert time.monotonic() < end, "1F57h stayed busy for 10 s"
            time.sleep(0.05)


@pytest.fixture
def mb(tmp_path):
    m = Microbit(tmp_path)
    yield m
    m.stop()


def test_update_by_block_then_from_the_application_by_segments(mb, tmp_path):
    first = image(tmp_path, 0x10000)
    mb.start(boot_info(first))
    # The bootloader, no program: the product's identity from its page.
    assert mb.u32(0x1000, 0) == 0x0008019A
    assert mb.u32(0x1F51, 1) == 3
    assert mb.u32(0x1F57, 1) == 1 << 1  # status 1: no valid program
    assert mb.u32(0x1F56, 1) == 0
    mb.control(3)
    mb.download(first, block=True)
    assert mb.u32(0x1F57, 1) == 0
    assert mb.u32(0x1F56, 1) == 0x10000
    assert mb.u32(0x1F51, 1) == 0  # a verified program, not started
    mb.control(1)
    mb.wait_bootup()  # the application, from the start's reset
    assert mb.u32(0x1F51, 1) == 1  # its side answers: started
    assert mb.u32(0x1F56, 1) == 0x10000
    # From the application: stop hands over; the bootloader boots up with
    # the installed image's identity, and a second image goes in.
    mb.control(0)
    mb.wait_bootup()
    assert mb.u32(0x1F51, 1) == 0
    assert mb.u32(0x1018, 1) == struct.unpack_from("<I", first.read_bytes(), 24)[0]
    second = image(tmp_path, 0x10001)
    mb.control(3)
    assert mb.u32(0x1F56, 1) == 0
    mb.download(second, block=False)
    assert mb.u32(0x1F56, 1) == 0x10001
    mb.control(1)
    mb.wait_bootup()
    assert mb.u32(0x1F51, 1) == 1


def test_refuses_another_products_image(mb, tmp_path):
    own = image(tmp_path, 0x10000)
    mb.start(boot_info(own))
    mb.control(3)
    # The DST X710's image: 1000h and 1018h:1-3 as the X730's, another
    # product ID: refused at its header, 08000020h, 1F57h status 3.
    with pytest.raises(canopen.SdoAbortedError):
        mb.download(image(tmp_path, 0x10000, product="dst-x710-xy30"), block=True)
    aborts = [a for a in mb.answers if a[0] == 0x80]
    assert aborts and aborts[0] == bytes.fromhex("80501f0120000008")
    assert mb.u32(0x1F57, 1) == 3 << 1
    assert mb.u32(0x1F51, 1) == 3
    # Nothing may be written without a new clear (status 4), then it goes in.
    with pytest.raises(canopen.SdoAbortedError):
        mb.download(own, block=False)
    assert mb.u32(0x1F57, 1) == 4 << 1
    mb.control(3)
    mb.download(own, block=False)
    assert mb.u32(0x1F56, 1) == 0x10000
