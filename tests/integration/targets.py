"""The targets of the one integration suite (test_targets.py): where a
product runs and how a test powers it, cuts its power, types on its input
lines and reaches its bus.

- linux: the canopen-sensor program on SocketCAN vcan0 (run the tests
  through tools/vcan-run); the simulated input language on its control
  socket (--control unix:PATH), answered there ("ok" / "error: ...");
  --nvm FILE is its EEPROM.
- rv32-virt, microbit: the bare-metal image build-<board>/bin/fw-<ID>.elf in
  qemu, started by tools/emu; the bus is python-can's slcan interface on
  the image's serial line (socket://127.0.0.1:PORT); the input language is
  written on the same line and answered there ("ok" / "error: ...");
  --flash FILE is the flash that holds the EEPROM emulation.
- rv32-can: the rv32-virt image in qemu with its SJA1000 (QEMU's Kvaser
  PCIcan) on vcan0 (tools/emu --can vcan0; run the tests through
  tools/vcan-run): the bus is python-can's socketcan on vcan0, as for
  linux; the serial line carries the input language alone, answered
  there; --flash FILE as for rv32-virt.

A Target is one device with one non-volatile memory that lives as long as
the target object: start() is power on (returns the python-can bus on
which the device's first frame, its boot-up, is still to come), stop() a
clean power off, kill() a power cut. Everything the tests check goes over
the bus; the target only adds what a bench would: power and the inputs.
"""
import contextlib
import os
import pathlib
import queue
import signal
import socket
import subprocess
import sys
import threading
import time

import can
from can.interfaces.slcan import slcanBus
from serial.urlhandler import protocol_socket

from conftest import BINARY, ROOT, Sensor

EMU = ROOT / "tools" / "emu"


# How long a write to the device's non-volatile memory may take to reach
# the file a restart reads: canopen-sensor writes its --nvm file before it
# answers, rv32-virt's CFI flash is written through by qemu; the micro:bit's
# flash lives in qemu's memory and tools/emu copies the EEPROM pages to the
# file every 100 ms (--snapshot-ms), so a power cut there acts up to 100 ms
# earlier.
PERSIST_S = {"microbit": 0.15}


class TargetError(AssertionError):
    """A target could not do what the test asked (an assertion: the test fails
    and says why, it is never skipped)."""


class Target:
    """One device under test; see the module comment."""

    name = "?"
    # How long the master waits for an SDO or LSS answer: a bound on the
    # wait, not a judgement of the device (docs/testing.md, "Bounds and
    # timing"). canopen's own 0.3 s was too short for qemu on a loaded
    # machine: at a load of 13 four of the 112 rv32-virt tests failed with
    # "No SDO response received"; CanEmuTarget has a reason of its own.
    RESPONSE_TIMEOUT = 2.0

    def __init__(self, product, tmp_path):
        self.product = product
        self.tmp = tmp_path
        self.bus = None

    def start(self):
        """Power on; returns the bus (python-can) from before the first frame."""
        raise NotImplementedError

    def stop(self):
        """Clean power off (SIGTERM); returns the exit status. The bus stays
        open (and silent) until release()."""
        raise NotImplementedError

    def kill(self):
        """Power cut (SIGKILL), at once, whatever the device is doing."""
        raise NotImplementedError

    def release(self):
        """Close the bus start() returned (after its reader stopped)."""
        if self.bus is not None:
            self.bus.shutdown()
            self.bus = None

    def inject(self, line):
        """One line of the simulated input language (`set ...`, `fault ...`, `can ...`)."""
        raise NotImplementedError

    def settle(self):
        """Wait until what the device wrote to its non-volatile memory would
        survive a power cut (see PERSIST_S)."""
        time.sleep(PERSIST_S.get(self.name, 0.0))

    def close(self):
        """End whatever still runs (the test's teardown)."""
        raise NotImplementedError


class LinuxTarget(Target):
    """canopen-sensor on vcan0, with --nvm and --log in the test's directory."""

    name = "linux"

    def __init__(self, product, tmp_path):
        super().__init__(product, tmp_path)
        if not pathlib.Path("/sys/class/net/vcan0").exists():
            raise TargetError("vcan0 is not up: run the linux target through tools/vcan-run")
        self.sensor = Sensor(product, tmp_path)

    def start(self):
        # The bus first, so that the boot-up is seen.
        self.bus = can.Bus(interface="socketcan", channel="vcan0")
        self.sensor.start()
        return self.bus

    def stop(self):
        return self.sensor.stop()

    def kill(self):
        return self.sensor.kill()

    def inject(self, line):
        """Sends the line through the control socket; anything but "ok" fails
        the test. A `set` is read back with `get` (Sensor.check_taken): the
        node's input itself, not the log line the program writes for it."""
        if not self.sensor.alive():
            raise TargetError(f"inject {line!r}: canopen-sensor is not running")
        answer = self.sensor.command(line)
        if answer != "ok":
            raise TargetError(f"linux: {line!r} answered {answer!r}")
        self.sensor.check_taken(line)

    def close(self):
        self.sensor.stop()


@contextlib.contextmanager
def _input_kept():
    """pyserial's socket:// open() ends by discarding whatever has arrived
    (reset_input_buffer), and the image starts as the connection is made
    (qemu's wait=on): on a busy machine its boot-up came before that and
    was lost (seen on the microbit, 4 of 60 power-ons with four runs side by
    side). Kept while python-can opens the line; pyserial 3.5, pinned."""
    cls = protocol_socket.Serial
    saved = cls.reset_input_buffer
    cls.reset_input_buffer = lambda self: None
    try:
        yield
    finally:
        cls.reset_input_buffer = saved


def nodelay(bus):
    """Each frame of an slcan bus on a TCP serial line sent at once:
    pyserial's socket:// leaves Nagle's algorithm on, which holds a small
    line for the peer's delayed acknowledge (40 ms a round trip instead of
    1; a block download's segments after the first, 40 ms a block)."""
    bus.serialPortOrig._socket.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return bus


def slcan_bus(port):
    """python-can's slcan bus on the serial line at 127.0.0.1:PORT."""
    return nodelay(can.Bus(interface="slcan", channel=f"socket://127.0.0.1:{port}",
                           sleep_after_open=0))


class SerialLine(slcanBus):
    """python-can's slcan bus on an emulated board's serial line, which also
    carries the simulated input language's answers: lines that are no SLCAN
    frame ("ok", "error: ...") are kept in .answers instead of dropped. A
    line that closes under it (qemu killed) is no error: .lost is set and
    the bus reads nothing from then on. _read is python-can 4.6's own
    (pinned in requirements.txt)."""

    FRAME_STARTS = "tTrRdDbBx"

    def __init__(self, port):
        self.answers = queue.Queue()
        self.lost = False
        with _input_kept():
            super().__init__(channel=f"socket://127.0.0.1:{port}", sleep_after_open=0)
        nodelay(self)

    def _read(self, timeout):
        if self.lost:
            time.sleep(min(timeout or 0.0, 0.05))
            return None
        try:
            line = super()._read(timeout)
        except can.CanError:
            self.lost = True
            return None
        text = (line or "").strip("\r\a")
        if text and text[0] not in self.FRAME_STARTS:
            self.answers.put(text)
        return line

    def write_line(self, text):
        """One text line on the serial line (the caller holds the send lock)."""
        self.serialPortOrig.write(text.encode() + b"\r")
        self.serialPortOrig.flush()

    def shutdown(self):
        # Our end of the socket first: pyserial's close() sleeps 0.3 s "in
        # case of quick reconnects", which a test with many power cycles pays.
        port = self.serialPortOrig
        sock, port._socket, port.is_open = port._socket, None, False
        if sock is not None:
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass  # the line was already gone (qemu killed)
            sock.close()
        try:
            super().shutdown()
        except can.CanError:
            pass  # its "C" command on the closed line


def free_port():
    """A TCP port free now on 127.0.0.1 (qemu binds it a moment later; a lost
    race shows as qemu's own error, and start() tries another port)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class EmuTarget(Target):
    """A product image in qemu through tools/emu, its serial line on a local
    TCP port, its flash in a file of the test's directory (kept across
    restarts: the same device powered again)."""

    CONNECT_TIMEOUT = 10.0

    def __init__(self, product, tmp_path, board):
        super().__init__(product, tmp_path)
        self.name = board
        self.board = board
        self.flash = tmp_path / f"flash-{board}.bin"
        self.image = ROOT / f"build-{board}" / "bin" / f"fw-{product}.elf"
        self.proc = None
        self.send_lock = None  # the master's, so that input lines never split a frame
        self.log = tmp_path / "emu.log"

    def _command(self, port):
        return [str(EMU), "--board", self.board, "--product", self.product,
                "--port", str(port), "--flash", str(self.flash)]

    def start(self):
        if not os.access(EMU, os.X_OK):
            raise TargetError(f"{EMU} is missing: the emulated targets need tools/emu")
        if not self.image.exists():
            raise TargetError(f"{self.image} is missing: build the {self.board} images "
                              f"(cmake -B build-{self.board} ...; see docs/emulator.md)")
        for _ in range(3):
            port = free_port()
            self.logf = open(self.log, "a")
            self.logf.write(f"--- start {' '.join(self._command(port))}\n")
            self.logf.flush()
            # Its own process group: kill() cuts qemu and whatever tools/emu runs.
            self.proc = subprocess.Popen(self._command(port), stdin=subprocess.DEVNULL,
                                         stdout=self.logf, stderr=subprocess.STDOUT,
                                         start_new_session=True)
            self.bus = self._connect(port)
            if self.bus is not None:
                return self.bus
            self._reap(signal.SIGKILL)
            if "port" not in self.log.read_text().splitlines()[-1]:
                break  # not a port another program took meanwhile: no retry
        raise TargetError(f"{self.board}: no serial line from tools/emu; its output:\n"
                          + self.log.read_text()[-2000:])

    def _connect(self, port):
        end = time.monotonic() + self.CONNECT_TIMEOUT
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                return None  # ended (port taken, bad arguments): see the log
            try:
                return SerialLine(port)
            except can.CanError:
                time.sleep(0.02)
        return None

    def _reap(self, sig=None):
        rc = None
        if self.proc is not None:
            if sig is not None and self.proc.poll() is None:
                try:
                    if sig == signal.SIGKILL:
                        os.killpg(self.proc.pid, sig)  # the power cut: the whole group
                    else:
                        self.proc.send_signal(sig)
                except ProcessLookupError:
                    pass
            try:
                rc = self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.logf.write(f"--- did not end in 10 s after signal {sig}: killed\n")
                try:
                    rc = self.proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    raise TargetError(f"{self.name}: tools/emu ({self.product}) did not end "
                                      "within 10 s of SIGKILL") from None
            self.proc = None
            self.logf.close()
        return rc

    def stop(self):
        return self._reap(signal.SIGTERM)

    def kill(self):
        return self._reap(signal.SIGKILL)

    def inject(self, line, timeout=1.0):
        """Writes the line on the serial line and waits for the image's answer;
        anything but "ok" fails the test."""
        if self.bus is None or self.bus.lost:
            raise TargetError(f"inject {line!r}: the {self.board} image is not running")
        while not self.bus.answers.empty():
            self.bus.answers.get_nowait()
        with self.send_lock:
            self.bus.write_line(line)
        try:
            answer = self.bus.answers.get(timeout=timeout)
        except queue.Empty:
            raise TargetError(f"{self.board}: no answer to {line!r} on the serial line within "
                              f"{timeout} s: the image does not take the simulated input "
                              "language (boards/common/serial_link)") from None
        if answer != "ok":
            raise TargetError(f"{self.board}: {line!r} answered {answer!r}")

    def close(self):
        self._reap(signal.SIGTERM)
        self.release()
        # 32 MiB on rv32-virt: not for pytest's kept directories (the log stays).
        self.flash.unlink(missing_ok=True)


class AnswerLine:
    """The image's serial line when its frames go through its CAN
    controller: a plain TCP client whose reader thread keeps every line
    that arrives ("ok", "error: ..."; the image ends each with CR). A line
    that closes under it (qemu killed) is no error: .lost is set."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=1.0)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.sock.settimeout(None)
        self.answers = queue.Queue()
        self.lost = False
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        buf = b""
        while True:
            try:
                chunk = self.sock.recv(4096)
            except OSError:
                chunk = b""
            if not chunk:
                self.lost = True
                return
            buf += chunk.replace(b"\n", b"\r")
            *lines, buf = buf.split(b"\r")
            for line in lines:
                if line.strip():
                    self.answers.put(line.decode(errors="replace").strip())

    def write_line(self, text):
        self.sock.sendall(text.encode() + b"\r")

    def close(self):
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass  # already gone (qemu killed)
        self.sock.close()
        self.reader.join(2.0)


class CanEmuTarget(EmuTarget):
    """The rv32-virt image in qemu with its SJA1000 on vcan0 (tools/emu
    --can vcan0): the bus is socketcan on vcan0, opened before power on;
    the serial line (an AnswerLine) takes the input language only."""

    IFACE = "vcan0"
    # An answer that writes flash (a save, a PF's autosaved write, LSS
    # store) comes after QEMU has written the CFI flash through, which
    # inside User-Mode Linux took 210-285 ms for the first save of a
    # device (a 256 KiB block erased) and 50-160 ms for the next ones
    # (20-30 ms with QEMU on the host): beyond canopen's 0.3 s under load.
    # Every other answer came within 1.4 ms (median) to 22 ms.
    RESPONSE_TIMEOUT = 2.0
    # From tools/emu's start to its "emu: ready" line: inside User-Mode
    # Linux 1.2-1.6 s, 2.3-3 s with a new flash file (32 MiB written).
    READY_TIMEOUT = 30.0

    def __init__(self, product, tmp_path):
        super().__init__(product, tmp_path, "rv32-virt")
        self.name = "rv32-can"
        if not pathlib.Path("/sys/class/net", self.IFACE).exists():
            raise TargetError(f"{self.IFACE} is not up: run the rv32-can target through "
                              "tools/vcan-run")
        self.line = None

    def _command(self, port):
        # tools/emu by this interpreter (it needs the standard library only):
        # its "python3" may be a version manager's shim, whose start took
        # 4-5 s a run inside User-Mode Linux here, against 0.3 s.
        return [sys.executable] + super()._command(port) + ["--can", self.IFACE]

    def start(self):
        # The bus first, so that the boot-up is seen (the image starts at
        # once: tools/emu --can runs the serial server with wait=off).
        self.bus = can.Bus(interface="socketcan", channel=self.IFACE)
        try:
            return self._start()
        except BaseException:
            self.release()
            raise

    def _start(self):
        if not os.access(EMU, os.X_OK):
            raise TargetError(f"{EMU} is missing: the emulated targets need tools/emu")
        if not self.image.exists():
            raise TargetError(f"{self.image} is missing: build the rv32-virt images "
                              "(cmake -B build-rv32-virt ...; see docs/emulator.md)")
        for _ in range(3):
            port = free_port()
            self.logf = open(self.log, "a")
            self.logf.write(f"--- start {' '.join(self._command(port))}\n")
            self.logf.flush()
            start = self.log.stat().st_size
            self.proc = subprocess.Popen(self._command(port), stdin=subprocess.DEVNULL,
                                         stdout=self.logf, stderr=subprocess.STDOUT,
                                         start_new_session=True)
            if self._ready(start):
                self.line = AnswerLine(port)
                return self.bus
            self._reap(signal.SIGKILL)
            if "port" not in self.log.read_text().splitlines()[-1]:
                break  # not a port another program took meanwhile: no retry
        raise TargetError("rv32-can: tools/emu did not get ready; its output:\n"
                          + self.log.read_text()[-2000:])

    def _ready(self, start):
        """Waits for tools/emu's "emu: ready" line (after offset start of the log)."""
        end = time.monotonic() + self.READY_TIMEOUT
        while time.monotonic() < end:
            with open(self.log, "rb") as f:
                f.seek(start)
                if any(l.startswith(b"emu: ready: ") for l in f.read().splitlines()):
                    return True
            if self.proc.poll() is not None:
                return False
            time.sleep(0.02)
        return False

    def _reap(self, sig=None):
        rc = super()._reap(sig)
        if self.line is not None:
            self.line.close()
            self.line = None
        return rc

    def close(self):
        self._reap(signal.SIGTERM)
        # The bus stays: Master.close() releases it after its reader has
        # stopped (a socketcan bus closed under the reader is an error).
        self.flash.unlink(missing_ok=True)

    def inject(self, line, timeout=1.0):
        """Writes the line on the serial line and waits for the image's answer;
        anything but "ok" fails the test."""
        if self.line is None or self.line.lost or self.proc is None or self.proc.poll() is not None:
            raise TargetError(f"inject {line!r}: the rv32-can image is not running")
        while not self.line.answers.empty():
            self.line.answers.get_nowait()
        self.line.write_line(line)
        try:
            answer = self.line.answers.get(timeout=timeout)
        except queue.Empty:
            raise TargetError(f"rv32-can: no answer to {line!r} on the serial line within "
                              f"{timeout} s") from None
        if answer != "ok":
            raise TargetError(f"rv32-can: {line!r} answered {answer!r}")


def make_target(name, product, tmp_path):
    """The target called name (TARGETS) for one product."""
    if name == "linux":
        return LinuxTarget(product, tmp_path)
    if name == "rv32-can":
        return CanEmuTarget(product, tmp_path)
    return EmuTarget(product, tmp_path, name)


def list_products():
    """Every product ID canopen-sensor knows (the linux build)."""
    out = subprocess.run([BINARY, "--list-products"], check=True, capture_output=True,
                         text=True, timeout=30).stdout
    return [line.split()[0] for line in out.splitlines() if line.strip()]


def period_fault(times, period_ms, window_s):
    """None if frames that arrived at these times (seconds), collected for
    window_s, came every period_ms; else what is wrong. A moment in which
    the machine starves an emulator or a process drops a beat (CiA 301's
    producer does not catch up) or delivers two frames together: it moves
    the mean, so the period is the median gap, to a fifth. The count: at
    least three quarters of what the window holds (a stall of a quarter of
    it is forgiven; a producer silent for longer fails), at most two more
    (one at each end, one that a late read brought in). Frames the host
    reads late arrive bunched, so a device's burst cannot be told from
    that here: the unit tests find bursts, on the stack's own clock."""
    want = window_s * 1000 / period_ms
    if len(times) < 2 or not want * 3 / 4 <= len(times) <= want + 2:
        return f"{len(times)} in {window_s} s at {period_ms} ms, want {want:.0f}"
    gaps = sorted(b - a for a, b in zip(times, times[1:]))
    median = gaps[len(gaps) // 2] * 1000
    if abs(median - period_ms) > period_ms / 5:
        return f"median period {median:.1f} ms, want {period_ms} ms " \
               f"(gaps {', '.join(f'{g * 1000:.0f}' for g in gaps)} ms)"
    return None


class Frames(can.Listener):
    """Every frame the master sees, with its arrival time, for the checks the
    canopen API hides (boot-up, heartbeat, EMCY, PDO counts)."""

    def __init__(self):
        super().__init__()
        self.q = queue.Queue()

    def on_message_received(self, msg):
        self.q.put((time.monotonic(), msg))

    def clear(self):
        self.drain()

    def drain(self):
        """(time, frame) of every frame received and not yet taken."""
        got = []
        while not self.q.empty():
            got.append(self.q.get_nowait())
        return got

    def stream(self, seconds):
        """(time, frame) as they arrive, for at most this many seconds."""
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            try:
                yield self.q.get(timeout=left)
            except queue.Empty:
                return

    def wait_for(self, can_id, timeout=2.0, pred=None):
        """The next frame with this CAN-ID (and pred), or None."""
        for _, m in self.stream(timeout):
            if m.arbitration_id == can_id and not m.is_remote_frame and (pred is None or pred(m)):
                return m
        return None

    def collect(self, can_id, seconds):
        """(time, frame) of every frame with this CAN-ID during seconds."""
        return [(t, m) for t, m in self.stream(seconds)
                if m.arbitration_id == can_id and not m.is_remote_frame]

    def count(self, can_id, want, timeout=2.0, quiet=0.3):
        """(time, frame) of the frames with this CAN-ID until want of them
        came (at most timeout seconds), then for quiet seconds more to see
        any extra one. A target that answers late (an emulator the machine
        starves for a moment) is waited for; one that answers too often or
        not at all is still counted wrong."""
        got = self.collect_until(can_id, timeout, want) if want else []
        return got + self.collect(can_id, quiet)

    def collect_until(self, can_id, seconds, n):
        """At most n frames with this CAN-ID within seconds."""
        got = []
        for t, m in self.stream(seconds):
            if m.arbitration_id == can_id and not m.is_remote_frame:
                got.append((t, m))
                if len(got) == n:
                    break
        return got


class Master:
    """The CANopen master of a test (canopen's Network, SDO client and LSS
    master) on a target: power_on() connects it to the bus the target gives,
    power_off()/power_cut() end the device and let go of that bus."""

    BOOT_TIMEOUT = 5.0

    def __init__(self, target):
        self.target = target
        self.frames = Frames()
        self.network = None
        self.boot_frames = []

    def power_on(self, node_ids):
        """Power on and wait for the boot-up of every node in node_ids; the
        frames up to the last boot-up are kept in boot_frames."""
        import canopen
        self.frames.clear()
        bus = self.target.start()
        if self.network is None:
            self.network = canopen.Network(bus)
            # The reader's poll period: power_off() waits for it to end
            # before it closes the bus (canopen's default is 1 s).
            self.network.NOTIFIER_CYCLE = 0.05
            self.network.listeners.append(self.frames)
            if self.target.RESPONSE_TIMEOUT is not None:
                self.network.lss.RESPONSE_TIMEOUT = self.target.RESPONSE_TIMEOUT
        else:
            self.network.bus = bus
        if hasattr(self.target, "send_lock"):
            self.target.send_lock = self.network.send_lock
        self.network.connect()
        want = {0x700 + n for n in node_ids}
        self.boot_frames = []
        for _, m in self.frames.stream(self.BOOT_TIMEOUT):
            self.boot_frames.append(m)
            if m.arbitration_id in want and bytes(m.data) == b"\0":
                want.discard(m.arbitration_id)
                if not want:
                    break
        missing = ", ".join(f"{c - 0x700:#04x}" for c in sorted(want))
        seen = "; ".join(f"{m.arbitration_id:03X} {bytes(m.data).hex()}"
                         for m in self.boot_frames[:8]) or "nothing"
        assert not want, f"{self.target.name}: no boot-up from node {missing} within " \
                         f"{self.BOOT_TIMEOUT} s of power on (saw {seen})"
        return self

    def _let_go(self):
        if self.network is not None and self.network.notifier is not None:
            self.network.notifier.stop(1.0)
            self.network.notifier = None
        self.target.release()
        if self.network is not None:
            self.network.bus = None

    def power_off(self):
        """Clean power off (the device saves nothing it was not told to)."""
        rc = self.target.stop()
        self._let_go()
        return rc

    def power_cut(self):
        """SIGKILL, now."""
        rc = self.target.kill()
        self._let_go()
        return rc

    def power_cut_after(self, can_id, data, delay):
        """Sends one frame, cuts the power delay seconds later, and returns what
        the device sent meanwhile. The reader is stopped first, so that the cut
        comes delay after the send, not after the reader's turn at the GIL
        (up to 5 ms: every cut of a save came after its answer)."""
        self.network.notifier.stop(1.0)
        self.network.notifier = None
        bus = self.target.bus
        bus.send(can.Message(arbitration_id=can_id, data=bytes(data), is_extended_id=False))
        if delay > 0:
            time.sleep(delay)
        self.target.kill()
        sent = []
        # Until 50 ms of silence; a bus that never falls silent (another
        # node's frames) ends it after a second.
        end = time.monotonic() + 1.0
        while time.monotonic() < end and (m := bus.recv(0.05)) is not None:
            sent.append(m)
        self._let_go()
        return sent

    def node(self, node_id):
        """canopen's RemoteNode for node_id (no dictionary: raw SDO)."""
        import canopen
        if node_id not in self.network:
            node = canopen.RemoteNode(node_id, canopen.ObjectDictionary())
            if self.target.RESPONSE_TIMEOUT is not None:
                node.sdo.RESPONSE_TIMEOUT = self.target.RESPONSE_TIMEOUT
            self.network.add_node(node)
        return self.network[node_id]

    def send(self, can_id, data=b"", remote=False):
        self.network.send_message(can_id, bytes(data), remote=remote)

    def close(self):
        self.target.close()
        self._let_go()
