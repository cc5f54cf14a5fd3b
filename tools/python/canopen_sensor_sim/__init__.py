"""Simulated CANopen sensors for machine tests.

A ``SimBus`` runs one ``canopen-sensor`` process with any number of nodes
(``--node PRODUCT[@NODEID][/IFACE]``) on a SocketCAN interface (or on
python-can's udp_multicast bus: ``default_interface()``), each with its
own stored parameters in a directory, and talks to it through its control
socket (``--control unix:PATH``): the same line language as its standard
input, one command a line, answered ``ok ...`` or ``error: <cause>``.

    with SimBus(["dst-x730-xy30@0x20", "jd2xxx@0x21"], interface="vcan0") as bus:
        bus.set(0x20, x=12.5)
        bus.ramp(0x21, "x", 30, seconds=5)
        assert bus.get(0x20)["nmt"] == "pre-operational"

``ControlClient`` is the line client alone, for a process started some other
way (with ``--control``): ``ControlClient.connect(path, proc=p)``, then
``ask(line)`` (the raw answer), ``command(line)`` (raises on ``error:``) and
``get()``.

The program is found in ``$CANOPEN_SENSOR``, else on ``PATH``, else in the
repository's ``build/bin`` (when this package runs from a checkout).
"""
import os
import pathlib
import shutil
import socket
import subprocess
import tempfile
import time

__all__ = ["ControlClient", "SimBus", "SimError", "UDP_LOOPBACK", "VERBS", "default_interface",
           "find_program", "python_can_args"]

# python-can's udp_multicast bus on this machine's loopback: its IPv4
# default group and port, joined on lo (the program's interface form).
UDP_LOOPBACK = "udp_multicast:239.74.163.2:43113%lo"

# The line language's verbs, in the program's order (its table,
# boards/linux/cmd.c): each is a SimBus method of the same name.
# tests/integration/test_cli.py checks this list against the program's.
VERBS = ("set", "ramp", "sine", "noise", "replay", "fault", "can", "unplug", "heartbeat", "get",
         "quit")


class SimError(RuntimeError):
    """The program refused a command (its ``error: <cause>``) or stopped."""


def find_program():
    """Path of the canopen-sensor program (see the module comment)."""
    env = os.environ.get("CANOPEN_SENSOR")
    if env:
        return env
    found = shutil.which("canopen-sensor")
    if found:
        return found
    here = pathlib.Path(__file__).resolve()
    for parent in here.parents:
        candidate = parent / "build" / "bin" / "canopen-sensor"
        if candidate.exists():
            return str(candidate)
    raise SimError("canopen-sensor not found: set CANOPEN_SENSOR or build the repository (tools/setup)")


def default_interface():
    """vcan0 where it exists, else python-can's udp_multicast bus on the
    loopback (UDP_LOOPBACK): no CAN in the kernel needed. A master that
    joins that bus with python-can sends on the host's default interface
    unless it runs in a network namespace with the loopback alone
    (tools/netns-run); see python_can_args."""
    # if_nameindex: this network namespace's interfaces (sysfs may show another's)
    names = [name for _, name in socket.if_nameindex()]
    return "vcan0" if "vcan0" in names else UDP_LOOPBACK


def python_can_args(interface):
    """The keyword arguments of ``can.Bus`` (and ``canopen.Network.connect``)
    for a master on the program's interface: SocketCAN for a CAN
    interface name, ``udp_multicast`` with the group and port for the
    program's ``udp_multicast:GROUP[:PORT][%IFNAME]`` form (python-can has
    no interface option: it joins and sends where the routing table says,
    which is why the tests run in tools/netns-run)."""
    prefix = "udp_multicast:"
    if not interface.startswith(prefix):
        return {"interface": "socketcan", "channel": interface}
    spec = interface[len(prefix):].split("%", 1)[0]
    group, _, port = spec.partition(":")
    return {"interface": "udp_multicast", "channel": group, "port": int(port or 43113)}


def _selector(node):
    """The node selector of a control line: a node-ID (int), "@all", or None."""
    if node is None:
        return ""
    if isinstance(node, int):
        return f"0x{node:02X} "
    return f"{node} "


def _value(v):
    """An input value as the line language writes it (units of the input):
    thousandths for a float of ordinary size; beyond 1e12 (no input's limit
    comes near) its shortest form (1e+300), so that the program answers
    "not a number within ..." rather than "line too long" for 300 digits."""
    if isinstance(v, float):
        return f"{v:.3f}" if abs(v) < 1e12 else repr(v)
    return str(v)


def parse_get(answer):
    """The text after ``ok`` of a ``get`` answer as a dict: numbers as
    floats, the rest (``nmt``) as text."""
    out = {}
    for token in answer.split():
        key, _, value = token.partition("=")
        try:
            out[key] = float(value)
        except ValueError:
            out[key] = value
    return out


class ControlClient:
    """One connection to a control socket (``--control unix:PATH`` or
    ``tcp:PORT``): one line out, one answer line back."""

    def __init__(self, sock):
        self._sock = sock
        self._rx = b""

    @classmethod
    def connect(cls, address, proc=None, timeout=10.0):
        """Connect to address (a unix socket path, or ``(host, port)``),
        retrying until the program listens. proc (a ``subprocess.Popen``):
        stop early, with its stderr, if it ends meanwhile. Raises SimError
        when nothing answers within timeout seconds."""
        family = socket.AF_INET if isinstance(address, tuple) else socket.AF_UNIX
        target = address if family == socket.AF_INET else str(address)
        deadline = time.monotonic() + timeout
        while True:
            if proc is not None and proc.poll() is not None:
                err = proc.stderr.read() if proc.stderr else ""
                if isinstance(err, bytes):
                    err = err.decode(errors="replace")
                raise SimError(f"canopen-sensor exited with {proc.returncode}: {err.strip()}")
            s = socket.socket(family, socket.SOCK_STREAM)
            try:
                s.connect(target)
                return cls(s)
            except OSError:
                s.close()
                if time.monotonic() > deadline:
                    raise SimError(f"no control socket at {address} after {timeout} s") from None
                time.sleep(0.05)

    def close(self):
        if self._sock is not None:
            self._sock.close()
            self._sock = None

    def ask(self, line, timeout=5.0):
        """Send one line; return its answer line as it came (``ok ...`` or
        ``error: ...``), without the newline."""
        if self._sock is None:
            raise SimError("the control connection is closed")
        if "\n" in line:
            raise SimError("one command a line")
        self._sock.settimeout(timeout)
        try:
            self._sock.sendall((line + "\n").encode())
            while b"\n" not in self._rx:
                chunk = self._sock.recv(4096)
                if not chunk:
                    raise SimError("control socket closed while waiting for the answer to "
                                   f"{line!r}")
                self._rx += chunk
        except TimeoutError:
            raise SimError(f"no answer to {line!r} within {timeout} s") from None
        answer, self._rx = self._rx.split(b"\n", 1)
        return answer.decode(errors="replace").strip()

    def command(self, line, timeout=5.0):
        """Send one line; return the text after ``ok``; raise SimError with
        the cause on ``error: ...``."""
        text = self.ask(line, timeout)
        if text == "ok" or text.startswith("ok "):
            return text[3:]
        if text.startswith("error:"):
            raise SimError(text[6:].strip())
        raise SimError(f"unexpected answer {text!r} to {line!r}")

    def get(self, selector=""):
        """The node's true inputs and NMT state (see ``parse_get``); selector:
        the line's node selector, empty for the first instance."""
        return parse_get(self.command(f"{selector} get".strip()))


class SimBus:
    """One canopen-sensor process with its nodes; a context manager.

    nodes: ``"PRODUCT[@NODEID][/IFACE]"`` strings; interface: the default
    CAN interface; nvm_dir: where each node keeps its stored set (a fresh
    temporary directory when None: every start is a factory-new device);
    seed: the motion generator's seed (``--seed``); extra: more arguments.
    """

    def __init__(self, nodes, interface="vcan0", nvm_dir=None, seed=None, program=None,
                 extra=(), start_timeout=10.0):
        if isinstance(nodes, (str, bytes)):
            raise SimError(f"nodes: a list of 'PRODUCT[@NODEID][/IFACE]' strings, not {nodes!r} "
                           "alone (write [" + repr(nodes) + "])")
        self.nodes = list(nodes)
        if not self.nodes:
            raise SimError("nodes: an empty list: give at least one 'PRODUCT[@NODEID][/IFACE]'")
        self.interface = interface
        self.seed = seed
        self.program = program or find_program()
        self.extra = list(extra)
        self.start_timeout = start_timeout
        self._tmp = tempfile.TemporaryDirectory(prefix="canopen-sensor-sim-")
        self.nvm_dir = pathlib.Path(nvm_dir) if nvm_dir else pathlib.Path(self._tmp.name) / "nvm"
        self.nvm_dir.mkdir(parents=True, exist_ok=True)
        self.control_path = pathlib.Path(self._tmp.name) / "control.sock"
        self.log_path = pathlib.Path(self._tmp.name) / "sensor.log"
        self.proc = None
        self._client = None

    # ---- the process ---------------------------------------------------
    def command_line(self):
        """The program's arguments for this bus."""
        args = [self.program, "--iface", self.interface]
        for n in self.nodes:
            args += ["--node", n]
        # Standard input is not used (DEVNULL): run on at its end.
        args += ["--on-eof", "run", "--nvm-dir", str(self.nvm_dir), "--control", f"unix:{self.control_path}",
                 "--log", str(self.log_path)]
        if self.seed is not None:
            args += ["--seed", str(self.seed)]
        return args + self.extra

    def start(self):
        """Power on every node; returns once the control socket answers."""
        if self.proc is not None and self.proc.poll() is None:
            raise SimError("the bus is running already: stop() it first")
        if self.control_path.exists():
            self.control_path.unlink()
        self.proc = subprocess.Popen(self.command_line(), stdin=subprocess.DEVNULL,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        try:
            self._client = ControlClient.connect(self.control_path, proc=self.proc,
                                                 timeout=self.start_timeout)
        except SimError:
            self.stop()
            raise
        return self

    def stop(self, timeout=5.0):
        """Power off cleanly (SIGTERM); returns the exit status."""
        if self._client is not None:
            self._client.close()
            self._client = None
        if self.proc is None:
            return None
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        rc = self.proc.returncode
        self.proc.stderr.close()
        self.proc = None
        return rc

    def kill(self):
        """Power cut (SIGKILL): what the stored sets hold is what survives."""
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
        return self.stop()

    def close(self):
        self.stop()
        self._tmp.cleanup()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.close()

    def log(self):
        """The program's log so far (text)."""
        return self.log_path.read_text(errors="replace") if self.log_path.exists() else ""

    # ---- the control line ----------------------------------------------
    def command(self, line, node=None, timeout=5.0):
        """Send one control line (with node's selector); return the text after
        ``ok``; raise SimError with the cause on ``error: ...``."""
        if self._client is None:
            raise SimError("the bus is not started")
        return self._client.command(_selector(node) + line, timeout)

    def set(self, node, **values):
        """True input values (the input's unit): ``bus.set(0x20, x=12.5)``."""
        self.command("set " + " ".join(f"{k}={_value(v)}" for k, v in values.items()), node)

    def fault(self, node, name, on=True):
        self.command(f"fault {name} {'on' if on else 'off'}", node)

    def ramp(self, node, name, to, seconds):
        self.command(f"ramp {name}={_value(to)} in {seconds}s", node)

    def sine(self, node, name, amp, period):
        self.command(f"sine {name} amp={_value(amp)} period={period}s", node)

    def noise(self, node, name, sd):
        self.command(f"noise {name} sd={_value(sd)}", node)

    def replay(self, node, path):
        self.command(f"replay {path}", node)

    def can(self, node, state, seconds=None):
        """The node's simulated CAN controller: ``bus-off`` (the bus unusable
        ``seconds``, then back after 128 x 11 bits), ``passive``, ``warning``
        or ``active``; node "@all" for every node."""
        hold = "" if seconds is None else f" {seconds}"
        self.command(f"can {state}{hold}", node)

    def unplug(self, node, seconds=None, off=False):
        """The node's cable pulled: no frame in or out, error counters as
        they were, for ``seconds`` or until ``unplug(node, off=True)``."""
        self.command("unplug off" if off else f"unplug {seconds}" if seconds else "unplug", node)

    def heartbeat(self, node, on):
        """The node's heartbeats stopped (on False) or sent again."""
        self.command(f"heartbeat {'start' if on else 'stop'}", node)

    def quit(self):
        """Stop the program by its own command (stop() signals it instead);
        returns the exit status."""
        if self._client is not None:
            self._client.command("quit")
        return self.stop()

    def get(self, node):
        """The node's true inputs and NMT state: ``{"x": 12.5, "nmt": "operational"}``
        (numbers as floats, the rest as text)."""
        return parse_get(self.command("get", node))
