"""The control socket (--control unix:PATH | tcp:PORT): the stdin line
language with a node selector, one answer line per line, several clients,
bad input answered with `error:` and disturbing nothing."""
import contextlib
import os
import re
import socket
import subprocess
import time

import can
import pytest

from conftest import BINARY, IFACE

NODES = [("dst-x730-xy30", 0x21), ("jd2xxx", 0x22), ("inx360d", 0x23)]


class Client:
    def __init__(self, addr):
        fam = socket.AF_UNIX if isinstance(addr, str) else socket.AF_INET
        self.s = socket.socket(fam, socket.SOCK_STREAM)
        for _ in range(50):
            try:
                self.s.connect(addr)
                break
            except (FileNotFoundError, ConnectionRefusedError):
                time.sleep(0.05)
        self.s.settimeout(3)
        self.f = self.s.makefile("rb")

    def ask(self, line):
        try:
            self.s.sendall(line.encode() + b"\n")
            return self.f.readline().decode().rstrip("\n")
        except TimeoutError:
            pytest.fail(f"no answer to {line!r} on the control socket within 3 s")

    def close(self):
        self.f.close()
        self.s.close()


@pytest.fixture(params=["unix", "tcp"])
def sim(request, tmp_path):
    if not os.path.exists(f"/sys/class/net/{IFACE}"):
        pytest.fail(f"{IFACE} is not up: run these tests through tools/vcan-run")
    if request.param == "unix":
        spec, addr = f"unix:{tmp_path}/ctl.sock", str(tmp_path / "ctl.sock")
    else:
        spec, addr = "tcp:47321", ("127.0.0.1", 47321)
    cmd = [BINARY, "--iface", IFACE, "--log", str(tmp_path / "log"), "--control", spec]
    for p, i in NODES:
        cmd += ["--node", f"{p}@{i:#x}"]
    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    clients = []

    def client():
        c = Client(addr)
        clients.append(c)
        return c

    yield proc, client
    for c in clients:
        c.close()
    proc.terminate()
    assert proc.wait(timeout=5) == 0
    if request.param == "unix":
        assert not os.path.exists(addr)  # removed at exit


def test_set_get_selectors_and_nmt(sim):
    proc, client = sim
    c = client()
    assert c.ask("0x22 set x=10 y=-2.5") == "ok"
    assert c.ask("0x22 get") == "ok x=10.000 y=-2.500 temp=25.000 nmt=pre-operational"
    assert c.ask("@1 get").startswith("ok x=10.000 y=-2.500")  # index 1: the JD too
    assert c.ask("get") == "ok x=0.000 y=0.000 nmt=pre-operational"  # no selector: the first
    assert c.ask("35 set x=90") == "ok"  # decimal node-ID
    assert c.ask("@2 get") == "ok x=90.000 nmt=pre-operational"
    with can.Bus(interface="socketcan", channel=IFACE) as bus:
        bus.send(can.Message(arbitration_id=0, data=[1, 0x21], is_extended_id=False))
    time.sleep(0.1)
    assert c.ask("0x21 get").endswith("nmt=operational")
    assert c.ask("0x22 get").endswith("nmt=pre-operational")
    # @all: every instance or none: the JD and the P+F have no `sensor` fault
    assert c.ask("@all fault sensor on").startswith("error: jd2xxx: ")
    assert c.ask("@all set x=1") == "ok"
    assert c.ask("@2 get") == "ok x=1.000 nmt=pre-operational"
    assert c.ask("@all get").startswith("error: get needs one node")
    # standard input keeps working (the first instance)
    proc.stdin.write("set y=7\n")
    proc.stdin.flush()
    time.sleep(0.2)
    assert c.ask("@0 get") == "ok x=1.000 y=7.000 nmt=operational"


def test_bad_lines_get_an_error_and_change_nothing(sim):
    _, client = sim
    c = client()
    assert c.ask("0x22 set x=3") == "ok"
    for line, cause in [("@7 get", "error: no node @7 (@0..@2, or @all)"),
                        ("@x get", "error: no node @x"),
                        ("0x55 get", "error: no node with node-ID 0x55"),
                        ("0x22", "error: no command"),
                        ("0x22 frobnicate", "error: "),
                        ("0x22 set nope=1", "error: "),
                        ("0x22 set x=1 nope=2", "error: "),
                        ("0x22 get now", "error: get takes nothing after it"),
                        ("0x22 set x=" + "1" * 300, "error: line longer than 255"),
                        ("0x22 set\0 x=1", "error: line holds a NUL byte")]:
        assert c.ask(line).startswith(cause), line
    assert c.ask("0x22 get").startswith("ok x=3.000 ")


def test_clients_at_once_and_one_leaving_mid_line(sim):
    _, client = sim
    a, b = client(), client()
    a.s.sendall(b"0x22 set x=")          # half a line ...
    assert b.ask("0x21 set x=4") == "ok"  # ... another client goes on
    a.close()                             # ... and the half is dropped with its client
    time.sleep(0.1)
    assert b.ask("0x22 get").startswith("ok x=0.000 ")
    c = client()
    assert c.ask("0x21 get").startswith("ok x=4.000 ")
    assert b.ask("0x23 set x=2") == "ok"


def test_quit_through_control(tmp_path):
    path = str(tmp_path / "q.sock")
    proc = subprocess.Popen([BINARY, "--iface", IFACE, "--node", "jd2xxx@5", "--control",
                             f"unix:{path}", "--on-eof", "run"], stdin=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    c = Client(path)
    assert c.ask("quit") == "ok"
    assert proc.wait(timeout=5) == 0
    c.close()


def run(*args):
    return subprocess.run([BINARY, "--iface", IFACE, "--node", "jd2xxx@5", *args],
                          capture_output=True, text=True, timeout=10, stdin=subprocess.DEVNULL)


def test_control_path_that_exists(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    r = run("--control", f"unix:{f}")
    assert r.returncode == 2 and "the path exists and is not a socket" in r.stderr
    assert f.read_text() == "x"
    r = run("--control", "udp:4")
    assert r.returncode == 2 and "give unix:PATH or tcp:PORT" in r.stderr
    r = run("--control", "tcp:0")
    assert r.returncode == 2 and "not a port 1..65535" in r.stderr
    # a live socket: refused; a stale one (nobody listening): replaced
    live = str(tmp_path / "live.sock")
    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.bind(live)
    s.listen(1)
    r = run("--control", f"unix:{live}")
    assert r.returncode == 2 and "a socket in use" in r.stderr
    s.close()  # the path stays: stale now
    proc = subprocess.Popen([BINARY, "--iface", IFACE, "--node", "jd2xxx@5", "--control",
                             f"unix:{live}", "--on-eof", "run"], stdin=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    c = Client(live)
    assert c.ask("get").startswith("ok ")
    c.close()
    proc.terminate()
    assert proc.wait(timeout=5) == 0


def test_stdin_beside_the_control_socket_of_a_product(sensor_factory):
    """The integration tests' Sensor (--product, --control) with its standard
    input kept (stdin=True): a line typed there reaches the same node the
    control socket reads back, and the socket's lines reach it too."""
    sensor = sensor_factory("jd2xxx", stdin=True).start()
    sensor.write_stdin("set x=7 y=-3")
    deadline = time.monotonic() + 2
    while sensor.get()["x"] != 7.0:
        assert time.monotonic() < deadline, f"stdin's set not taken: {sensor.get()}"
        time.sleep(0.02)
    assert sensor.get()["y"] == -3.0
    sensor.send("set y=4")
    assert sensor.get()["x"] == 7.0
    assert sensor.stop() == 0


def test_replay_reads_regular_files_once_for_all(sim, tmp_path):
    """A FIFO (or any file that is not regular) is refused at once: opening
    it used to block the whole program; @all starts one table on every
    instance that has its inputs, or on none."""
    proc, client = sim
    c = client()
    fifo = tmp_path / "f.csv"
    os.mkfifo(fifo)
    assert c.ask(f"replay {fifo}") == f"error: replay {fifo}: not a regular file"
    assert c.ask(f"replay {tmp_path}") == f"error: replay {tmp_path}: not a regular file"
    assert c.ask("get").startswith("ok x=0.000")  # still answering
    table = tmp_path / "t.csv"
    table.write_text("t,x\n0,12\n1000,12\n")
    # inx360d's x is 0..360 as well: every instance has an x.
    assert c.ask(f"@all replay {table}") == "ok"
    time.sleep(0.1)
    for sel in ("0x21", "0x22", "0x23"):
        assert c.ask(f"{sel} get").startswith("ok x=12.000"), sel
    bad = tmp_path / "b.csv"
    bad.write_text("t,y\n0,5\n")  # the INX has no y: refused for all, nothing changes
    assert c.ask(f"@all replay {bad}").startswith("error: inx360d: replay")
    assert c.ask("0x21 get").startswith("ok x=12.000 y=0.000")


def test_a_full_standard_output_holds_nothing_up(tmp_path):
    """`get` on standard input answers on standard output; a pipe nobody
    reads fills up, and the answers are then dropped (counted in the log)
    while the nodes and the control socket carry on."""
    sock = str(tmp_path / "ctl.sock")
    proc = subprocess.Popen([BINARY, "--iface", IFACE, "--product", "dst-x730-xy30", "--log",
                             str(tmp_path / "log"), "--control", f"unix:{sock}"],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    try:
        c = Client(sock)
        proc.stdin.write(b"get\n" * 5000)  # about 200 kB of answers: more than a pipe holds
        proc.stdin.flush()
        time.sleep(1.0)
        assert c.ask("get").startswith("ok x=0.000"), "the loop is held up"
        c.close()
        assert "standard output cannot take the answer to get: dropped" in \
            (tmp_path / "log").read_text()
        first = proc.stdout.readline()
        assert first.startswith(b"ok x=0.000 y=0.000 ")
    finally:
        proc.terminate()
        assert proc.wait(timeout=5) == 0


def test_a_client_faster_than_it_reads_is_slowed_down_not_cut_off(sim):
    """3000 lines in one go: every answer comes, in order (the program
    stops reading the client while its answers wait for the kernel); a
    client that never reads only holds its own slot."""
    proc, client = sim
    lazy = client()
    lazy.s.sendall(b"get\n" * 20000)  # never reads a byte of its answers
    c = client()
    lines = [f"0x22 set x={i % 90}" if i % 2 else "0x22 get" for i in range(3000)]
    c.s.sendall(("\n".join(lines) + "\n").encode())
    for i, line in enumerate(lines):
        answer = c.f.readline().decode().rstrip("\n")
        if i % 2:
            assert answer == "ok", (i, answer)
        else:
            assert answer.startswith(f"ok x={(i - 1) % 90 if i else 0}.000 "), (i, answer)
    assert client().ask("get").startswith("ok x=0.000")  # others served meanwhile


def test_lines_that_misled(sim, tmp_path):
    """An empty line names every command; a node-ID out of 1..127 (0xFF: an
    LSS-unconfigured node's) is not 'held by more than one node'; a replay
    file with a UTF-8 byte order mark (as spreadsheets save CSV) is taken;
    a relative name's error says which directory it was looked for in."""
    proc, client = sim
    c = client()
    assert c.ask("") == \
        "error: no command (set, ramp, sine, noise, replay, fault, can, get, quit)"
    assert c.ask("0xFF get") == \
        "error: '0xFF': not a node-ID 1..127 (a node without one: select it by index, @N)"
    assert c.ask("0 get").startswith("error: '0': not a node-ID 1..127")
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbft,x\r\n0,21\r\n")
    assert c.ask(f"0x22 replay {bom}") == "ok"
    time.sleep(0.05)
    assert c.ask("0x22 get").startswith("ok x=21.000")
    cwd = os.getcwd()
    assert c.ask("replay no-such.csv") == \
        f"error: replay no-such.csv: No such file or directory (in {cwd}, the program's " \
        "working directory)"


def test_replay_file_size_bounded(sim, tmp_path):
    """A replay file is read while every node waits: 10 MB of comments
    held every node 8.5 s. Beyond SIM_REPLAY_BYTES (256 KiB) it is refused
    at once, saying why; one just within is read in a pass of the loop
    shorter than the JD's 50 ms heartbeat period by the program's own
    clock (its log; about 2 ms on a PC, the rest is margin for a loaded
    machine), and the heartbeat goes on meanwhile."""
    proc, client = sim
    c = client()
    huge = tmp_path / "huge.csv"
    with open(huge, "w") as f:
        f.write("t,x\n" + "#\n" * 5_000_000 + "0,1\n")
    assert c.ask(f"replay {huge}") == \
        f"error: replay {huge}: 10000008 bytes, more than the 262144 a replay file may have " \
        "(it is read while every node waits)"
    big = tmp_path / "big.csv"  # 131068 comment lines: at the limit, in bytes
    big.write_text("t,x\n" + "#\n" * ((262144 - 8) // 2) + "0,2\n")
    assert big.stat().st_size == 262144
    bus = can.Bus(interface="socketcan", channel=IFACE,
                  can_filters=[{"can_id": 0x722, "can_mask": 0x7FF}])
    try:
        # 50 ms heartbeat on the JD (0x1017 through SDO would need a master:
        # the JD's default is 0, so set it with a raw expedited download)
        sdo = can.Bus(interface="socketcan", channel=IFACE,
                      can_filters=[{"can_id": 0x5A2, "can_mask": 0x7FF}])
        sdo.send(can.Message(arbitration_id=0x622, is_extended_id=False,
                             data=bytes([0x2B, 0x17, 0x10, 0, 50, 0, 0, 0])))
        answer = sdo.recv(2)
        assert answer is not None and answer.data[0] == 0x60, answer
        sdo.shutdown()
        beats = 0
        end = time.monotonic() + 1.5
        sent = False
        while time.monotonic() < end:
            beats += bus.recv(0.2) is not None
            if not sent and time.monotonic() > end - 1.0:
                assert c.ask(f"0x22 replay {big}") == "ok"
                sent = True
        # Loose: the wall-clock arrivals are the emulated kernel's as much
        # as the program's (docs/testing.md, "Bounds and timing"); 30 due.
        assert beats >= 22, f"{beats} heartbeats in 1.5 s at 50 ms"
    finally:
        bus.shutdown()
    assert c.ask("0x22 get").startswith("ok x=2.000")
    proc.terminate()
    assert proc.wait(timeout=5) == 0
    log = (tmp_path / "log").read_text()
    longest = re.search(r"loop: the longest pass took (\d+\.\d+) ms", log)
    assert longest, log[-2000:]
    assert float(longest[1]) < 50, log[-2000:]


def test_socket_removed_at_stop_only_when_ours(tmp_path):
    """A clean stop removed the unix socket at PATH whoever bound it: after
    ours was removed and another program bound PATH, that one's was
    deleted. Only the socket this process bound goes."""
    path = str(tmp_path / "c.sock")
    proc = subprocess.Popen([BINARY, "--iface", IFACE, "--node", "jd2xxx@5", "--control",
                             f"unix:{path}", "--on-eof", "run"], stdin=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    c = Client(path)
    assert c.ask("get").startswith("ok ")
    c.close()
    os.unlink(path)
    other = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    other.bind(path)
    other.listen(1)
    proc.terminate()
    assert proc.wait(timeout=5) == 0
    assert os.path.exists(path), "another program's socket was removed"
    other.close()


def test_answers_show_control_bytes_escaped(sim):
    """An error answer showed the client's bytes raw (an escape sequence
    sent came back to its terminal): bytes that are not printable ASCII
    are \\xNN in it, as in standard input's rejections."""
    proc, client = sim
    c = client()
    c.s.sendall(b"\x1b]0;pwned\x07get\n")
    answer = c.f.readline()
    assert answer.startswith(b"error: unknown command '\\x1B]0;pwned\\x07get'"), answer
    assert b"\x1b" not in answer and b"\x07" not in answer
    c.s.sendall(b"0x22 \xff\n")
    answer = c.f.readline()
    assert b"\\xFF" in answer and b"\xff" not in answer, answer
    assert c.ask("0x22 get").startswith("ok x=")  # and nothing else disturbed


CTL = os.path.join(os.path.dirname(__file__), "..", "..", "tools", "ctl")


@contextlib.contextmanager
def ctl_beside_two_nodes(tmp_path):
    """tools/ctl's path and a control socket's, the socket listening in a
    process with a JD2 at 0x22 and an INX at 0x23; the process must end
    cleanly (status 0) afterwards."""
    path = str(tmp_path / "c.sock")
    proc = subprocess.Popen([BINARY, "--iface", IFACE, "--node", "jd2xxx@0x22", "--node",
                             "inx360d@0x23", "--control", f"unix:{path}", "--on-eof", "run"],
                            stdin=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        Client(path).close()  # listening
        yield CTL, path
    finally:
        proc.terminate()
        assert proc.wait(timeout=5) == 0


def test_ctl_client(tmp_path):
    """tools/ctl: one command from its arguments, or lines from standard
    input; answers printed as they come; exit 0 / 1 (an error answer) / 2."""
    with ctl_beside_two_nodes(tmp_path) as (ctl, path):
        r = subprocess.run([ctl, f"unix:{path}", "0x22", "set", "x=5"], capture_output=True,
                           text=True, timeout=10)
        assert (r.returncode, r.stdout) == (0, "ok\n"), r.stderr
        r = subprocess.run([ctl, path, "0x22 get"], capture_output=True, text=True, timeout=10)
        assert r.returncode == 0 and r.stdout.startswith("ok x=5.000 "), r
        r = subprocess.run([ctl, f"unix:{path}"], input="0x23 set x=7\n0x23 get\n0x24 get\n",
                           capture_output=True, text=True, timeout=10)
        lines = r.stdout.splitlines()
        assert r.returncode == 1 and lines[0] == "ok" and lines[1].startswith("ok x=7.000 ")
        assert lines[2] == "error: no node with node-ID 0x24"
        r = subprocess.run([ctl, str(tmp_path / "none.sock"), "get"], capture_output=True,
                           text=True, timeout=10)
        assert r.returncode == 2 and "No such file or directory" in r.stderr
        r = subprocess.run([ctl], capture_output=True, text=True, timeout=10)
        assert r.returncode == 2 and "usage: tools/ctl" in r.stderr


def test_ctl_client_passes_bytes_that_are_not_utf8(tmp_path):
    """tools/ctl sends a line that is not UTF-8 (standard input or an
    argument) as its bytes and goes on with the next; it died with a
    UnicodeEncodeError traceback, the lines after it never sent."""
    with ctl_beside_two_nodes(tmp_path) as (ctl, path):
        r = subprocess.run([ctl, f"unix:{path}"], input=b"0x22 get\n\xff\xfe get\n0x23 get\n",
                           capture_output=True, timeout=10)
        lines = r.stdout.splitlines()
        assert r.returncode == 1 and b"Traceback" not in r.stderr, r
        assert len(lines) == 3 and lines[0].startswith(b"ok x=") and lines[2].startswith(b"ok x=")
        assert lines[1].startswith(b"error: unknown command"), lines
        r = subprocess.run([ctl.encode(), path.encode(), b"0x22", b"\xff"], capture_output=True,
                           timeout=10)
        assert r.returncode == 1 and b"Traceback" not in r.stderr, r
        assert r.stdout.startswith(b"error: ") and r.stdout.count(b"\n") == 1, r


def test_selectors_on_standard_input(tmp_path):
    """Standard input takes the control socket's selectors: 0xNN, @N, @all
    (a line without one acts on the first instance, as before); a selected
    get answers on standard output, a bad line is rejected on stderr."""
    path = str(tmp_path / "c.sock")
    proc = subprocess.Popen([BINARY, "--iface", IFACE, "--node", "jd2xxx@0x22", "--node",
                             "inx360d@0x23", "--control", f"unix:{path}", "--log",
                             str(tmp_path / "log")], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        c = Client(path)
        proc.stdin.write(b"0x23 set x=9\n@0 set x=4\n@1 get\n@all set x=1\n0x7E get\n"
                         b"0x22 get\n0x22 set\ty=2\n")
        proc.stdin.flush()
        assert proc.stdout.readline().startswith(b"ok x=9.000 ")
        assert proc.stdout.readline().startswith(b"ok x=1.000 ")
        assert c.ask("0x23 get").startswith("ok x=1.000")
        assert c.ask("0x22 set\tx=2") == "ok"
        c.close()
        proc.stdin.close()
        assert proc.wait(timeout=5) == 0
        assert "no node with node-ID 0x7E" in proc.stderr.read().decode()
        log = (tmp_path / "log").read_text()
        assert "stdin: 0x23 set x=9" in log and "control: 0x23 set x=9" not in log
        # a control line's bytes as standard input's: \\xNN, never raw
        assert "stdin: 0x22 set\\x09y=2" in log and "control: 0x22 set\\x09x=2" in log, log
        assert "\t" not in log
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_selector_of_nodes_lss_made_unconfigured(tmp_path):
    """Two JDs made LSS-unconfigured (node-ID 0xFF, CiA 305): '0xFF get'
    said 'held by more than one node'; 0xFF is no node-ID, and @N selects
    a node without one."""
    path = str(tmp_path / "c.sock")
    proc = subprocess.Popen([BINARY, "--iface", IFACE, "--node", "jd2xxx@0x22", "--node",
                             "jd1xxx@0x24", "--control", f"unix:{path}", "--on-eof", "run"],
                            stdin=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    bus = can.Bus(interface="socketcan", channel=IFACE,
                  can_filters=[{"can_id": 0x7E4, "can_mask": 0x7FF}])
    try:
        c = Client(path)
        # switch state global (configuration), configure node-ID 0xFF, waiting
        for data in ("0401", "11FF", "0400"):
            bus.send(can.Message(arbitration_id=0x7E5, data=bytes.fromhex(data).ljust(8, b"\0"),
                                 is_extended_id=False))
        answers = [bus.recv(1) for _ in range(2)]
        assert all(m is not None and bytes(m.data[:2]) == b"\x11\x00" for m in answers), answers
        bus.send(can.Message(arbitration_id=0x000, data=b"\x82\x00", is_extended_id=False))
        end = time.monotonic() + 3
        while not (c.ask("0x22 get").startswith("error: no node") and
                   c.ask("0x24 get").startswith("error: no node")):
            assert time.monotonic() < end, "the JDs kept their node-IDs"
            time.sleep(0.05)
        assert c.ask("0xFF get") == \
            "error: '0xFF': not a node-ID 1..127 (a node without one: select it by index, @N)"
        assert c.ask("@1 get").startswith("ok z=0.000 ")
        c.close()
    finally:
        bus.shutdown()
        proc.terminate()
        assert proc.wait(timeout=5) == 0
