"""The demo session (run by tools/demo inside vcan): a canopen master talks
to a simulated sensor of any product ID and prints what it sees, decoded.

    demo.py PRODUCT [--iface IFACE] [--step SECONDS]

The node-IDs are the ones the sensor's boot-up messages come from (the
GSH-A redundant runs two nodes); the dictionary is the product's EDS
(canopen-sensor --eds), so only objects the product has are read. What is
done with each product family, and how its TPDO1 is decoded, is the
FAMILIES table below; a family it does not name (one tools/new-family just
made) gets a session made from what `canopen-sensor --list-products --json`
says of the product (generic_family): its inputs stepped, its first fault
raised and cleared, TPDO1 read as CiA 410 slopes.
"""
import argparse
import json
import os
import queue
import subprocess
import tempfile
import time

import can
import canopen

BINARY = os.environ.get("CANOPEN_SENSOR", "build/bin/canopen-sensor")
T0 = time.monotonic()


def say(cob, data, text):
    hexdata = " ".join(f"{b:02X}" for b in data[:8])
    if len(data) > 8:  # a segmented SDO upload: the first 7 bytes and a mark
        hexdata = hexdata[:20] + " .."
    print(f"[{time.monotonic() - T0:5.2f}] {cob:>4}  {hexdata:<23}  {text}", flush=True)


def s16(lo, hi):
    v = lo | hi << 8
    return v - 0x10000 if v & 0x8000 else v


def u16(lo, hi):
    return lo | hi << 8


def u16le(v):
    return v.to_bytes(2, "little")


# ---- decoding of each family's TPDO1 and EMCY -----------------------------
# deg: degrees per count of the slope objects, as read from the node's
# resolution object (0.001 deg x its value) when the session starts.

def tpdo_xy(d, deg):
    """CiA 410 slope longitudinal (X) and lateral (Y), INTEGER16."""
    return f"X={s16(d[0], d[1]) * deg:+7.2f} deg  Y={s16(d[2], d[3]) * deg:+7.2f} deg"


def tpdo_z(d, deg):
    """One signed slope: the DST Z-360 (-180..+180 deg)."""
    return f"Z={s16(d[0], d[1]) * deg:+7.2f} deg"


def tpdo_z_turn(d, deg):
    """One full-turn angle, UNSIGNED16 (ifm JD1xxx: 0..360 deg)."""
    return f"Z={u16(d[0], d[1]) * deg:7.2f} deg"


def tpdo_x_turn(d, deg):
    """P+F INX360D: X, 0..359.9 deg."""
    return f"X={s16(d[0], d[1]) * deg:6.1f} deg"


def tpdo_xy_turn(d, deg):
    """P+F INY360D: X and Y, 0..359.9 deg each."""
    return f"X={s16(d[0], d[1]) * deg:6.1f} deg  Y={s16(d[2], d[3]) * deg:6.1f} deg"


GSH_ALARMS = {0x0002: "under-extension", 0x0004: "over-extension", 0x0010: "field high",
              0x0020: "field low", 0x0200: "extension element", 0x0400: "tilt element"}


def tpdo_gsh(d, deg):
    """GSH-A fixed 8 bytes: position (mm, 0x6005 = 1 mm), angle (0x6810,
    0..359.9 deg), alarm word, counter, checksum (gsh_pdo_checksum)."""
    alarms = u16(d[4], d[5])
    names = ", ".join(n for bit, n in GSH_ALARMS.items() if alarms & bit) or "no alarm"
    chk = "ok" if d[7] == (sum(d[:7]) + 254) % 255 else "BAD"
    return (f"length={u16(d[0], d[1]):5d} mm  angle={u16(d[2], d[3]) * deg:5.1f} deg  "
            f"{names}  #{d[6]:03d} checksum {chk}")


def emcy_dst(code, d):
    return f"EMCY {code:04X}h, 0x4001 = {d[4]:#04x}"  # the DST's error code object


def emcy_cia(code, d):
    return f"EMCY {code:04X}h, error register {d[2]:02X}h"


class Family:
    """What the demo does with one product family.
    prefixes: product IDs it covers; res: the resolution object (slopes in
    its value x 0.001 deg); setup: SDO downloads (index, sub, data, text);
    steps: simulator commands, one per step; tpdo, emcy: decoders."""

    def __init__(self, prefixes, res, setup, steps, tpdo, emcy=emcy_cia):
        self.prefixes, self.res, self.setup = prefixes, res, setup
        self.steps, self.tpdo, self.emcy = steps, tpdo, emcy


DST_SETUP = [(0x6000, 0, u16le(10), "6000h/0  resolution := 10 (0.01 deg)"),
             (0x2001, 0, b"\x02", "2001h/0  filter := fast"),
             (0x1010, 1, b"save", "1010h/1  save (the filter applies after a save)")]
FAMILIES = [
    # Danfoss DST X730/X710 dual axis: the +-30 variant stops at 33 deg.
    Family(("dst-x730-xy", "dst-x710-xy"), 0x6000, DST_SETUP,
           ["set x=0 y=0", "set x=12.5 y=-3", "set x=-20 y=7.25", "set x=40 y=0", "set x=5 y=5"],
           tpdo_xy, emcy_dst),
    # DST Z-360: a full turn, shown -180..+180; the sensor fault raises EMCY.
    Family(("dst-x730-z360", "dst-x710-z360"), 0x6000, DST_SETUP,
           ["set z=0", "set z=90", "set z=-135.5", "fault sensor on", "fault sensor off",
            "set z=179.25"],
           tpdo_z, emcy_dst),
    # Gefran GSH-A: operational by itself (0x5000), fixed PDO; alarms in it.
    Family(("gsh-a",), 0x6800, [],
           ["set length=0 angle=0", "set length=1234 angle=12.5", "set length=8200 angle=90",
            "set length=2500 field=40", "fault tilt-element on",
            "fault tilt-element off", "set length=500 angle=359.9 field=100"],
           tpdo_gsh),
    # ifm JD1xxx: one axis 0..360 deg, UNSIGNED16; synchronous PDO.
    Family(("jd1",), 0x6000, [(0x6000, 0, u16le(10), "6000h/0  resolution := 10 (0.01 deg)")],
           ["set z=0", "set z=12.5", "set z=90", "set z=270.25", "set z=359.9"],
           tpdo_z_turn),
    # ifm JD2xxx: X/Y +-90 deg; synchronous PDO.
    Family(("jd2",), 0x6000, [(0x6000, 0, u16le(10), "6000h/0  resolution := 10 (0.01 deg)")],
           ["set x=0 y=0", "set x=12.5 y=-3", "set x=-20 y=7.25", "set x=45 y=-60"],
           tpdo_xy),
    # Pepperl+Fuchs INX360D: one full-turn axis in 0.1 deg (fixed); synchronous.
    Family(("inx",), 0x6000, [],
           ["set x=0", "set x=12.5", "set x=-20", "fault range-x on", "fault range-x off",
            "set x=180"],
           tpdo_x_turn),
    # P+F INY360D: two full-turn axes.
    Family(("iny",), 0x6000, [],
           ["set x=0 y=0", "set x=12.5 y=-3", "set x=-20 y=7.25", "fault range-y on",
            "fault range-y off"],
           tpdo_xy_turn),
]


def generic_family(p):
    """A session for product p (its --list-products --json entry) of a
    family FAMILIES does not name: each input set to 0, 12.5, -20 and 45
    (within its limit), its first fault raised and cleared; TPDO1 read as
    one INTEGER16 slope a degree input (CiA 410, 6000h the resolution)."""
    inputs = p["inputs"]
    steps = ["set " + " ".join(f"{i['name']}={max(-i['limit'], min(i['limit'], v)):g}"
                               for i in inputs)
             for v in (0, 12.5, -20, 45)]
    if p["faults"]:
        steps[2:2] = [f"fault {p['faults'][0]} on", f"fault {p['faults'][0]} off"]
    angles = [i["name"] for i in inputs if i["unit"] == "deg"]

    def tpdo(d, deg):
        return "  ".join(f"{name}={s16(d[2 * k], d[2 * k + 1]) * deg:+7.2f} deg"
                         for k, name in enumerate(angles[:len(d) // 2]))
    return Family((p["id"],), 0x6000, [], steps, tpdo)


def listed_products():
    """The sensor's products, as `canopen-sensor --list-products --json` gives them."""
    out = subprocess.run([BINARY, "--list-products", "--json"], check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out)


def family_of(product, listed=None):
    """The FAMILIES entry of a product ID; for another product the sensor
    lists (listed: listed_products() unless given) its generic_family;
    None for an ID it does not list."""
    for f in FAMILIES:
        if product.startswith(f.prefixes):
            return f
    for p in listed_products() if listed is None else listed:
        if p["id"] == product:
            return generic_family(p)
    return None


class Tap(can.Listener):
    """Everything on the bus, decoded; each node's PDOs printed at most
    every pdo_every seconds."""

    def __init__(self, family, pdo_every=0.5):
        super().__init__()
        self.q = queue.Queue()
        self.family = family
        self.pdo_every = pdo_every
        self.nodes = {}      # node-ID: degrees per slope count
        self.last_pdo = {}   # node-ID: time of the last PDO printed

    def on_message_received(self, m):
        self.q.put(m)

    def boot_ups(self, seconds):
        """Node-IDs whose boot-up arrives within seconds (then 0.3 s for a second node)."""
        found, end = [], time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            try:
                m = self.q.get(timeout=left)
            except queue.Empty:
                break
            if 0x701 <= m.arbitration_id <= 0x77F and bytes(m.data) == b"\0":
                say(f"{m.arbitration_id:03X}", m.data, "boot-up")
                found.append(m.arbitration_id - 0x700)
                end = min(end, time.monotonic() + 0.3)
        return found

    def drain(self):
        while not self.q.empty():
            m = self.q.get_nowait()
            cid, d = m.arbitration_id, bytes(m.data)
            node = cid & 0x7F
            if node not in self.nodes:
                continue
            kind = cid & 0x780
            if kind == 0x700:
                names = {0: "boot-up", 4: "heartbeat: stopped", 5: "heartbeat: operational",
                         0x7F: "heartbeat: pre-operational"}
                say(f"{cid:03X}", d, names.get(d[0], "heartbeat"))
            elif kind == 0x180 and m.timestamp - self.last_pdo.get(node, 0.0) >= self.pdo_every:
                self.last_pdo[node] = m.timestamp
                try:
                    text = self.family.tpdo(d, self.nodes[node])
                except IndexError:  # e.g. a mapping changed by hand: too few bytes
                    text = f"{len(d)} bytes, not the layout this demo decodes"
                say(f"{cid:03X}", d, "TPDO1  " + text)
            elif kind == 0x80 and len(d) == 8:
                code = d[0] | d[1] << 8
                say(f"{cid:03X}", d, "EMCY error reset" if code == 0 else self.family.emcy(code, d))


def session(args, family, net, tap, sensor):
    print(f"demo: {args.product} on {args.iface}, master = python canopen {canopen.__version__}")
    ids = tap.boot_ups(5)
    if not ids:
        raise SystemExit(f"demo: no boot-up from {args.product} within 5 s")
    eds = subprocess.run([BINARY, "--product", args.product, "--eds"], check=True,
                         capture_output=True, text=True).stdout
    eds_path = os.path.join(args.tmp, f"{args.product}.eds")
    with open(eds_path, "w") as f:
        f.write(eds)
    nodes = {}
    for nid in ids:
        nodes[nid] = net.add_node(nid, canopen.import_od(eds_path, nid))
    u32 = lambda b: f"0x{int.from_bytes(b, 'little'):08X}"
    text = lambda b: repr(b.decode())
    reads = [(0x1000, 0, "device type", u32), (0x1018, 1, "vendor-ID", u32),
             (0x1018, 2, "product code", u32), (0x1008, 0, "device name", text),
             (0x100A, 0, "software version", text)]
    for nid, node in nodes.items():
        if len(nodes) > 1:
            print(f"demo: node {nid:#04x}")
        for index, sub, name, fmt in reads:
            if index in node.object_dictionary:
                raw = node.sdo.upload(index, sub)
                say("SDO", raw, f"{index:04X}h/{sub}  {name}: {fmt(raw)}")
        for index, sub, data, what in family.setup:
            node.sdo.download(index, sub, data)
            say("SDO", data, what)
        raw = node.sdo.upload(family.res, 0)
        tap.nodes[nid] = int.from_bytes(raw, "little") * 0.001
        say("SDO", raw, f"{family.res:04X}h/0  resolution: {tap.nodes[nid]:g} deg")
        node.sdo.download(0x1017, 0, u16le(1000))
        say("SDO", u16le(1000), "1017h/0  heartbeat := 1000 ms")
        node.nmt.state = "OPERATIONAL"
        say("NMT", bytes([1, nid]), "start remote node")
    sync = [n.sdo.upload(0x1800, 2)[0] for n in nodes.values()]
    if any(t <= 240 for t in sync):  # synchronous PDOs: the master sends SYNC
        net.sync.start(0.1)
        say("SYNC", b"", "every 100 ms (the TPDO is synchronous)")
    while not tap.q.empty():  # shown from the first step on (the GSH-A sends from its boot)
        tap.q.get_nowait()
    for cmd in family.steps:
        sensor.stdin.write(cmd + "\n")
        sensor.stdin.flush()
        print(f"[{time.monotonic() - T0:5.2f}]  sim  {cmd}", flush=True)
        end = time.monotonic() + args.step
        while time.monotonic() < end:
            time.sleep(0.05)
            tap.drain()
    net.sync.stop()


def main():
    global T0
    ap = argparse.ArgumentParser(description="A CANopen master's session with a simulated sensor.")
    ap.add_argument("product", nargs="?", default="dst-x730-xy30")
    ap.add_argument("--iface", default="vcan0")
    ap.add_argument("--step", type=float, default=1.6, help="seconds per simulator step")
    args = ap.parse_args()
    listed = listed_products()
    known = [p["id"] for p in listed]
    family = family_of(args.product, listed)
    if args.product not in known or family is None:
        raise SystemExit(f"demo: no demo for product '{args.product}' (see "
                         f"canopen-sensor --list-products)")
    args.tmp = tempfile.mkdtemp(prefix="demo-")
    log = os.path.join(args.tmp, "sensor.log")
    net = canopen.Network()
    net.connect(interface="socketcan", channel=args.iface)
    tap = Tap(family)
    net.notifier.add_listener(tap)
    T0 = time.monotonic()
    sensor = subprocess.Popen([BINARY, "--product", args.product, "--iface", args.iface,
                               "--log", log], stdin=subprocess.PIPE, text=True)
    try:
        session(args, family, net, tap, sensor)
    except (canopen.SdoAbortedError, canopen.SdoCommunicationError) as e:
        raise SystemExit(f"demo: {e}")
    except KeyboardInterrupt:  # Ctrl-C (tools/vcan-run passes it on)
        print("demo: interrupted", flush=True)
        raise SystemExit(130)
    finally:
        sensor.stdin.close()
        sensor.terminate()
        sensor.wait(timeout=5)
        net.disconnect()
    print(f"demo: done (sensor log: {log})")


if __name__ == "__main__":
    main()
