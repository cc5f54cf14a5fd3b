"""The demo session (run by tools/demo inside vcan): a canopen master talks
to a simulated sensor and prints what it sees, decoded."""
import os
import queue
import subprocess
import sys
import tempfile
import time

import can
import canopen

PRODUCT = sys.argv[1] if len(sys.argv) > 1 else "dst-x730-xy30"
BINARY = os.environ.get("CANOPEN_SENSOR", "build/bin/canopen-sensor")
NODE = 0x7F
T0 = time.monotonic()


def say(cob, data, text):
    hexdata = " ".join(f"{b:02X}" for b in data)
    print(f"[{time.monotonic() - T0:5.2f}] {cob:>4}  {hexdata:<23}  {text}", flush=True)


def s16(lo, hi):
    v = lo | hi << 8
    return v - 0x10000 if v & 0x8000 else v


class Tap(can.Listener):
    """Everything the sensor sends, decoded; PDOs printed at most twice a second."""

    def __init__(self):
        super().__init__()
        self.q = queue.Queue()

    def on_message_received(self, m):
        self.q.put(m)

    def drain(self, res_deg, pdo_every=0.5):
        last_pdo = getattr(self, "last_pdo", 0.0)
        while not self.q.empty():
            m = self.q.get_nowait()
            cid, d = m.arbitration_id, bytes(m.data)
            if cid == 0x700 + NODE:
                names = {0: "boot-up", 4: "heartbeat: stopped", 5: "heartbeat: operational",
                         0x7F: "heartbeat: pre-operational"}
                say(f"{cid:03X}", d, names.get(d[0], "heartbeat"))
            elif cid == 0x180 + NODE and m.timestamp - last_pdo >= pdo_every:
                last_pdo = m.timestamp
                x, y = s16(d[0], d[1]) * res_deg, s16(d[2], d[3]) * res_deg
                say(f"{cid:03X}", d, f"TPDO1  X={x:+7.2f} deg  Y={y:+7.2f} deg")
            elif cid == 0x80 + NODE:
                code = d[0] | d[1] << 8
                text = "EMCY error reset" if code == 0 else f"EMCY {code:04X}h, 0x4001 = {d[4]:#04x}"
                say(f"{cid:03X}", d, text)
        self.last_pdo = last_pdo


def main():
    global T0
    log = tempfile.NamedTemporaryFile(prefix="sensor-", suffix=".log", delete=False).name
    net = canopen.Network()
    net.connect(interface="socketcan", channel="vcan0")
    tap = Tap()
    net.notifier.add_listener(tap)
    node = net.add_node(NODE, canopen.ObjectDictionary())
    T0 = time.monotonic()
    sensor = subprocess.Popen([BINARY, "--product", PRODUCT, "--iface", "vcan0", "--log", log],
                              stdin=subprocess.PIPE, text=True)
    try:
        print(f"demo: {PRODUCT} on vcan0, master = python canopen {canopen.__version__}")
        deadline = time.monotonic() + 3
        while tap.q.empty() and time.monotonic() < deadline:
            time.sleep(0.01)
        tap.drain(0.01)

        def read(index, sub, name, fmt):
            raw = node.sdo.upload(index, sub)
            say("SDO", raw, f"{index:04X}h/{sub}  {name}: {fmt(raw)}")
        u32 = lambda b: f"0x{int.from_bytes(b, 'little'):08X}"
        text = lambda b: repr(b.decode())
        read(0x1000, 0, "device type", u32)
        read(0x1018, 1, "vendor-ID", u32)
        read(0x1018, 2, "product code", u32)
        read(0x1008, 0, "device name", text)
        read(0x100A, 0, "software version", text)
        node.sdo.download(0x6000, 0, (10).to_bytes(2, "little"))
        say("SDO", b"\x0a\x00", "6000h/0  resolution := 10 (0.01 deg)")
        node.sdo.download(0x2001, 0, b"\x02")
        node.sdo.download(0x1010, 1, b"save")
        say("SDO", b"save", "2001h filter := fast, 1010h/1 save")
        node.sdo.download(0x1017, 0, (1000).to_bytes(2, "little"))
        node.nmt.state = "OPERATIONAL"
        say("NMT", b"\x01\x7f", "start remote node")
        for cmd in ("set x=0 y=0", "set x=12.5 y=-3", "set x=-20 y=7.25",
                    "set x=40 y=0", "set x=5 y=5"):
            sensor.stdin.write(cmd + "\n")
            sensor.stdin.flush()
            print(f"[{time.monotonic() - T0:5.2f}]  sim  {cmd}")
            end = time.monotonic() + 1.6
            while time.monotonic() < end:
                time.sleep(0.05)
                tap.drain(0.01)
    finally:
        sensor.stdin.close()
        sensor.terminate()
        sensor.wait(timeout=5)
        net.disconnect()
    print(f"demo: done (sensor log: {log})")


if __name__ == "__main__":
    main()
