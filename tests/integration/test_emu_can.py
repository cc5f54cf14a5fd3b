"""tools/emu --can on a real SocketCAN bus, inside tools/vcan-run: the
rv32-virt image's SJA1000 (QEMU's Kvaser PCIcan) bridged to vcan0. The
image starts at once (nobody on its serial line) and is a node on vcan0;
its serial line answers the input language and carries no frames; an
interface that is down is refused. Then a mixed bus: the image, two
canopen-sensor processes and the master on one vcan0, every node's
heartbeats and event-timer TPDOs each on time, none missing, none doubled.

The runs that need no CAN interface (--can on the micro:bit, a missing or
non-CAN interface) are in test_emu.py, on the host."""
import socket
import statistics
import struct
import subprocess
import sys
import time

import can
import pytest

from conftest import IFACE, Sensor, line_within
from facts import PRODUCTS
from targets import EMU, CanEmuTarget, Master, free_port, period_fault

IMAGE = "jd1xxx"  # node 10; the mixed bus adds the Linux program's
OTHERS = ("dst-x730-xy30", "inx360d")  # nodes 0x7F and 1: SYNC types, as the JD


@pytest.fixture(autouse=True)
def vcan():
    if not (subprocess.run(["ip", "link", "show", IFACE], capture_output=True).returncode == 0):
        pytest.fail(f"{IFACE} is not up: run these tests through tools/vcan-run")


def emu_can(port, iface=IFACE, flash=None):
    """tools/emu --can (by this interpreter: see CanEmuTarget._command)."""
    cmd = [sys.executable, str(EMU), "--board", "rv32-virt", "--product", IMAGE,
           "--port", str(port), "--can", iface]
    if flash is not None:
        cmd += ["--flash", str(flash)]
    return subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            start_new_session=True)


def read_line_until(proc, prefix, timeout):
    """tools/emu's standard error up to a line that starts with prefix,
    within timeout seconds in all."""
    end = time.monotonic() + timeout
    seen = []
    while not seen or not seen[-1].startswith(prefix):
        seen.append(line_within(proc.stderr, max(0.0, end - time.monotonic()),
                                f"{prefix!r} from tools/emu (so far: {''.join(seen)!r})"))
    return seen


def test_boots_onto_the_bus_with_nobody_on_its_serial_line(tmp_path):
    """The boot-up comes on vcan0 with nobody connected to the serial line
    (wait=off), the node answers SDO there; then the serial line answers
    an input line and carries no frame though the node sends heartbeats.
    Three starts: the time from tools/emu's start to the boot-up is
    printed (a figure of docs/emulator.md)."""
    node = PRODUCTS[IMAGE].nodes[0]
    bus = can.Bus(interface="socketcan", channel=IFACE)
    times = []
    try:
        for _ in range(3):
            port = free_port()
            while bus.recv(0) is not None:
                pass  # the last run's heartbeats
            t0 = time.monotonic()
            proc = emu_can(port, flash=tmp_path / "flash.bin")
            try:
                first = None  # the node's first frame
                end = t0 + 30
                while first is None and time.monotonic() < end:
                    m = bus.recv(0.5)
                    if m is not None and m.arbitration_id & 0x7F == node:
                        first = m
                    assert proc.poll() is None, proc.stderr.read().decode()
                assert first is not None, f"nothing from node {node:#x} on {IFACE} within 30 s"
                assert first.arbitration_id == 0x700 + node and bytes(first.data) == b"\0", \
                    f"the first frame of node {node:#x} is no boot-up: {first}"
                times.append(time.monotonic() - t0)
                # The ready line came before (a whole line; the image runs).
                read_line_until(proc, "emu: ready: ", 5)
                bus.send(can.Message(arbitration_id=0x600 + node, is_extended_id=False,
                                     data=bytes.fromhex("4000100000000000")))
                end = time.monotonic() + 2
                answer = None
                while answer is None and time.monotonic() < end:
                    m = bus.recv(0.5)
                    if m is not None and m.arbitration_id == 0x580 + node:
                        answer = m
                assert answer is not None and answer.data[0] == 0x43, f"SDO answer {answer}"
                assert struct.unpack_from("<I", answer.data, 4)[0] == PRODUCTS[IMAGE].device_type
                # Heartbeats every 20 ms: none of them on the serial line.
                bus.send(can.Message(arbitration_id=0x600 + node, is_extended_id=False,
                                     data=bytes.fromhex("2B17100014000000")))
                with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
                    s.sendall(b"get\r")
                    got = b""
                    end = time.monotonic() + 1.0
                    while time.monotonic() < end:
                        s.settimeout(max(0.01, end - time.monotonic()))
                        try:
                            chunk = s.recv(4096)
                        except socket.timeout:
                            break
                        if not chunk:
                            break
                        got += chunk
                lines = [l for l in got.decode(errors="replace").split("\r") if l.strip()]
                assert lines and lines[0].startswith("ok "), lines
                assert len(lines) == 1, f"more than the answer on the serial line: {lines}"
                beats = []
                end = time.monotonic() + 0.3
                while time.monotonic() < end:
                    m = bus.recv(0.05)
                    if m is not None and m.arbitration_id == 0x700 + node:
                        beats.append(m)
                assert beats, "no heartbeat on vcan0 after 1017h := 20 ms"
            finally:
                proc.terminate()
                rc = proc.wait(timeout=15)
            assert rc == 0
    finally:
        bus.shutdown()
        (tmp_path / "flash.bin").unlink(missing_ok=True)
    print(f"tools/emu --can: start to boot-up {', '.join(f'{t:.2f}' for t in times)} s, "
          f"median {statistics.median(times):.2f} s")


def test_refuses_an_interface_that_is_down():
    """vcan1 taken down: a usage error that says so (exit 2), QEMU never
    started; up again, accepted."""
    subprocess.run(["ip", "link", "set", "vcan1", "down"], check=True)
    try:
        r = subprocess.run([sys.executable, str(EMU), "--board", "rv32-virt", "--product", IMAGE,
                            "--port", str(free_port()), "--can", "vcan1"],
                           capture_output=True, text=True, timeout=60)
    finally:
        subprocess.run(["ip", "link", "set", "vcan1", "up"], check=True)
    assert r.returncode == 2, r.stderr
    assert "vcan1: the interface is down (ip link set vcan1 up)" in r.stderr
    proc = emu_can(free_port(), iface="vcan1")
    try:
        read_line_until(proc, "emu: ready: ", 30)
    finally:
        proc.terminate()
        assert proc.wait(timeout=15) == 0


# The mixed bus: every node's heartbeat over MIX_WINDOW_S (its period the
# median gap, targets.period_fault, as the one suite's check), and its
# TPDO1 by SYNC counted exactly. Measured here
# inside User-Mode Linux, with the machine busy (load 6 on 2 cores): single
# frames 30-45 ms late at a 50 ms period, so gaps between frames tell a
# late frame from a missing or doubled one only on a quiet machine; a
# TPDO per SYNC does at any load: one lost or doubled SYNC or TPDO changes
# the count.
MIX_HB_MS, MIX_WINDOW_S = 100, 3.0
MIX_SYNCS, MIX_SYNC_GAP_S = 40, 0.025


def test_mixed_bus(tmp_path):
    """The image, two canopen-sensor processes and the master on vcan0:
    every boot-up seen, every node answers SDO, each node's heartbeats
    come at their period, and MIX_SYNCS SYNCs make exactly MIX_SYNCS /
    its SYNC type TPDO1s of every node: no SYNC lost or doubled on its way
    to a node (the image's through QEMU's bridge and its controller), no
    TPDO lost or doubled on its way to the master."""
    image_dir, a_dir, b_dir = (tmp_path / d for d in ("image", "a", "b"))
    for d in (image_dir, a_dir, b_dir):
        d.mkdir()
    master = Master(CanEmuTarget(IMAGE, image_dir))
    sensors = [Sensor(p, d) for p, d in zip(OTHERS, (a_dir, b_dir))]
    try:
        master.power_on(PRODUCTS[IMAGE].nodes)
        for s in sensors:
            master.frames.clear()
            s.start()
            for n in PRODUCTS[s.product].nodes:
                m = master.frames.wait_for(0x700 + n, timeout=3, pred=lambda m: bytes(m.data) == b"\0")
                assert m is not None, f"{s.product}: no boot-up of node {n:#x}"
        facts = {n: PRODUCTS[p] for p in (IMAGE,) + OTHERS for n in PRODUCTS[p].nodes}
        assert len(facts) == 3 and all(f.sync_type for f in facts.values())
        for n, f in facts.items():
            sdo = master.node(n).sdo
            assert bytes(sdo.upload(0x1000, 0)) == struct.pack("<I", f.device_type), f"node {n:#x}"
            sdo.download(0x1800, 2, bytes([f.sync_type]))
            sdo.download(0x1017, 0, struct.pack("<H", MIX_HB_MS))
        master.send(0x000, bytes([0x01, 0]))  # all operational
        time.sleep(0.3)
        master.frames.clear()
        got = list(master.frames.stream(MIX_WINDOW_S))
        wrong = []
        for n in facts:
            times = [t for t, m in got if m.arbitration_id == 0x700 + n]
            print(f"node {n:#x}: {len(times)} heartbeats in {MIX_WINDOW_S} s")
            fault = period_fault(times, MIX_HB_MS, MIX_WINDOW_S)
            if fault:
                wrong.append(f"node {n:#x}: heartbeats: {fault}")
        cobs = {f.tpdo_cob.of(n) for n, f in facts.items()}
        early = sorted({m.arbitration_id for _, m in got if m.arbitration_id in cobs})
        if early:
            wrong.append(f"TPDO1 without SYNC on {', '.join(f'{c:03X}h' for c in early)}")
        master.frames.clear()
        for _ in range(MIX_SYNCS):
            master.send(0x080)
            time.sleep(MIX_SYNC_GAP_S)
        got = list(master.frames.stream(0.5))
        for n, f in facts.items():
            count = sum(1 for _, m in got if m.arbitration_id == f.tpdo_cob.of(n)
                        and not m.is_remote_frame)
            print(f"node {n:#x}: {count} TPDO1s for {MIX_SYNCS} SYNCs, type {f.sync_type}")
            if count != MIX_SYNCS // f.sync_type:
                wrong.append(f"node {n:#x}: {count} TPDO1s for {MIX_SYNCS} SYNCs, "
                             f"want {MIX_SYNCS // f.sync_type}")
        assert not wrong, "; ".join(wrong)
    finally:
        for s in sensors:
            s.stop()
        master.close()
