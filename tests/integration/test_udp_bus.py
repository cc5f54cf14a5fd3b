"""python-can's udp_multicast bus: canopen-sensor processes and the
`canopen` master share a bus with no CAN in the kernel and no User-Mode
Linux (canopen-sensor --iface udp_multicast:GROUP:PORT%lo). Run through
tools/netns-run: a private network namespace with the loopback alone, so
nothing sent here leaves the machine; outside one these tests fail at
once rather than send on the host's interfaces.

What SocketCAN gives and this bus must give too: every node of every
process heard by the master and by the other nodes, of its own process
and of others; a node does not hear itself; a datagram that is no classic
CAN frame python-can would accept is ignored, never answered."""
import socket
import time

import can
import canopen
import msgpack
import pytest
from canopen_sensor_sim import SimBus
from conftest import eds_od

GROUP = "239.74.163.2"  # python-can's IPv4 default group
PORT = 43113
IFACE = f"udp_multicast:{GROUP}:{PORT}%lo"


@pytest.fixture(autouse=True)
def private_namespace():
    names = [n for _, n in socket.if_nameindex()]
    if names != ["lo"]:
        pytest.fail(f"interfaces {names}: run these tests through tools/netns-run, "
                    "so that the bus stays on this machine")


@pytest.fixture
def master():
    net = canopen.Network()
    net.connect(interface="udp_multicast", channel=GROUP, port=PORT)
    yield net
    net.disconnect()


@pytest.fixture
def frames(master):
    """Every frame the master's bus reads from now on (a list of can.Message)."""
    got = []
    master.notifier.add_listener(got.append)
    return got


@pytest.fixture
def sim(tmp_path):
    """sim(nodes): one canopen-sensor process on the bus, stopped at the end."""
    buses = []

    def start(nodes):
        bus = SimBus(nodes, interface=IFACE, nvm_dir=tmp_path / f"nvm{len(buses)}")
        buses.append(bus)
        return bus.start()

    yield start
    for b in buses:
        b.close()


def wait_for(frames, pred, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        for m in list(frames):
            if pred(m):
                return m
        time.sleep(0.01)
    return None


def test_nodes_of_two_processes_answer_the_master(master, frames, sim, tmp_path):
    sim(["jd2xxx@0x21", "gsh-a@0x30"])
    sim(["dst-x730-xy30@0x7F"])
    for nid, product in ((0x21, "jd2xxx"), (0x30, "gsh-a"), (0x7F, "dst-x730-xy30")):
        od = eds_od(product, tmp_path, nid)
        node = master.add_node(nid, od)
        assert node.sdo[0x1000].raw == od[0x1000].default, product
        assert node.sdo[0x1018][1].raw == od[0x1018][1].default, product
    master.nmt.send_command(0x01)  # start every node
    for nid in (0x30, 0x7F):  # their TPDOs run on an event timer
        assert wait_for(frames, lambda m: 0x180 <= m.arbitration_id < 0x580
                        and m.arbitration_id & 0x7F == nid, 2.0), f"no TPDO of {nid:#x}"


@pytest.mark.parametrize("where", ["same process", "another process"])
def test_a_node_hears_the_other_nodes(master, frames, sim, where):
    """The JD2xxx consumes the GSH-A's heartbeat (1016h): no event while it
    comes every 50 ms, EMCY 8130h once it stops."""
    if where == "same process":
        sim(["jd2xxx@0x21", "gsh-a@0x30"])
    else:
        sim(["jd2xxx@0x21"])
        sim(["gsh-a@0x30"])
    jd = master.add_node(0x21, canopen.ObjectDictionary())
    gsh = master.add_node(0x30, canopen.ObjectDictionary())
    gsh.sdo.download(0x1017, 0, (50).to_bytes(2, "little"))
    jd.sdo.download(0x1016, 1, ((0x30 << 16) | 300).to_bytes(4, "little"))
    time.sleep(1.0)
    emcy = [m for m in frames if m.arbitration_id == 0x80 + 0x21]
    assert emcy == [], "the consumer missed heartbeats that came"
    gsh.sdo.download(0x1017, 0, (0).to_bytes(2, "little"))
    m = wait_for(frames, lambda m: m.arbitration_id == 0x80 + 0x21, 2.0)
    assert m is not None, "no EMCY after the heartbeat stopped"
    assert m.data[0:2] == bytes([0x30, 0x81]), m


def pack(**fields):
    """A datagram as python-can packs a can.Message, fields changed."""
    d = {"timestamp": 0.0, "arbitration_id": 0x630, "is_extended_id": False,
         "is_remote_frame": False, "is_error_frame": False, "channel": None, "dlc": 8,
         "data": bytes([0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]), "is_fd": False,
         "bitrate_switch": False, "error_state_indicator": False}
    d.update(fields)
    return msgpack.packb(d, use_bin_type=True)


class Listener:
    """The bus read without python-can, whose receiving thread ends at the
    first datagram it cannot unpack: a socket of the group, each datagram
    unpacked here, those that are no map left out."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        self.sock.bind((GROUP, PORT))
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                             socket.inet_aton(GROUP) + socket.inet_aton("127.0.0.1"))
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)

    def send(self, datagram):
        self.sock.sendto(datagram, (GROUP, PORT))

    def frames(self, seconds):
        """The maps read within seconds."""
        got = []
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            self.sock.settimeout(left)
            try:
                d = self.sock.recv(4096)
            except socket.timeout:
                break
            try:
                m = msgpack.unpackb(d, raw=False)
            except Exception:
                continue
            if isinstance(m, dict):
                got.append(m)
        return got

    def close(self):
        self.sock.close()


def test_what_is_no_classic_frame_is_ignored(sim, tmp_path):
    """Each datagram asks the GSH-A (0x30) for 1000h in a form python-can
    refuses or that is no classic CAN frame: none is answered; the plain
    request then is, and so is one naming a channel."""
    lis = Listener()
    try:
        sim(["gsh-a@0x30"])
        good = pack()
        bad = [
            pack(is_fd=True, dlc=8),
            pack(is_extended_id=True),
            pack(is_error_frame=True),
            pack(dlc=4),                                 # the DLC and the data differ
            pack(data="@\x00\x10\x00\x00\x00\x00\x00"),  # text, not bytes
            pack(is_remote_frame=True),                  # a remote frame with data
            pack(arbitration_id=0x630 | 0x800),          # no 11-bit identifier
            pack(nonsense=1),                            # python-can's Message() takes no such key
            pack(dlc=9, data=bytes(9)),
            good[:-1],                                   # cut short
            good + b"\x00",                              # something after the map
            msgpack.packb([0x630, 8, bytes(8)]),
            b"\xc1" * 40,                                # no MessagePack at all
            b"\x91" * 900,                               # nested deeper than any frame
            bytes(2000),                                 # longer than any frame
        ]
        lis.frames(0.3)  # the boot-up
        for d in bad:
            lis.send(d)
        answers = [m for m in lis.frames(0.5) if m.get("arbitration_id") == 0x5B0]
        assert answers == [], answers
        lis.send(pack(channel="vcan0"))
        answers = [m for m in lis.frames(0.5) if m.get("arbitration_id") == 0x5B0]
        device_type = eds_od("gsh-a", tmp_path, 0x30)[0x1000].default
        assert len(answers) == 1, answers
        assert answers[0]["data"] == bytes([0x43, 0x00, 0x10, 0x00]) + device_type.to_bytes(4, "little")
    finally:
        lis.close()


def test_a_remote_frame(master, frames, sim):
    """Node guarding's remote frame (DLC 1, as some masters send it) is
    answered with the node's state and toggle bit by the INX360D (guarding
    is on once the heartbeat is off: CiA 301)."""
    sim(["inx360d@0x30"])
    inx = master.add_node(0x30, canopen.ObjectDictionary())
    inx.sdo.download(0x1017, 0, (0).to_bytes(2, "little"))
    master.nmt.send_command(0x80)  # pre-operational
    time.sleep(0.2)
    frames.clear()
    master.bus.send(can.Message(arbitration_id=0x730, is_extended_id=False,
                                is_remote_frame=True, dlc=1))
    m = wait_for(frames, lambda m: m.arbitration_id == 0x730 and not m.is_remote_frame
                 and len(m.data) == 1, 1.0)
    assert m is not None, "no guarding answer"
    assert m.data[0] & 0x7F == 0x7F  # pre-operational


def test_a_node_does_not_hear_itself(master, frames, sim):
    """The JD2xxx set to consume its own heartbeat: as on SocketCAN, which
    never loops a frame back to the socket that sent it, the node does not
    receive its own frames (the program tells its datagrams apart by their
    sender), so the consumer never starts and its heartbeat's end is no
    event. A node that heard itself would send EMCY 8130h."""
    sim(["jd2xxx@0x21", "gsh-a@0x30"])
    jd = master.add_node(0x21, canopen.ObjectDictionary())
    jd.sdo.download(0x1017, 0, (50).to_bytes(2, "little"))
    jd.sdo.download(0x1016, 1, ((0x21 << 16) | 300).to_bytes(4, "little"))
    assert wait_for(frames, lambda m: m.arbitration_id == 0x700 + 0x21, 1.0), "no heartbeat"
    time.sleep(0.3)
    jd.sdo.download(0x1017, 0, (0).to_bytes(2, "little"))
    time.sleep(1.0)
    emcy = [m for m in frames if m.arbitration_id == 0x80 + 0x21]
    assert emcy == [], "the node heard its own heartbeat"


def heartbeats(frames, nid, since):
    return [m for m in frames if m.arbitration_id == 0x700 + nid and m.timestamp >= since
            and not m.is_remote_frame]


def test_unplug_as_the_master_sees_it(master, frames, sim):
    """`unplug SECONDS` on one node: its heartbeats stop and its SDO goes
    unanswered (a timeout, no abort; a write sent meanwhile never arrives),
    no bus-off and no boot-up after; the
    other node of the process goes on throughout; `unplug` until `unplug
    off` the same."""
    bus = sim(["gsh-a@0x30", "inx360d@0x31"])
    nodes = {n: master.add_node(n, canopen.ObjectDictionary()) for n in (0x30, 0x31)}
    for n in nodes.values():
        n.sdo.download(0x1017, 0, (50).to_bytes(2, "little"))
        n.sdo.RESPONSE_TIMEOUT = 0.3
    for form, undo in (("unplug 1.5", None), ("unplug", "unplug off")):
        time.sleep(0.2)
        bus.command(form, 0x30)
        t0 = time.time()
        time.sleep(0.1)  # what was on its way
        with pytest.raises(canopen.SdoCommunicationError):
            nodes[0x30].sdo.upload(0x1000, 0)
        with pytest.raises(canopen.SdoCommunicationError):  # never heard: the heartbeat stays
            nodes[0x30].sdo.download(0x1017, 0, (0).to_bytes(2, "little"))
        time.sleep(0.6)
        t1 = time.time()
        assert heartbeats(frames, 0x30, t0 + 0.1) == []
        assert len(heartbeats(frames, 0x31, t0)) >= 2  # the other node: untouched
        assert "unplug=on" in bus.command("get", 0x30)
        if undo:
            bus.command(undo, 0x30)
        else:
            time.sleep(max(0.0, t0 + 1.6 - time.time()))
        assert wait_for(frames, lambda m: m.arbitration_id == 0x730 and m.timestamp > t1
                        and m.data[:1] != b"\0", 2.0), "no heartbeat after the cable is back"
        assert nodes[0x30].sdo.upload(0x1000, 0)
        assert [m for m in frames if m.arbitration_id == 0x730 and m.data[:1] == b"\0"
                and m.timestamp > t0] == []  # no boot-up: the node ran on
        assert [m for m in frames if m.arbitration_id == 0x80 + 0x30 and m.timestamp > t0] == []


def test_heartbeat_stop_and_start(master, frames, sim):
    """`heartbeat stop`: the node's heartbeats end while its SDO answers;
    the other node's go on; `heartbeat start`: back."""
    bus = sim(["gsh-a@0x30", "inx360d@0x31"])
    nodes = {n: master.add_node(n, canopen.ObjectDictionary()) for n in (0x30, 0x31)}
    for n in nodes.values():
        n.sdo.download(0x1017, 0, (50).to_bytes(2, "little"))
    bus.heartbeat(0x30, False)
    t0 = time.time()
    time.sleep(0.6)
    assert nodes[0x30].sdo.upload(0x1000, 0)
    assert heartbeats(frames, 0x30, t0 + 0.1) == []
    assert len(heartbeats(frames, 0x31, t0)) >= 2
    assert "heartbeat=stopped" in bus.command("get", 0x30)
    bus.heartbeat(0x30, True)
    t1 = time.time()
    assert wait_for(frames, lambda m: m.arbitration_id == 0x730 and m.timestamp > t1, 1.0)
    assert "heartbeat" not in bus.command("get", 0x30)
