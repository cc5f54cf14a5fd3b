#!/usr/bin/env python3
"""tools/busbench.py [--nodes N] [--seconds S] [--product ID] [--check]:
many simulated nodes in one canopen-sensor process, measured on vcan.

Starts N nodes (default 127, node-IDs 1..N) of one product in one process
(the simulated sensor bus: tools/python/canopen_sensor_sim), gives each a
10 ms TPDO event timer and a 100 ms heartbeat over SDO, starts them all
(NMT), then for S seconds (default 10) counts every node's TPDOs and
heartbeats on the bus and the process's CPU time (/proc/PID/stat: user +
system). Prints CPU per node and in all (percent of one core), frames lost
(TPDOs and heartbeats short of S / period) and the worst heartbeat mean
period error. --check fails (exit 1) beyond issue 13's target: at most 10 %
of one core for all the nodes, no frame lost, heartbeats within 1 % of
their period. Needs vcan0 (run through tools/vcan-run).
"""
import argparse
import os
import pathlib
import struct
import sys
import time

import can

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent / "python"))
from canopen_sensor_sim import SimBus  # noqa: E402

TPDO_MS = 10
HB_MS = 100


def cpu_seconds(pid):
    fields = pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    ticks = os.sysconf("SC_CLK_TCK")
    return (int(fields[11]) + int(fields[12])) / ticks  # utime, stime


def sdo_write(bus, node, index, sub, value, size):
    cmd = {1: 0x2F, 2: 0x2B, 4: 0x23}[size]
    data = bytes([cmd]) + struct.pack("<HB", index, sub) + value.to_bytes(4, "little")
    bus.send(can.Message(arbitration_id=0x600 + node, data=data, is_extended_id=False))
    deadline = time.monotonic() + 2.0
    while time.monotonic() < deadline:
        m = bus.recv(0.5)
        if m is not None and m.arbitration_id == 0x580 + node and m.data[1:4] == data[1:4]:
            if m.data[0] != 0x60:
                raise SystemExit(f"node {node}: SDO write {index:04X}sub{sub} aborted: {m.data.hex()}")
            return
    raise SystemExit(f"node {node}: no SDO answer to {index:04X}sub{sub}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--nodes", type=int, default=127)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--product", default="dst-x730-xy30")
    ap.add_argument("--iface", default="vcan0")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    if not 1 <= a.nodes <= 127:
        ap.error("--nodes: 1..127")
    nodes = [f"{a.product}@{i}" for i in range(1, a.nodes + 1)]
    with SimBus(nodes, interface=a.iface) as sim, \
            can.Bus(interface="socketcan", channel=a.iface, receive_own_messages=False) as bus:
        time.sleep(0.5)
        for n in range(1, a.nodes + 1):
            sdo_write(bus, n, 0x1800, 5, TPDO_MS, 2)   # event timer
            sdo_write(bus, n, 0x1017, 0, HB_MS, 2)     # producer heartbeat
        bus.send(can.Message(arbitration_id=0, data=[1, 0], is_extended_id=False))
        time.sleep(1.0)  # settle: every timer running
        while bus.recv(0) is not None:
            pass
        tpdo = {n: 0 for n in range(1, a.nodes + 1)}
        hb = {n: [] for n in range(1, a.nodes + 1)}
        cpu0, t0 = cpu_seconds(sim.proc.pid), time.monotonic()
        end = t0 + a.seconds
        while True:
            now = time.monotonic()
            if now >= end:
                break
            m = bus.recv(end - now)
            if m is None:
                continue
            cid = m.arbitration_id
            if 0x181 <= cid <= 0x1FF and cid - 0x180 in tpdo:
                tpdo[cid - 0x180] += 1
            elif 0x701 <= cid <= 0x77F and cid - 0x700 in hb:
                hb[cid - 0x700].append(m.timestamp)
        cpu = cpu_seconds(sim.proc.pid) - cpu0
        wall = time.monotonic() - t0
    want_tpdo = int(a.seconds * 1000 / TPDO_MS)
    want_hb = int(a.seconds * 1000 / HB_MS)
    lost_tpdo = sum(max(0, want_tpdo - 1 - c) for c in tpdo.values())
    lost_hb = sum(max(0, want_hb - 1 - len(t)) for t in hb.values())
    worst = 0.0
    for t in hb.values():
        if len(t) >= 2:
            mean = (t[-1] - t[0]) / (len(t) - 1) * 1000
            worst = max(worst, abs(mean - HB_MS) / HB_MS * 100)
    share = cpu / wall * 100
    print(f"busbench: {a.nodes} x {a.product} in one process, TPDO every {TPDO_MS} ms, "
          f"heartbeat every {HB_MS} ms, {wall:.1f} s on {a.iface}")
    print(f"  CPU: {share:.2f} % of one core in all, {share / a.nodes * 1000:.1f} per mille "
          f"of a core per node")
    print(f"  TPDOs: {sum(tpdo.values())} received, {lost_tpdo} lost (each node >= {want_tpdo - 1})")
    print(f"  heartbeats: {sum(len(t) for t in hb.values())} received, {lost_hb} lost; "
          f"worst mean period {worst:.2f} % off")
    ok = share <= 10.0 and lost_tpdo == 0 and lost_hb == 0 and worst <= 1.0
    if a.check and not ok:
        print("busbench: FAILED issue 13's target (<= 10 % of one core, no frame lost, "
              "heartbeats within 1 %)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
