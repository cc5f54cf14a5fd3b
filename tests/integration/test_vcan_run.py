"""tools/vcan-run over User-Mode Linux: the exit status and output come
through, a signal to vcan-run reaches the command inside, vcan-run then ends
promptly by that signal, and no process of its User-Mode Linux is left
behind, however it ends (timeout's SIGTERM, a command that ignores the
signal, SIGKILL). Run on the host (not inside vcan-run), with
VCAN_RUN_MODE=uml: the path taken where the kernel has no CAN."""
import os
import pathlib
import pty
import select
import shutil
import signal
import socket
import subprocess
import time

import pytest

from conftest import BINARY, ROOT

VCAN_RUN = str(ROOT / "tools" / "vcan-run")
BOOT = 60    # s: User-Mode Linux boots in about 3 s; generous for a loaded machine
PROMPT = 4   # s: from the signal to the end of vcan-run, when the command obeys it


@pytest.fixture(autouse=True)
def uml_present():
    if shutil.which("linux.uml") is None:
        pytest.fail("linux.uml is missing (Debian user-mode-linux): run tools/setup")


def uml_pids(umid):
    """Host processes of the User-Mode Linux instance with this umid."""
    pids = []
    for p in pathlib.Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                args = p.joinpath("cmdline").read_bytes().split(b"\0")
            except OSError:
                continue
            if f"umid={umid}".encode() in args:
                pids.append(int(p.name))
    return pids


def start(tmp_path, script, **env):
    """vcan-run bash -c SCRIPT, with $D = tmp_path (shared with the inside
    through hostfs) and TMPDIR there too (vcan-run's work directory)."""
    work = tmp_path / "tmp"
    work.mkdir(exist_ok=True)
    e = dict(os.environ, VCAN_RUN_MODE="uml", TMPDIR=str(work), D=str(tmp_path), **env)
    return subprocess.Popen([VCAN_RUN, "bash", "-c", script], env=e, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def wait_file(path, proc):
    end = time.monotonic() + BOOT
    while not path.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < end, "the command did not start inside User-Mode Linux"
        time.sleep(0.05)


def assert_torn_down(umid, tmp_path):
    assert uml_pids(umid) == [], f"linux.uml processes of {umid} left running"
    assert list((tmp_path / "tmp").iterdir()) == [], "vcan-run left its work directory"


# The command inside: says it runs, then records the first signal it gets.
RECORDER = """
for s in INT TERM HUP; do trap "echo $s > $D/got; exit 3" $s; done
echo ready > $D/ready
sleep 60 & wait $!
echo none > $D/got
"""


def test_status_and_output_pass_through(tmp_path):
    p = start(tmp_path, "ip -br link show vcan1; echo to-stderr >&2; exit 7")
    out, err = p.communicate(timeout=BOOT)
    assert p.returncode == 7
    assert out.startswith("vcan1") and "UP" in out
    assert "to-stderr" in err
    assert_torn_down(f"vcanrun{p.pid}", tmp_path)


@pytest.mark.parametrize("name", ["a b", 'a"b', "a\u00a0b"])
def test_tmpdir_the_kernel_line_cannot_carry(tmp_path, name):
    """A $TMPDIR with a blank (or a quote, or U+00A0, whose byte A0h the
    kernel takes for a blank): its path on User-Mode Linux's command line
    was split, init not found, and vcan-run said "cannot start a process on
    this host" with exit 77, ctest's skip: every vcan test skipped. The
    command runs; the work directory is in /tmp then, and gone after."""
    work = tmp_path / name
    work.mkdir()
    e = dict(os.environ, VCAN_RUN_MODE="uml", TMPDIR=str(work))
    cmd = 'ip -br link show vcan0; echo "$TMPDIR"; exit 7'
    p = subprocess.Popen([VCAN_RUN, "bash", "-c", cmd], env=e, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    out, err = p.communicate(timeout=BOOT)
    assert p.returncode == 7, err
    assert out.startswith("vcan0") and "UP" in out, (out, err)
    assert out.splitlines()[1] == str(work)  # the command's TMPDIR is the caller's
    assert list(work.iterdir()) == []
    assert list(pathlib.Path("/tmp").glob(f"vcan-run.{p.pid}.*")) == []
    assert uml_pids(f"vcanrun{p.pid}") == []


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_signal_reaches_the_command(tmp_path, sig):
    p = start(tmp_path, RECORDER)
    wait_file(tmp_path / "ready", p)
    assert uml_pids(f"vcanrun{p.pid}") != []
    t = time.monotonic()
    p.send_signal(sig)
    _, err = p.communicate(timeout=30)
    took = time.monotonic() - t
    assert (tmp_path / "got").read_text().strip() == sig.name[3:], err
    assert p.returncode == -sig, err  # ends by the signal: a shell shows 128+N
    assert took < PROMPT, f"{took:.1f} s from the signal to the end"
    assert_torn_down(f"vcanrun{p.pid}", tmp_path)


def test_timeout_tears_down(tmp_path):
    """`timeout 5 tools/vcan-run sleep 60`: ends at 5 s, nothing left."""
    work = tmp_path / "tmp"
    work.mkdir()
    e = dict(os.environ, VCAN_RUN_MODE="uml", TMPDIR=str(work))
    t = time.monotonic()
    # exec keeps the PID, which names the UML instance (umid=vcanrun<PID>).
    p = subprocess.Popen(["timeout", "5", "bash", "-c", 'echo $$; exec "$0" sleep 60', VCAN_RUN],
                         env=e, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    pid = int(p.stdout.readline())
    _, err = p.communicate(timeout=30)
    took = time.monotonic() - t
    assert p.returncode == 124, err  # timeout's "timed out"
    assert took < 5 + PROMPT, f"ended {took:.1f} s after the start"
    assert_torn_down(f"vcanrun{pid}", tmp_path)


def test_command_ignoring_the_signal_gets_the_grace_time(tmp_path):
    p = start(tmp_path, "trap '' INT TERM HUP; echo ready > $D/ready; sleep 60",
              VCAN_RUN_GRACE="1")
    wait_file(tmp_path / "ready", p)
    t = time.monotonic()
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=30)
    took = time.monotonic() - t
    assert p.returncode == -signal.SIGTERM, err
    assert 1 <= took < 1 + PROMPT, f"{took:.1f} s from the signal to the end"
    assert_torn_down(f"vcanrun{p.pid}", tmp_path)


def test_sigkill_of_vcan_run_leaves_nothing(tmp_path):
    """Nothing can be trapped: UML's parent-death signal ends it, and
    vcan-run's janitor removes its work directory, copy of the caller's
    environment and all. That copy is its owner's alone while it exists
    (mode 0600; the command inside removes it once read)."""
    p = start(tmp_path, "echo ready > $D/ready; sleep 60", VCAN_RUN_SECRET="s3cret")
    modes = set()
    end = time.monotonic() + BOOT
    while not (tmp_path / "ready").exists():
        assert p.poll() is None, p.communicate()
        assert time.monotonic() < end, "the command did not start inside User-Mode Linux"
        for f in (tmp_path / "tmp").glob("vcan-run.*/*"):
            try:
                modes.add((f.name, f.stat().st_mode & 0o777))
            except FileNotFoundError:
                pass
        time.sleep(0.005)
    assert ("env", 0o600) in modes, modes
    # What vcan-run writes there (the command's words, directory and the
    # scripts too); User-Mode Linux's own files (its pid, its mconsole
    # socket) take the caller's umask, as the command's files do.
    ours = {"env", "cmd", "cwd", "init", "run"}
    assert all(m & 0o077 == 0 for name, m in modes if name in ours), modes
    envs = list((tmp_path / "tmp").glob("vcan-run.*/env"))
    assert envs == [], "the environment's copy is still there while the command runs"
    umid = f"vcanrun{p.pid}"
    p.kill()
    p.communicate(timeout=30)
    end = time.monotonic() + PROMPT
    while (uml_pids(umid) or list((tmp_path / "tmp").iterdir())) and time.monotonic() < end:
        time.sleep(0.1)
    assert_torn_down(umid, tmp_path)


class Terminal:
    """vcan-run --shell on a pseudo-terminal, as a person at a terminal
    runs it: what is typed goes in, what the screen shows comes out."""

    def __init__(self, tmp_path, args):
        work = tmp_path / "tmp"
        work.mkdir(exist_ok=True)
        env = dict(os.environ, VCAN_RUN_MODE="uml", TMPDIR=str(work))
        self.master, slave = pty.openpty()
        self.proc = subprocess.Popen([VCAN_RUN, "--shell"] + args, stdin=slave, stdout=slave,
                                     stderr=slave, env=env, start_new_session=True)
        os.close(slave)
        self.screen = b""

    def wait_for(self, text, timeout=20):
        end = time.monotonic() + timeout
        while text.encode() not in self.screen:
            left = end - time.monotonic()
            assert left > 0, f"{text!r} not on the screen:\n{self.screen.decode(errors='replace')}"
            if select.select([self.master], [], [], left)[0]:
                try:
                    self.screen += os.read(self.master, 4096)
                except OSError:  # the terminal's other side is gone
                    assert text.encode() in self.screen, self.screen.decode(errors="replace")

    def type(self, text):
        os.write(self.master, text.encode())

    def close(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        os.close(self.master)


def test_shell_next_to_a_sensor_on_a_terminal(tmp_path):
    """A newcomer's bus: vcan-run --shell COMMAND gives a shell inside
    User-Mode Linux with the command (a sensor) running as its job %1, and
    candump, cansend and the sensor's TCP control socket at hand there.
    The port is not reachable from this machine. Ctrl-C stops the shell's
    foreground job, not the session; exit ends it, and nothing of it is
    left."""
    with socket.socket() as s:  # a port nothing listens on here
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    t = Terminal(tmp_path, [BINARY, "--product", "dst-x730-xy30", "--iface", "vcan0",
                            "--on-eof", "run", "--control", f"tcp:{port}"])
    try:
        t.wait_for("candump and cansend at hand", timeout=BOOT)
        t.wait_for("(vcan-run) ")
        t.type("jobs\n")
        t.wait_for("canopen-sensor")
        # An SDO upload of 1000h: the sensor's answer as candump shows it.
        t.type("candump -n1 vcan0,5FF:7FF & sleep 0.5; cansend vcan0 67F#4000100000000000; wait %2\n")
        t.wait_for("5FF   [8]  43 00 10 00")
        # The control socket, from inside the same User-Mode Linux.
        t.type(f"{ROOT}/build/venv/bin/python -c 'import socket, time\n"
               "for i in range(50):\n"
               "    try:\n"
               f"        s = socket.create_connection((\"127.0.0.1\", {port})); break\n"
               "    except OSError: time.sleep(0.1)\n"
               "s.sendall(b\"set x=12.5\\nget\\n\"); time.sleep(0.5); print(s.recv(200).decode())'\n")
        t.wait_for("ok x=12.500")
        # User-Mode Linux's network is its own: the port is not on this
        # machine's loopback (what docs/running.md says a runner outside meets).
        with pytest.raises(ConnectionRefusedError):
            socket.create_connection(("127.0.0.1", port), timeout=5).close()
        # (Each echo's output differs from the line typed, which the
        # terminal shows too.)
        t.type("sleep 30; echo sl''ept\n")
        time.sleep(1)
        t.type("\x03")  # Ctrl-C: to the foreground job inside
        # (The terminal drops what was typed ahead of an interrupt: wait.)
        time.sleep(1)
        t.type("echo after-$((6 * 7))\n")
        t.wait_for("after-42", timeout=10)
        assert b"slept" not in t.screen
        t.type("exit\n")
        assert t.proc.wait(timeout=PROMPT + 10) == 0
    finally:
        t.close()
    assert_torn_down(f"vcanrun{t.proc.pid}", tmp_path)


def test_shell_reads_commands_from_a_pipe(tmp_path):
    """Standard input not a terminal: the commands are read to the end,
    then run as a script inside, with vcan up; its status comes back."""
    work = tmp_path / "tmp"
    work.mkdir()
    env = dict(os.environ, VCAN_RUN_MODE="uml", TMPDIR=str(work))
    r = subprocess.run([VCAN_RUN, "--shell"], input="candump -n1 vcan1 &\nsleep 0.5\n"
                       "cansend vcan1 123#1122\nwait\nexit 3\n", capture_output=True, text=True,
                       env=env, timeout=BOOT)
    assert r.returncode == 3, r.stderr
    assert "vcan1  123   [2]  11 22" in r.stdout
    assert list(work.iterdir()) == []


# ---- One EEPROM file, one user, across User-Mode Linux kernels ----------

LEASE = 10  # s: boards/linux/nvm_file.h, LP_NVM_LEASE_S; tools/emu's HOLD_LEASE


def hold_age(lock):
    return time.time() - lock.stat().st_mtime


def test_one_eeprom_file_across_sessions(tmp_path):
    """Each tools/vcan-run is a kernel of its own, which neither the
    program's abstract-socket hold nor a flock reaches: two sessions each
    ran canopen-sensor --nvm on one file, both saved, the last save won.
    The hold file beside it is seen everywhere: a second session, the
    program on the host and tools/emu on the host are refused while the
    first runs (it renews the hold every second, seen from the host); a
    kill -9 of that session leaves the hold, refused until its lease has
    run out (aged here rather than waited for), then taken over by a third
    session; its clean stop removes it."""
    nvm, lock = tmp_path / "e.nvm", tmp_path / "e.nvm.lock"
    env = {"B": BINARY}
    first = start(tmp_path, 'exec "$B" --product jd2xxx --iface vcan0 --nvm "$D/e.nvm" '
                  '--on-eof run < /dev/null 2> "$D/first.log"', **env)
    try:
        wait_file(lock, first)
        holder = lock.read_text()
        assert holder.startswith("canopen-hold 1 boot=") and holder.endswith(
            " by=canopen-sensor\n"), holder
        pid = holder.split(" pid=")[1].split()[0]
        who = f"canopen-sensor, pid {pid} of another kernel"
        # Renewed from inside, seen on the host.
        os.utime(lock, (time.time() - 100, time.time() - 100))
        end = time.monotonic() + LEASE
        while hold_age(lock) > 50 and time.monotonic() < end:
            time.sleep(0.1)
        assert hold_age(lock) < LEASE, "the hold file is not renewed"
        # A second session: refused, exit 2, naming the holder.
        second = start(tmp_path, 'exec "$B" --product jd2xxx --iface vcan0 --nvm "$D/e.nvm" '
                       '--on-eof quit < /dev/null', **env)
        _, err = second.communicate(timeout=BOOT)
        assert second.returncode == 2, err
        assert (f"EEPROM file {nvm} is in use by {who} (boot id ") in err, err
        # The program on the host (refused before it looks for an interface).
        r = subprocess.run([BINARY, "--product", "jd2xxx", "--iface", "vcan0", "--nvm", str(nvm)],
                           stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=30)
        assert r.returncode == 2 and f"is in use by {who}" in r.stderr, r.stderr
        # tools/emu on the host, for the same file as its flash (refused
        # before QEMU would start: the image need not be one).
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        r = subprocess.run([str(ROOT / "tools" / "emu"), "--board", "rv32-virt", "--product",
                            "dst-x730-xy30", "--port", str(port), "--image", BINARY, "--flash",
                            str(nvm)], stdin=subprocess.DEVNULL, capture_output=True, text=True,
                           timeout=30)
        assert r.returncode == 2, r.stderr
        assert f"emu: flash file {nvm} is in use by {who}" in r.stderr, r.stderr
        assert lock.read_text() == holder
    finally:
        first.kill()  # a power cut: User-Mode Linux and the program die at once
        first.communicate(timeout=30)
    assert lock.read_text() == holder  # nobody removed it
    r = subprocess.run([BINARY, "--product", "jd2xxx", "--iface", "vcan0", "--nvm", str(nvm)],
                       stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=30)
    assert r.returncode == 2 and f"is in use by {who}" in r.stderr, r.stderr
    # The lease run out: another session takes the file over, and removes
    # the hold at its clean stop.
    os.utime(lock, (time.time() - LEASE - 2, time.time() - LEASE - 2))
    third = start(tmp_path, 'exec "$B" --product jd2xxx --iface vcan0 --nvm "$D/e.nvm" '
                  '--on-eof quit < /dev/null', **env)
    _, err = third.communicate(timeout=BOOT)
    assert third.returncode == 0, err
    assert f"stale hold file {lock} removed ({who} (boot id " in err, err
    assert not lock.exists()
    assert sorted(f.name for f in tmp_path.iterdir() if f.name.startswith("e.")) == [], \
        "a hold file or a helper of it was left"
