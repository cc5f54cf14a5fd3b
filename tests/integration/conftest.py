"""Fixtures for the end-to-end tests: the real canopen-sensor program on a
real SocketCAN vcan interface, and an independent CANopen master (the
`canopen` and `python-can` packages). Run through tools/vcan-run, which
brings vcan0 and vcan1 up (inside User-Mode Linux where the kernel has no CAN).
"""
import os
import pathlib
import queue
import signal
import subprocess
import time

import can
import canopen
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BINARY = os.environ.get("CANOPEN_SENSOR", str(ROOT / "build" / "bin" / "canopen-sensor"))
IFACE = "vcan0"


def pytest_addoption(parser):
    """test_targets.py runs on one target, for a list of products."""
    group = parser.getgroup("targets", "the one suite on three targets (test_targets.py)")
    group.addoption("--target", default="linux", choices=("linux", "rv32-virt", "microbit"),
                    help="where the products run: linux (canopen-sensor on vcan0, through "
                         "tools/vcan-run) or an emulated board (tools/emu, qemu)")
    group.addoption("--products", default=os.environ.get("CO_TEST_PRODUCTS", "ci"),
                    help="ci (one of each family, facts.CI_PRODUCTS), all, or IDs "
                         "separated by commas; default $CO_TEST_PRODUCTS, else ci "
                         "(tools/check --all-products sets it to all)")
    group.addoption("--shard", default="1/1", metavar="K/N",
                    help="run the K-th of N shares of the products (ctest runs the "
                         "shares of a board in parallel)")


def pytest_sessionstart(session):
    if not os.access(BINARY, os.X_OK):
        pytest.exit(f"{BINARY} is missing: build first (see README)", returncode=3)


class Sensor:
    """One canopen-sensor process. stop() + start() with the same --nvm file
    is a power cycle; kill() is a power cut."""

    def __init__(self, product, tmp_path, nvm=True, iface=IFACE):
        self.product = product
        self.iface = iface
        self.nvm = str(tmp_path / "eeprom.bin") if nvm else None
        self.log = tmp_path / "sensor.log"
        self.proc = None

    def start(self):
        cmd = [BINARY, "--product", self.product, "--iface", self.iface, "--log", str(self.log)]
        if self.nvm:
            cmd += ["--nvm", self.nvm]
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True)
        return self

    def send(self, line):
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()

    def stop(self, sig=signal.SIGTERM):
        if self.proc is None:
            return None
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            rc = self.proc.wait(timeout=5)
        finally:
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


def eds_od(product, tmp_path, node_id):
    """The master's dictionary: the product's EDS, as canopen-sensor prints it."""
    path = tmp_path / f"{product}.eds"
    path.write_text(subprocess.run([BINARY, "--product", product, "--eds"], check=True,
                                   capture_output=True, text=True).stdout)
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
