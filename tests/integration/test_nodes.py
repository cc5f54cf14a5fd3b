"""Many nodes in one canopen-sensor process (--node PRODUCT[@ID][/IFACE],
--nvm-dir): each answers on its own node-ID, has its own stored set, and a
node-ID given on the command line is its factory default (what a blank
EEPROM boots with and what 0x1011 "restore defaults" returns to). The
usage errors need no CAN: they are refused before any socket opens."""
import signal
import socket
import subprocess
import time

import canopen

from conftest import BINARY, IFACE, eds_od


def run(*args):
    return subprocess.run([BINARY, *args], capture_output=True, text=True, timeout=10,
                          stdin=subprocess.DEVNULL)


def refused(r, text):
    assert r.returncode == 2, (r.returncode, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and text in lines[0], r.stderr


def test_usage_errors(tmp_path):
    refused(run("--node", "jd2xxx@0x21", "--node", "dst-x730-xy30@33", "--iface", "vcan0"),
            "node-ID 0x21 twice on vcan0 (jd2xxx and dst-x730-xy30)")
    # Without @ID each takes its product's default: two GSH-A (0x13) clash.
    refused(run("--node", "gsh-a", "--node", "gsh-a-redundant", "--iface", "vcan0"),
            "node-ID 0x13 twice on vcan0")
    refused(run("--product", "jd2xxx", "--node", "jd1xxx", "--iface", "vcan0"),
            "node-ID 0x0A twice on vcan0 (jd2xxx and jd1xxx)")
    refused(run("--node", "nope@3", "--iface", "vcan0"), "--node nope@3: unknown product 'nope'")
    refused(run("--node", "jd2xxx@128", "--iface", "vcan0"), "node-ID '128' is not 1..127")
    refused(run("--node", "jd2xxx@", "--iface", "vcan0"), "node-ID '' is not 1..127")
    refused(run("--node", "gsh-a-redundant@127", "--iface", "vcan0"),
            "--node gsh-a-redundant@127: gsh-a-redundant has 2 nodes, node-IDs 0x7F to 0x80: "
            "the last passes 127 (give at most 0x7E)")
    refused(run("--node", "jd2xxx@5"), "--node jd2xxx@5: no interface (give /IFACE or --iface)")
    refused(run("--node", "jd2xxx@5/vcan0,vcan1"), "jd2xxx has one node")
    many = [a for i in range(1, 129) for a in ("--node", f"jd2xxx@{min(i, 127)}")]
    refused(run(*many, "--iface", "vcan0"), "more than 127 nodes in one process")
    many = [a for i in range(1, 65) for a in ("--node", f"gsh-a-redundant@1/vcan{i}")]
    refused(run(*many), "128 nodes: at most 127 in one process")
    refused(run("--node", "jd2xxx@5", "--iface", "vcan0", "--nvm", str(tmp_path / "e")),
            "use --nvm-dir with --node")
    refused(run("--node", "jd2xxx@5", "--iface", "vcan0", "--nvm-dir", str(tmp_path / "no")),
            "not a directory")


def test_the_same_id_on_two_interfaces_is_no_clash():
    r = run("--node", "jd2xxx@5/vcan-nope0", "--node", "jd2xxx@5/vcan-nope1")
    assert r.returncode == 1 and "vcan-nope0" in r.stderr  # past the clash check


PRODUCTS = [("dst-x730-xy30", 0x21), ("jd2xxx", 0x22), ("inx360d", 0x23)]


class Bench:
    """One process with several --node options, and a master on vcan0."""

    def __init__(self, tmp_path, network, bus, extra=()):
        self.tmp, self.network, self.bus, self.extra = tmp_path, network, bus, list(extra)
        self.nvm = tmp_path / "nvm"
        self.nvm.mkdir(exist_ok=True)
        self.proc = None

    def start(self, expect_ids):
        self.bus.clear()
        cmd = [BINARY, "--iface", IFACE, "--nvm-dir", str(self.nvm), "--log",
               str(self.tmp / "sensor.log"), "--on-eof", "run"]
        for p, i in PRODUCTS:
            cmd += ["--node", f"{p}@{i:#x}"]
        self.proc = subprocess.Popen(cmd + self.extra, stdin=subprocess.DEVNULL)
        seen = set()
        for m in self.bus.frames(4):
            if 0x701 <= m.arbitration_id <= 0x77F and bytes(m.data) == b"\0":
                seen.add(m.arbitration_id - 0x700)
            if seen >= set(expect_ids):
                break
        assert seen >= set(expect_ids), f"boot-ups {sorted(seen)}, expected {expect_ids}"

    def node(self, product, node_id):
        n = canopen.RemoteNode(node_id, eds_od(product, self.tmp, node_id))
        self.network.add_node(n)
        return n

    def stop(self):
        self.proc.send_signal(signal.SIGTERM)
        assert self.proc.wait(timeout=5) == 0


def test_three_products_in_one_process(tmp_path, network, bus):
    b = Bench(tmp_path, network, bus)
    b.start([i for _, i in PRODUCTS])
    try:
        nodes = [b.node(p, i) for p, i in PRODUCTS]
        for n in nodes:
            assert n.sdo.upload(0x1000, 0)  # each answers SDO on its own ID
            n.sdo.download(0x1017, 0, (100).to_bytes(2, "little"))
        bus.clear()
        beats = {}
        for m in bus.frames(1.0):
            if 0x721 <= m.arbitration_id <= 0x723:
                beats[m.arbitration_id] = beats.get(m.arbitration_id, 0) + 1
        for _, i in PRODUCTS:
            assert 8 <= beats.get(0x700 + i, 0) <= 12, beats  # 100 ms each
    finally:
        b.stop()
    names = sorted(f.name for f in b.nvm.iterdir())
    # Only the P+F stores every write by itself (autonomous store): its own file.
    assert names == ["inx360d-0x23-vcan0.nvm"], names


def test_own_stored_sets_and_restore_defaults_to_the_command_line_id(tmp_path, network, bus):
    b = Bench(tmp_path, network, bus)
    b.start([0x21, 0x22, 0x23])
    try:
        jd = b.node("jd2xxx", 0x22)
        assert jd.sdo.upload(0x3000, 0) == bytes([0x21])  # node number = ID - 1
        jd.sdo.download(0x3000, 0, bytes([0x3F]))          # node-ID 0x40 ...
        jd.sdo.download(0x1010, 1, b"save")                # ... stored
    finally:
        b.stop()
    assert sorted(f.name for f in b.nvm.iterdir()) == ["jd2xxx-0x22-vcan0.nvm"]
    b.start([0x21, 0x40, 0x23])  # a power cycle: the stored ID; the others as they were
    try:
        jd = b.node("jd2xxx", 0x40)
        jd.sdo.download(0x1011, 1, b"load")
    finally:
        b.stop()
    b.start([0x21, 0x22, 0x23])  # restore defaults: the command line's node-ID again
    b.stop()


def test_a_clash_made_over_can_is_logged(tmp_path, network, bus):
    """A node-ID clash the command line did not have, made later over CAN
    (the JD's 3000h, then reset node): both nodes run on (as devices
    would), and the log says which two collide; a new ID ends it."""
    b = Bench(tmp_path, network, bus)
    b.start([0x21, 0x22, 0x23])
    try:
        jd = b.node("jd2xxx", 0x22)
        jd.sdo.download(0x3000, 0, bytes([0x20]))  # node number 0x20: node-ID 0x21, the DST's
        jd.sdo.download(0x1010, 1, b"save")        # reset node loads the stored set
        bus.clear()
        network.send_message(0x000, bytes([0x81, 0x22]))  # reset node
        assert bus.wait_for(0x721, timeout=3, pred=lambda m: bytes(m.data) == b"\0")
        time.sleep(0.2)
        log = (tmp_path / "sensor.log").read_text()
        assert ("warning: node 0 (dst-x730-xy30) and node 1 (jd2xxx) both have node-ID 0x21 "
                "on vcan0: their frames collide") in log
        assert b.proc.poll() is None  # running on
    finally:
        b.stop()


def sdo_on(channel, node_id, request, timeout=2.0):
    """One SDO request on a bus of its own; the answer's 8 bytes."""
    import can
    with can.Bus(interface="socketcan", channel=channel) as b:
        b.send(can.Message(arbitration_id=0x600 + node_id, data=bytes.fromhex(request),
                           is_extended_id=False))
        end = time.monotonic() + timeout
        while (left := end - time.monotonic()) > 0:
            m = b.recv(left)
            if m is not None and m.arbitration_id == 0x580 + node_id:
                return bytes(m.data)
    return None


def test_one_id_on_two_buses_is_two_devices_with_two_files(tmp_path):
    """jd2xxx@0x21 on vcan0 and on vcan1: each saves into its own file
    (the interface is in the name), and each reads its own value back
    after a power cycle."""
    nvm = tmp_path / "nvm"
    nvm.mkdir()
    cmd = [BINARY, "--on-eof", "run", "--nvm-dir", str(nvm), "--log", str(tmp_path / "log"),
           "--node", "jd2xxx@0x21/vcan0", "--node", "jd2xxx@0x21/vcan1"]
    for run_no in range(2):
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL)
        try:
            # Up on both buses (not a fixed sleep: a loaded machine starts slower)
            for ch in ("vcan0", "vcan1"):
                end = time.monotonic() + 10
                while sdo_on(ch, 0x21, "4000100000000000", timeout=0.3) is None:
                    assert time.monotonic() < end, f"no SDO answer on {ch}"
            if run_no == 0:
                for ch, hb in (("vcan0", "3412"), ("vcan1", "7707")):
                    assert sdo_on(ch, 0x21, f"2B171000{hb}0000")[0] == 0x60
                    assert sdo_on(ch, 0x21, "2310100173617665")[0] == 0x60  # save
            else:
                assert sdo_on("vcan0", 0x21, "4017100000000000")[4:6] == bytes.fromhex("3412")
                assert sdo_on("vcan1", 0x21, "4017100000000000")[4:6] == bytes.fromhex("7707")
        finally:
            proc.terminate()
            assert proc.wait(timeout=5) == 0
    assert sorted(f.name for f in nvm.iterdir()) == ["jd2xxx-0x21-vcan0.nvm",
                                                     "jd2xxx-0x21-vcan1.nvm"]


def test_a_file_of_the_former_name_is_taken_over(tmp_path, network, bus):
    """DIR/PRODUCT-0xNN.nvm (before the interface was in the name) is
    renamed to the new name at start, its stored set kept."""
    b = Bench(tmp_path, network, bus)
    b.start([0x21, 0x22, 0x23])
    try:
        jd = b.node("jd2xxx", 0x22)
        jd.sdo.download(0x1017, 0, (0x1234).to_bytes(2, "little"))
        jd.sdo.download(0x1010, 1, b"save")
    finally:
        b.stop()
    (b.nvm / "jd2xxx-0x22-vcan0.nvm").rename(b.nvm / "jd2xxx-0x22.nvm")
    b.start([0x21, 0x22, 0x23])
    try:
        assert jd.sdo.upload(0x1017, 0) == (0x1234).to_bytes(2, "little")
    finally:
        b.stop()
    assert not (b.nvm / "jd2xxx-0x22.nvm").exists()
    assert "jd2xxx-0x22.nvm renamed" in (tmp_path / "sensor.log").read_text()


def test_two_node_product_and_two_interfaces(tmp_path, network, bus):
    """gsh-a-redundant@0x30 is nodes 0x30 and 0x31; /vcan1 puts one on vcan1."""
    b = Bench(tmp_path, network, bus, ["--node", "gsh-a-redundant@0x30",
                                        "--node", "jd1xxx@0x21/vcan1"])
    b.start([0x21, 0x22, 0x23, 0x30, 0x31])
    b.stop()
    log = (tmp_path / "sensor.log").read_text()
    assert "jd1xxx, node-ID 0x21 on vcan1" in log
    assert "gsh-a-redundant, node-ID 0x31 on vcan0" in log


def test_127_nodes_in_one_process(tmp_path, bus):
    """The most one bus holds: every node boots on its command-line ID and
    the last one answers through the control socket."""
    sock = str(tmp_path / "ctl.sock")
    cmd = [BINARY, "--iface", IFACE, "--on-eof", "run", "--log", str(tmp_path / "log"),
           "--control", f"unix:{sock}"]
    products = ["jd2xxx", "dst-x730-xy30", "inx360d", "gsh-a"]
    for i in range(1, 128):
        cmd += ["--node", f"{products[i % 4]}@{i}"]
    bus.clear()
    proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL)
    try:
        seen = set()
        for m in bus.frames(10):
            if 0x701 <= m.arbitration_id <= 0x77F and bytes(m.data) == b"\0":
                seen.add(m.arbitration_id - 0x700)
            if len(seen) == 127:
                break
        assert seen == set(range(1, 128))
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.connect(sock)
        s.sendall(b"@125 get\n126 set x=1.5\n126 get\n")  # ID 126: inx360d
        f = s.makefile("rb")
        assert f.readline().startswith(b"ok x=0.000 ")
        assert f.readline() == b"ok\n"
        assert f.readline().startswith(b"ok x=1.500 ")
        s.close()
    finally:
        proc.terminate()
        assert proc.wait(timeout=10) == 0


# --- serial numbers: each node its own LSS address (CiA 305) ---------------

JDS = (("jd2xxx", 0x21), ("jd2xxx", 0x22), ("jd1xxx", 0x23))


def start_jds(tmp_path, bus, extra=()):
    bus.clear()
    cmd = [BINARY, "--iface", IFACE, "--log", str(tmp_path / "sensor.log"), "--on-eof", "run"]
    for p, i in JDS:
        cmd += ["--node", f"{p}@{i:#x}"]
    proc = subprocess.Popen(cmd + list(extra), stdin=subprocess.DEVNULL)
    seen = set()
    for m in bus.frames(4):
        if m.arbitration_id in (0x721, 0x722, 0x723) and bytes(m.data) == b"\0":
            seen.add(m.arbitration_id)
        if len(seen) == 3:
            break
    assert len(seen) == 3, f"boot-ups {sorted(seen)}"
    return proc


def stop(proc):
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=5) == 0


def identities(network):
    """1018h subs 1..4 of each JD, by SDO."""
    out = {}
    for _, i in JDS:
        node = network[i] if i in network else network.add_node(i, canopen.ObjectDictionary())
        out[i] = tuple(int.from_bytes(node.sdo.upload(0x1018, s), "little") for s in range(1, 5))
    return out


def lss(network, cs, data=b""):
    network.send_message(0x7E5, bytes([cs]) + data.ljust(7, b"\0"))


def test_three_jds_have_their_own_lss_addresses(tmp_path, network, bus):
    """Three JDs on one bus: 1018h:04 differs between them, so a switch state
    selective request with one unit's address is answered by that one alone
    (one 7E4 44); the serials are the same after a restart (derived from
    product, interface and factory node-ID), and --serial N gives N, N+1, ..."""
    proc = start_jds(tmp_path, bus)
    try:
        ids = identities(network)
        serials = [ids[i][3] for _, i in JDS]
        assert len(set(serials)) == 3 and 0 not in serials, serials
        vendor, product, revision, serial = ids[0x22]
        bus.clear()
        for cs, v in ((0x40, vendor), (0x41, product), (0x42, revision), (0x43, serial)):
            lss(network, cs, v.to_bytes(4, "little"))
        answers = bus.collect(0x7E4, 0.5)
        assert [bytes(m.data) for m in answers] == [b"\x44" + bytes(7)], answers
        lss(network, 0x5E)  # inquire node-ID: the selected one
        m = bus.wait_for(0x7E4, timeout=1)
        assert m is not None and m.data[0] == 0x5E and m.data[1] == 0x22
        lss(network, 0x04, b"\0")  # all back to waiting
    finally:
        stop(proc)
    for i in list(network):
        del network[i]
    proc = start_jds(tmp_path, bus)
    try:
        assert identities(network) == ids  # stable across restarts
    finally:
        stop(proc)
    for i in list(network):
        del network[i]
    proc = start_jds(tmp_path, bus, ["--serial", "0x5E000001"])
    try:
        got = identities(network)
        assert [got[i][3] for _, i in JDS] == [0x5E000001, 0x5E000002, 0x5E000003]
    finally:
        stop(proc)
    log = (tmp_path / "sensor.log").read_text()
    assert "factory node-ID 0x22, serial 0x5E000002" in log
