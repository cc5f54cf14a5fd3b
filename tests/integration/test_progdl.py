"""Program download (CiA 302-3) on the Linux program: canopen-sensor
--program-download on vcan0 against the canopen master and tools/update,
one product of each family (the redundant GSH-A for a device of two
nodes): an update by block and by segmented SDO, refusals, and a process
killed at each point of an update. Images from tools/mkimage. The same
flow on the program's own port without vcan: tests/unit/test_linux_prog.c.
Behaviour: docs/program-download.md, "The Linux program"."""
import subprocess
import sys
import time

import pytest
from canopen.sdo.exceptions import SdoAbortedError

import facts
from conftest import BINARY, ROOT, boot

PRODUCTS = ("dst-x730-xy30", "gsh-a-redundant", "jd2xxx", "inx360d")
OPTION = ["--program-download"]
NOT_CLEARED_OR_STATE = 0x08000022
REFUSED = 0x08000020


# Bytes of payload in the tests' images: the Linux program keeps them and
# runs none, so they are any bytes; enough for a download of many blocks.
PAYLOAD = 6000


def mkimage(tmp_path, product, pid, name=None):
    """The image of product for the Linux program with program ID pid and
    PAYLOAD bytes of payload: its bytes (and the file, tmp_path/name)."""
    out = tmp_path / (name or f"{product}-{pid:08x}.img")
    payload = tmp_path / "payload.bin"
    payload.write_bytes(bytes((i * 7 + 3) & 0xFF for i in range(PAYLOAD)))
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "mkimage"), "--product", product,
                        "--board", "linux", "--program-id", hex(pid), "--program", BINARY,
                        "--payload", str(payload), "--load-addr", "0", "-o", str(out)],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return out.read_bytes()


def u32(node, index, sub=1):
    return int.from_bytes(node.sdo.upload(index, sub), "little")


def control(node):
    return node.sdo.upload(0x1F51, 1)[0]


def abort_code(fn):
    with pytest.raises(SdoAbortedError) as e:
        fn()
    return e.value.code


def stop_and_clear(node):
    """What a master does before it downloads: pre-operational, stop, clear."""
    node.nmt.send_command(0x80)
    time.sleep(0.05)
    node.sdo.download(0x1F51, 1, b"\x00")
    node.sdo.download(0x1F51, 1, b"\x03")


def download(node, data, block):
    with node.sdo.open(0x1F50, 1, "wb", size=len(data), block_transfer=block,
                       force_segment=not block) as f:
        f.write(data)


def flash_done(node, timeout=5.0):
    """1F57h:1, polled every 100 ms until its busy bit ends."""
    end = time.monotonic() + timeout
    while True:
        v = u32(node, 0x1F57)
        if not v & 1:
            return v
        assert time.monotonic() < end, f"1F57h:1 still busy ({v:#x}) after {timeout} s"
        time.sleep(0.1)


def start(node, bus, ids):
    """1F51h:1 = 1, then the boot-up of every node of the device."""
    bus.clear()
    node.sdo.download(0x1F51, 1, b"\x01")
    want = {0x700 + i for i in ids}
    end = time.monotonic() + 3.0
    while want and time.monotonic() < end:
        m = bus.wait_for_any(lambda m: m.arbitration_id in want and bytes(m.data) == b"\0",
                             timeout=end - time.monotonic())
        if m is not None:
            want.discard(m.arbitration_id)
    assert not want, f"no boot-up of {sorted(hex(c - 0x700) for c in want)} after the start"


def restart(sensor, bus, nid):
    """Power the device again and wait for its boot-up."""
    bus.clear()
    sensor.start()
    m = bus.wait_for(0x700 + nid, timeout=3, pred=lambda m: bytes(m.data) == b"\0")
    assert m is not None, f"no boot-up from node {nid:#x} after the restart"


def version(node):
    """100Ah, or None where the product has none."""
    try:
        return node.sdo.upload(0x100A, 0).decode()
    except SdoAbortedError as e:
        assert e.code == 0x06020000
        return None


@pytest.fixture(params=PRODUCTS)
def device(request, sensor_factory, network, bus, tmp_path):
    product = request.param
    ids = facts.PRODUCTS[product].nodes
    sensor = sensor_factory(product, args=OPTION)
    node = boot(sensor, network, bus, ids[0])
    return product, ids, sensor, node


@pytest.mark.parametrize("block", [True, False], ids=["block", "segmented"])
def test_update(device, bus, tmp_path, block):
    """Stop, clear, download, verify, start: the device boots up again as
    the new program (100Ah says so where the product has one), and a
    restart runs it too."""
    product, ids, sensor, node = device
    own = u32(node, 0x1F56)
    assert own != 0 and control(node) == 1 and u32(node, 0x1F57) == 0
    base = version(node)
    new = (own + 0x101) & 0xFFFFFFFF
    data = mkimage(tmp_path, product, new)
    stop_and_clear(node)
    assert control(node) == 3 and u32(node, 0x1F56) == 0
    t0 = time.monotonic()
    download(node, data, block)
    took = time.monotonic() - t0
    assert flash_done(node) == 0
    assert u32(node, 0x1F56) == new and control(node) == 0
    start(node, bus, ids)
    assert u32(node, 0x1F56) == new and control(node) == 1
    if base is not None:
        assert version(node) == f"{base}, program {new:08X}"
    assert took < 10, f"{len(data)} bytes took {took:.1f} s"
    sensor.stop()
    restart(sensor, bus, ids[0])
    assert u32(node, 0x1F56) == new and control(node) == 1


def test_tools_update(device, tmp_path):
    """tools/update: updates, then finds the node up to date; --force and
    --segmented update again; an image for another device is refused
    before anything is stopped."""
    product, ids, sensor, node = device
    own = u32(node, 0x1F56)
    img = tmp_path / "new.img"
    mkimage(tmp_path, product, own ^ 0x00FF0000, "new.img")

    def update(*args):
        return subprocess.run([sys.executable, str(ROOT / "tools" / "update"), "--channel",
                               "vcan0", "--node", str(ids[0]), *args], capture_output=True,
                              text=True, timeout=120)
    r = update(str(img))
    assert r.returncode == 0, r.stdout + r.stderr
    assert "started: 1F56h:1 reads" in r.stdout and "updated" in r.stdout, r.stdout
    assert u32(node, 0x1F56) == own ^ 0x00FF0000 and control(node) == 1
    r = update(str(img))
    assert r.returncode == 0 and "up to date" in r.stdout, r.stdout + r.stderr
    r = update("--force", "--segmented", str(img))
    assert r.returncode == 0 and "by segmented SDO" in r.stdout, r.stdout + r.stderr
    other = "jd2xxx" if product != "jd2xxx" else "inx360d"
    mkimage(tmp_path, other, 5, "other.img")
    r = update(str(tmp_path / "other.img"))
    assert r.returncode == 1 and "identity: no IMAGE" in r.stderr, r.stdout + r.stderr
    assert control(node) == 1  # nothing was stopped


def test_refusals(device, bus, tmp_path):
    """A download without a clear leaves the program running; after the
    clear, another product's image, a truncated one and a wrong CRC are
    refused (08000020h, 1F57h status 3) and leave a device with its
    identity and no program, which the next download updates."""
    product, ids, sensor, node = device
    own = u32(node, 0x1F56)
    identity = [u32(node, 0x1000, 0), u32(node, 0x1018, 1), u32(node, 0x1018, 2)]
    good = mkimage(tmp_path, product, own + 7)
    assert abort_code(lambda: download(node, good, True)) == NOT_CLEARED_OR_STATE
    assert control(node) == 1 and u32(node, 0x1F56) == own
    other = mkimage(tmp_path, "jd2xxx" if product != "jd2xxx" else "inx360d", own + 7)
    damaged = bytearray(good)
    damaged[-100] ^= 0x01  # a byte of the payload
    for name, data in (("other product", other), ("truncated", good[:-3]),
                       ("wrong CRC", bytes(damaged))):
        stop_and_clear(node)
        code = abort_code(lambda: download(node, data, True))
        assert code == REFUSED, f"{name}: abort {code:#x}"
        assert u32(node, 0x1F57) == 3 << 1, name
        assert control(node) == 3 and u32(node, 0x1F56) == 0, name
        assert [u32(node, 0x1000, 0), u32(node, 0x1018, 1), u32(node, 0x1018, 2)] == identity
    stop_and_clear(node)
    download(node, good, True)
    assert flash_done(node) == 0
    start(node, bus, ids)
    assert u32(node, 0x1F56) == own + 7 and control(node) == 1


# Where a process is killed: after the stop, after the clear, after a part
# of the image (bytes), after the whole image was checked (before start).
CUTS = ["stop", "clear", 7, 301, 2996, "almost-all", "flashed"]


@pytest.mark.parametrize("cut", CUTS, ids=[str(c) for c in CUTS])
def test_killed(device, bus, tmp_path, cut):
    """SIGKILL at each point of an update: the device comes back with the
    old program (before the clear), with no valid program and its identity
    (from the clear to the check), or with the whole new one (after it);
    never a part of it. Then a second update completes."""
    product, ids, sensor, node = device
    own = u32(node, 0x1F56)
    dt = u32(node, 0x1000, 0)
    new = (own + 0x200) & 0xFFFFFFFF
    data = mkimage(tmp_path, product, new)
    node.nmt.send_command(0x80)
    time.sleep(0.05)
    node.sdo.download(0x1F51, 1, b"\x00")
    if cut != "stop":
        node.sdo.download(0x1F51, 1, b"\x03")
    if cut == "flashed":
        download(node, data, True)
        assert flash_done(node) == 0
    elif cut != "clear":
        # Whole segments only (a short one ends a transfer), short of the end.
        n = (len(data) - 1 if cut == "almost-all" else cut) // 7 * 7
        f = node.sdo.open(0x1F50, 1, "wb", size=len(data), force_segment=True, buffering=0)
        pos = 0
        while pos < n:
            pos += f.write(data[pos:min(pos + 7, n)])
        f._done = True  # canopen 2.4.1: no end of transfer sent when it is dropped
    sensor.kill()
    restart(sensor, bus, ids[0])
    assert u32(node, 0x1000, 0) == dt
    if cut == "stop":
        assert control(node) == 1 and u32(node, 0x1F56) == own
    elif cut == "flashed":
        assert control(node) == 1 and u32(node, 0x1F56) == new
    else:
        assert control(node) == 3 and u32(node, 0x1F56) == 0 and u32(node, 0x1F57) == 1 << 1
    second = mkimage(tmp_path, product, new + 1)
    stop_and_clear(node)
    download(node, second, True)
    assert flash_done(node) == 0
    start(node, bus, ids)
    assert u32(node, 0x1F56) == new + 1 and control(node) == 1
