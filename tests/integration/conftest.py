"""Fixtures for the end-to-end tests: the real canopen-sensor program on a
real SocketCAN vcan interface, and an independent CANopen master (the
`canopen` and `python-can` packages). Run through tools/vcan-run, which
brings vcan0 and vcan1 up (inside User-Mode Linux where the kernel has no CAN).
"""
import os
import pathlib
import queue
import select
import signal
import subprocess
import sys
import threading
import time
import traceback

import can
import canopen
import pytest
from canopen_sensor_sim import ControlClient, SimError

ROOT = pathlib.Path(__file__).resolve().parents[2]
BINARY = os.environ.get("CANOPEN_SENSOR", str(ROOT / "build" / "bin" / "canopen-sensor"))
IFACE = "vcan0"


def pytest_addoption(parser):
    """test_targets.py runs on one target, for a list of products."""
    group = parser.getgroup("targets", "the one suite on four targets (test_targets.py)")
    group.addoption("--target", default="linux",
                    choices=("linux", "rv32-virt", "microbit", "rv32-can"),
                    help="where the products run: linux (canopen-sensor on vcan0, through "
                         "tools/vcan-run), an emulated board on its SLCAN serial line "
                         "(tools/emu, qemu), or rv32-can (the rv32-virt image's SJA1000 "
                         "on vcan0: tools/emu --can, through tools/vcan-run)")
    group.addoption("--products", default=os.environ.get("CO_TEST_PRODUCTS", "ci"),
                    help="ci (one of each family, facts.CI_PRODUCTS), all, or IDs "
                         "separated by commas; default $CO_TEST_PRODUCTS, else ci "
                         "(tools/check --all-products sets it to all)")
    group.addoption("--shard", default="1/1", metavar="K/N",
                    help="run the K-th of N shares of the products (ctest runs the "
                         "shares of a board in parallel)")


# ---- Bounds ----------------------------------------------------------------
# Every test ends within its bound (seconds): a test still running then (a
# frame that never comes, an emulator the machine stopped, a read without a
# timeout) fails with the stack of every thread, its teardown ends what it
# started, and the tests after it are not run: ctest's output then says
# what stopped and where, long before ctest's own TIMEOUT would kill the
# shard without a word. CO_TEST_TIMEOUT replaces the default for a run; a
# test that needs longer says so with @pytest.mark.bound(SECONDS). The
# longest measured: 7 s (rv32-virt's power cuts at a load of 13 on two
# cores); the bus flood of test_hostile sends for 10 s by design.
TEST_BOUND_S = 180.0
# After the bound, setup and teardown have this long to finish; a test that
# has not ended by then (its main thread stuck where no signal reaches it)
# gets every thread's stack written out, its processes killed and pytest
# ended at once (exit status 3).
TEARDOWN_GRACE_S = 60.0
# At the session's end the threads a test left running (not daemons, so the
# interpreter would wait for them without end) get this long to end.
THREAD_GRACE_S = 10.0
WATCHDOG = "test-bound-watchdog"  # the last resort's thread


def pytest_configure(config):
    config.addinivalue_line("markers", "bound(seconds): this test's bound instead of the "
                                       "default TEST_BOUND_S (conftest.py)")


def bound_of(item):
    """The seconds item may run: its bound marker, else CO_TEST_TIMEOUT, else TEST_BOUND_S."""
    mark = item.get_closest_marker("bound")
    if mark is not None:
        return float(mark.args[0])
    text = os.environ.get("CO_TEST_TIMEOUT", "")
    if not text:
        return TEST_BOUND_S
    try:
        bound = float(text)
    except ValueError:
        bound = 0.0
    if not 0 < bound < 86400:
        pytest.exit(f"CO_TEST_TIMEOUT={text!r}: not a number of seconds (0 to 86400)",
                    returncode=4)
    return bound


def thread_stacks():
    """Where every thread of this process is, innermost call last: pytest's
    and pluggy's frames and the bound's own left out."""
    frames = sys._current_frames()
    parts = []
    for t in threading.enumerate():
        frame = frames.get(t.ident)
        if frame is None or t.name == WATCHDOG:
            continue
        stack = [f for f in traceback.extract_stack(frame)
                 if not any(k in f.filename for k in ("/_pytest/", "/pluggy/"))
                 and f.name not in ("expired", "thread_stacks", "last_resort", "pytest_unconfigure")]
        kind = " (daemon)" if t.daemon else ""
        parts.append(f"--- thread {t.name}{kind}:\n" + "".join(traceback.format_list(stack)))
    return "\n".join(parts)


def out_of_capture(config, text):
    """Write text on the real standard error, past pytest's capture."""
    capman = config.pluginmanager.getplugin("capturemanager")
    if capman is not None:
        capman.suspend_global_capture(in_=True)
    sys.stderr.write(text)
    sys.stderr.flush()


def kill_children():
    """SIGKILL to every child of this process, to the whole group of one
    that leads its own (tools/emu and its QEMU)."""
    me = os.getpid()
    for stat in pathlib.Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue  # ended meanwhile
        pid, ppid, pgid = int(stat.parent.name), int(fields[1]), int(fields[2])
        if ppid != me:
            continue
        try:
            if pgid == pid:
                os.killpg(pid, signal.SIGKILL)
            else:
                os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    bound = bound_of(item)

    def expired(signum, frame):
        hit.append(True)
        item.session.shouldstop = (f"{item.nodeid} ran into its bound of {bound:g} s: "
                                   "the tests after it were not run")
        pytest.fail(f"{item.nodeid}: still running after its bound of {bound:g} s "
                    "(see conftest.TEST_BOUND_S); where each thread waited:\n"
                    + thread_stacks())

    def last_resort():
        out_of_capture(item.config,
                       f"\n{item.nodeid}: not ended {TEARDOWN_GRACE_S:g} s after its bound of "
                       f"{bound:g} s; where each thread waits:\n{thread_stacks()}\n"
                       "its processes killed, pytest ends here (exit status 3)\n")
        kill_children()
        sys.stdout.flush()
        os._exit(3)

    hit = []
    old = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, bound)
    watchdog = threading.Timer(bound + TEARDOWN_GRACE_S, last_resort)
    watchdog.name = WATCHDOG
    watchdog.daemon = True
    watchdog.start()
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
        watchdog.cancel()
        if hit:
            kill_children()  # what its teardown left: the session stops here


def pytest_unconfigure(config):
    """A thread that is no daemon and still runs keeps the interpreter from
    exiting, after pytest has said everything, and without a word: named
    and ended here instead."""
    left = [t for t in threading.enumerate()
            if t is not threading.main_thread() and not t.daemon and t.is_alive()]
    for t in left:
        t.join(THREAD_GRACE_S)
    left = [t for t in left if t.is_alive()]
    if left:
        out_of_capture(config, f"\npytest: {len(left)} thread(s) a test started still run "
                               f"{THREAD_GRACE_S:g} s after the last test ("
                               + ", ".join(t.name for t in left) + "); where each waits:\n"
                               + thread_stacks() + "\nexit status 3\n")
        kill_children()
        sys.stdout.flush()
        os._exit(3)


def pytest_sessionstart(session):
    if not os.access(BINARY, os.X_OK):
        pytest.exit(f"{BINARY} is missing: build first (see README)", returncode=3)


class Sensor:
    """One canopen-sensor process. stop() + start() with the same --nvm file
    is a power cycle; kill() is a power cut.

    Its inputs are driven through its control socket (--control unix:PATH in
    the test's directory, the package's ControlClient): send() for lines that
    must be taken, command() for the raw answer of a line a test expects to be
    refused, get() for the node's true inputs. Standard input is /dev/null
    (--on-eof run) unless stdin=True: then write_stdin() types on it, for the
    tests of standard input itself. args: more options for its command line
    (--program-download)."""

    def __init__(self, product, tmp_path, nvm=True, iface=IFACE, stdin=False, args=()):
        self.product = product
        self.args = list(args)
        self.iface = iface
        self.nvm = str(tmp_path / "eeprom.bin") if nvm else None
        self.log = tmp_path / "sensor.log"
        self.control_path = tmp_path / "control.sock"
        # sun_path holds 108 bytes with its NUL (Linux): a longer path cannot
        # be bound, and the program would refuse it at start.
        assert len(os.fsencode(self.control_path)) < 108, \
            f"{self.control_path}: too long for a unix socket (give pytest a shorter --basetemp)"
        self.stdin = stdin
        self.proc = None
        self.control = None
        self.stderr = ""

    def start(self):
        """Power on; returns once the control socket answers."""
        cmd = [BINARY, "--product", self.product, "--iface", self.iface, "--log", str(self.log),
               "--control", f"unix:{self.control_path}", "--on-eof", "run"]
        if self.nvm:
            cmd += ["--nvm", self.nvm]
        cmd += self.args
        if self.control_path.exists():
            self.control_path.unlink()  # a power cut's stale socket
        # Decision: standard input is /dev/null and --on-eof run, so the
        # program's input is the control socket alone. The cost: the pipe no
        # longer ties it to pytest, so a pytest killed outright leaves it
        # running until tools/vcan-run tears User-Mode Linux down (on a host
        # vcan, VCAN_RUN_MODE=host, until killed by hand); stop() at teardown
        # ends it in every other case.
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE if self.stdin else subprocess.DEVNULL,
                                     stderr=subprocess.PIPE, text=True)
        try:
            self.control = ControlClient.connect(self.control_path, proc=self.proc)
        except SimError as e:
            self.stop(signal.SIGKILL)
            pytest.fail(f"{self.product}: {e}")
        return self

    def command(self, line):
        """One control line; its answer as it came: "ok ..." or "error: ..."."""
        if self.control is None:
            pytest.fail(f"{line!r}: canopen-sensor is not running")
        return self.control.ask(line)

    def send(self, line):
        """One control line that must be taken: an "error: ..." answer fails
        the test; a `set` is then read back (check_taken). Returns the text
        after "ok"."""
        answer = self.command(line)
        if answer != "ok" and not answer.startswith("ok "):
            pytest.fail(f"{self.product}: {line!r} answered {answer!r}")
        self.check_taken(line)
        return answer[3:]

    def check_taken(self, line):
        """After a `set` line was answered "ok": every value it gave must be
        the node's true input now, as `get` says (to the thousandth it
        prints). Other lines: nothing to read back (`get` shows no faults)."""
        words = line.split()
        if not words or words[0] != "set":
            return
        now = self.get()
        for token in words[1:]:
            name, _, value = token.partition("=")
            assert now.get(name) == pytest.approx(float(value), abs=0.0005), \
                f"{line!r} answered ok, but get says {now}"

    def get(self):
        """The node's true inputs and NMT state from the control socket:
        {"x": 12.5, ..., "nmt": "operational"}."""
        if self.control is None:
            pytest.fail("get: canopen-sensor is not running")
        return self.control.get()

    def write_stdin(self, line):
        """One line on standard input (a Sensor made with stdin=True)."""
        assert self.stdin, "write_stdin needs Sensor(..., stdin=True)"
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()

    def stop(self, sig=signal.SIGTERM):
        if self.control is not None:
            self.control.close()
            self.control = None
        if self.proc is None:
            return None
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            try:
                rc = self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                # Killed, so that reading its stderr below cannot wait for it.
                self.proc.kill()
                self.proc.wait(timeout=5)
                pytest.fail(f"{self.product}: canopen-sensor did not end within 5 s of "
                            f"signal {sig}: killed")
        finally:
            if self.proc.stdin:
                self.proc.stdin.close()
            self.stderr = self.proc.stderr.read()
            self.proc.stderr.close()
            self.proc = None
        return rc

    def kill(self):
        return self.stop(signal.SIGKILL)

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def log_text(self):
        return self.log.read_text() if self.log.exists() else ""


class Bus(can.Listener):
    """Raw frames seen on the bus, for the checks the master API hides."""

    def __init__(self, network):
        super().__init__()
        self.q = queue.Queue()
        network.notifier.add_listener(self)

    def on_message_received(self, msg):
        self.q.put(msg)

    def clear(self):
        while not self.q.empty():
            self.q.get_nowait()

    def frames(self, seconds):
        """Frames as they arrive, for at most this many seconds."""
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            try:
                yield self.q.get(timeout=left)
            except queue.Empty:
                return

    def wait_for(self, can_id, timeout=2.0, pred=None):
        for m in self.frames(timeout):
            if m.arbitration_id == can_id and (pred is None or pred(m)):
                return m
        return None

    def wait_for_any(self, pred, timeout=2.0):
        for m in self.frames(timeout):
            if pred(m):
                return m
        return None

    def collect(self, can_id, seconds):
        return [m for m in self.frames(seconds) if m.arbitration_id == can_id]


def line_within(stream, seconds, what):
    """The next line of a child's pipe, read within seconds; the test fails
    naming what it waited for when none comes (or the pipe ends)."""
    end = time.monotonic() + seconds
    got = b""
    while not got.endswith(b"\n"):
        left = end - time.monotonic()
        if left <= 0 or not select.select([stream], [], [], left)[0]:
            pytest.fail(f"no line with {what} within {seconds:.3g} s (got {got!r})")
        chunk = os.read(stream.fileno(), 1)  # a byte at a time: nothing past the line
        if not chunk:
            pytest.fail(f"the pipe ended before a line with {what} (got {got!r})")
        got += chunk
    return got.decode()


def eds_od(product, tmp_path, node_id):
    """The master's dictionary: the product's EDS, as canopen-sensor prints it."""
    path = tmp_path / f"{product}.eds"
    path.write_text(subprocess.run([BINARY, "--product", product, "--eds"], check=True,
                                   capture_output=True, text=True, timeout=30).stdout)
    return canopen.import_od(str(path), node_id)


def boot(sensor, network, bus, node_id):
    """Start the sensor, wait for its boot-up, and give the master its node."""
    bus.clear()
    sensor.start()
    m = bus.wait_for(0x700 + node_id, timeout=3, pred=lambda m: bytes(m.data) == b"\0")
    assert m is not None, f"no boot-up from node {node_id:#x}"
    node = canopen.RemoteNode(node_id, eds_od(sensor.product, sensor.log.parent, node_id))
    network.add_node(node)
    return node


@pytest.fixture
def network():
    if not pathlib.Path("/sys/class/net", IFACE).exists():
        pytest.fail(f"{IFACE} is not up: run these tests through tools/vcan-run")
    net = canopen.Network()
    net.connect(interface="socketcan", channel=IFACE)
    yield net
    net.disconnect()


@pytest.fixture
def bus(network):
    return Bus(network)


@pytest.fixture
def raw():
    """A second, plain python-can bus for frames canopen would not send."""
    b = can.Bus(interface="socketcan", channel=IFACE)
    yield b
    b.shutdown()


@pytest.fixture
def sensor_factory(tmp_path):
    made = []

    def make(product, **kw):
        s = Sensor(product, tmp_path, **kw)
        made.append(s)
        return s

    yield make
    for s in made:
        s.stop()
