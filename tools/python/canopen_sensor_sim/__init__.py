"""Simulated CANopen sensors for machine tests.

A ``SimBus`` runs one ``canopen-sensor`` process with any number of nodes
(``--node PRODUCT[@NODEID][/IFACE]``) on a SocketCAN interface, each with its
own stored parameters in a directory, and talks to it through its control
socket (``--control unix:PATH``): the same line language as its standard
input, one command a line, answered ``ok ...`` or ``error: <cause>``.

    with SimBus(["dst-x730-xy30@0x20", "jd2xxx@0x21"], interface="vcan0") as bus:
        bus.set(0x20, x=12.5)
        bus.ramp(0x21, "x", 30, seconds=5)
        assert bus.get(0x20)["nmt"] == "pre-operational"

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

__all__ = ["SimBus", "SimError", "find_program"]


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


def _selector(node):
    """The node selector of a control line: a node-ID (int), "@all", or None."""
    if node is None:
        return ""
    if isinstance(node, int):
        return f"0x{node:02X} "
    return f"{node} "


def _value(v):
    """An input value as the line language writes it (units of the input)."""
    return f"{v:.3f}" if isinstance(v, float) else str(v)


class SimBus:
    """One canopen-sensor process with its nodes; a context manager.

    nodes: ``"PRODUCT[@NODEID][/IFACE]"`` strings; interface: the default
    CAN interface; nvm_dir: where each node keeps its stored set (a fresh
    temporary directory when None: every start is a factory-new device);
    seed: the motion generator's seed (``--seed``); extra: more arguments.
    """

    def __init__(self, nodes, interface="vcan0", nvm_dir=None, seed=None, program=None,
                 extra=(), start_timeout=10.0):
        self.nodes = list(nodes)
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
        self._sock = None
        self._rx = b""

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
        if self.control_path.exists():
            self.control_path.unlink()
        self._rx = b""
        self.proc = subprocess.Popen(self.command_line(), stdin=subprocess.DEVNULL,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        deadline = time.monotonic() + self.start_timeout
        while True:
            if self.proc.poll() is not None:
                err = self.proc.stderr.read().decode(errors="replace").strip()
                raise SimError(f"canopen-sensor exited with {self.proc.returncode}: {err}")
            try:
                s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
                s.connect(str(self.control_path))
                self._sock = s
                return self
            except OSError:
                s.close()
                if time.monotonic() > deadline:
                    self.stop()
                    raise SimError(f"no control socket at {self.control_path} after "
                                   f"{self.start_timeout} s")
                time.sleep(0.05)

    def stop(self, timeout=5.0):
        """Power off cleanly (SIGTERM); returns the exit status."""
        if self._sock is not None:
            self._sock.close()
            self._sock = None
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
        if self._sock is None:
            raise SimError("the bus is not started")
        if "\n" in line:
            raise SimError("one command a line")
        self._sock.sendall((_selector(node) + line + "\n").encode())
        self._sock.settimeout(timeout)
        while b"\n" not in self._rx:
            chunk = self._sock.recv(4096)
            if not chunk:
                raise SimError(f"control socket closed while waiting for the answer to {line!r}")
            self._rx += chunk
        answer, self._rx = self._rx.split(b"\n", 1)
        text = answer.decode(errors="replace").strip()
        if text == "ok" or text.startswith("ok "):
            return text[3:]
        if text.startswith("error:"):
            raise SimError(text[6:].strip())
        raise SimError(f"unexpected answer {text!r} to {line!r}")

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

    def get(self, node):
        """The node's true inputs and NMT state: ``{"x": 12.5, "nmt": "operational"}``
        (numbers as floats, the rest as text)."""
        out = {}
        for token in self.command("get", node).split():
            key, _, value = token.partition("=")
            try:
                out[key] = float(value)
            except ValueError:
                out[key] = value
        return out
