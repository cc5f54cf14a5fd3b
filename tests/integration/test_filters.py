"""Kernel receive filters (CAN_RAW_FILTER, boards/linux/can_port.c): each
canopen-sensor socket takes only the CAN-IDs its node consumes, so that
ten separate processes on one bus at a 10 ms TPDO keep their timing, and
the filter follows a new SYNC COB-ID or node-ID at once."""
import os
import time

import can
import pytest

from conftest import Sensor

NODES = 10
TPDO_MS = 10
HB_MS = 100
TOLERANCE = 0.10  # every interval within +-10 % of its period
SECONDS = 3.0


def sdo_write(bus, node_id, index, sub, data, timeout=2.0):
    """Expedited download; returns the answer's first byte (0x60: done)."""
    cmd = 0x23 | ((4 - len(data)) << 2)
    payload = bytes([cmd, index & 0xFF, index >> 8, sub]) + bytes(data).ljust(4, b"\0")
    bus.send(can.Message(arbitration_id=0x600 + node_id, data=payload, is_extended_id=False))
    end = time.monotonic() + timeout
    while (left := end - time.monotonic()) > 0:
        m = bus.recv(left)
        if m is not None and m.arbitration_id == 0x580 + node_id:
            return m.data[0]
    return None


def wait_for(bus, can_id, timeout=3.0, data=None):
    end = time.monotonic() + timeout
    while (left := end - time.monotonic()) > 0:
        m = bus.recv(left)
        if m is not None and m.arbitration_id == can_id and not m.is_remote_frame and \
                (data is None or bytes(m.data) == data):
            return m
    return None


def utime_ticks(pid):
    with open(f"/proc/{pid}/stat") as f:
        return int(f.read().rsplit(")", 1)[1].split()[11])  # field 14: utime


@pytest.fixture
def raw():
    b = can.Bus(interface="socketcan", channel="vcan0")
    yield b
    b.shutdown()


def configure_gsh(raw, tmp_path, node_id):
    """A GSH-A (autostart, type 254) stored with node-ID node_id, a 10 ms
    event timer and a 100 ms heartbeat: set up alone at its factory
    node-ID 0x13, saved, stopped (the way of the GSH-A manual's section 13,
    example 1)."""
    d = tmp_path / f"n{node_id}"
    d.mkdir()
    s = Sensor("gsh-a", d)
    s.start()
    assert wait_for(raw, 0x713, data=b"\0"), "no boot-up at 0x13"
    assert sdo_write(raw, 0x13, 0x1800, 5, TPDO_MS.to_bytes(2, "little")) == 0x60
    assert sdo_write(raw, 0x13, 0x1017, 0, HB_MS.to_bytes(2, "little")) == 0x60
    assert sdo_write(raw, 0x13, 0x3001, 0, bytes([node_id])) == 0x60
    assert sdo_write(raw, 0x13, 0x1010, 1, b"save") == 0x60
    assert s.stop() == 0
    return s


def test_ten_processes_keep_their_timing(raw, tmp_path):
    ids = list(range(0x20, 0x20 + NODES))
    sensors = [configure_gsh(raw, tmp_path, i) for i in ids]
    try:
        for s in sensors:
            s.start()
        time.sleep(1.0)  # every node booted and sending
        assert all(s.alive() for s in sensors)
        u0 = utime_ticks(sensors[0].proc.pid)
        seen = {}
        # The window in the kernel's receive time stamps: the socket still
        # holds the frames of the set-up (the configuration runs, seconds
        # before), which once made a "silence" of 3 s at the window's start;
        # and a reader that lags reads the window's end after it.
        t_open = time.time()
        t_close = t_open + SECONDS
        ticks = None
        while True:
            m = raw.recv(0.5)
            if ticks is None and time.time() >= t_close:
                ticks = utime_ticks(sensors[0].proc.pid) - u0
            if m is None:
                if time.time() > t_close + 0.5:
                    break
                continue
            if m.timestamp < t_open or m.is_remote_frame:
                continue
            if m.timestamp > t_close:
                break
            seen.setdefault(m.arbitration_id, []).append(m.timestamp)
        if ticks is None:
            ticks = utime_ticks(sensors[0].proc.pid) - u0
        hz = os.sysconf("SC_CLK_TCK")
        print(f"\nnode 0x20 among {NODES}: user CPU {ticks / hz / SECONDS * 100:.2f} % "
              f"({ticks} ticks of 1/{hz} s in {SECONDS} s)")
        # Judged per node: its frame count over the window (nothing lost,
        # nothing late enough to fall out of it) and its median interval,
        # each within +-10 % of the period. Not every single interval: in
        # User-Mode Linux on a shared 2-core machine one node alone already
        # sees about 10 % of its 10 ms intervals outside +-1 ms (timer
        # slack, the vCPU descheduled), filter or not; measured without the
        # filters, ten processes lost 40-60 % of their TPDOs and half of
        # their heartbeat intervals were outside, which this check catches.
        # The count is judged against the span of the frames' receive time
        # stamps. A silence of the whole bus (no frame of any of the ten
        # nodes for three TPDO periods) is the virtual machine itself
        # stalled (User-Mode Linux on a loaded shared host: 0.7-1 s seen
        # in some runs), when no node can send: the measurement says
        # nothing about the nodes then, and the test is skipped, loudly.
        every = sorted(t for v in seen.values() for t in v)
        stalls = [(a, b) for a, b in zip(every, every[1:]) if b - a > 3 * TPDO_MS / 1000]
        if stalls:
            pytest.skip(f"TIMING NOT JUDGED: the whole bus was silent {len(stalls)} times, "
                        f"{sum(b - a for a, b in stalls) * 1000:.0f} ms in all (the machine "
                        "stalled, not a node); run on a less loaded machine")
        span = every[-1] - every[0]
        bad = []
        outside = {TPDO_MS: [0, 0], HB_MS: [0, 0]}  # intervals outside +-10 %, all intervals
        for i in ids:
            for cob, period_ms in ((0x180 + i, TPDO_MS), (0x700 + i, HB_MS)):
                ts = seen.get(cob, [])
                for a, b in zip(ts, ts[1:]):
                    outside[period_ms][0] += abs((b - a) * 1000 - period_ms) > period_ms * TOLERANCE
                    outside[period_ms][1] += 1
                want = span * 1000 / period_ms
                if abs(len(ts) - want) > want * TOLERANCE:
                    bad.append(f"{cob:03X}: {len(ts)} frames in {span:.2f} s, {want:.0f} expected")
                    continue
                gaps = sorted((b - a) * 1000 for a, b in zip(ts, ts[1:]))
                median = gaps[len(gaps) // 2]
                if abs(median - period_ms) > period_ms * TOLERANCE:
                    bad.append(f"{cob:03X}: median interval {median:.2f} ms, {period_ms} ms wanted")
        for period_ms, (n_out, n_all) in outside.items():
            print(f"{period_ms} ms: {n_out} of {n_all} intervals outside +-10 %")
        assert not bad, "\n".join(bad)
    finally:
        for s in sensors:
            s.stop()
    # Nothing the node needs was lost in its socket's queue either.
    for s in sensors:
        assert ", 0 dropped by the kernel" in s.log_text()


def test_filter_follows_sync_cobid_and_node_id(raw, tmp_path):
    """JD2xxx: SYNC moved to 0x081 drives the TPDO there (0x080 no more);
    a node-ID set by LSS is served at once after reset communication."""
    s = Sensor("jd2xxx", tmp_path)
    s.start()
    try:
        assert wait_for(raw, 0x70A, data=b"\0")
        assert sdo_write(raw, 0x0A, 0x1800, 2, b"\x01") == 0x60  # TPDO1 at every SYNC
        raw.send(can.Message(arbitration_id=0x000, data=b"\x01\x0A", is_extended_id=False))
        time.sleep(0.1)
        raw.send(can.Message(arbitration_id=0x080, data=b"", is_extended_id=False))
        assert wait_for(raw, 0x18A, timeout=1), "no TPDO at a SYNC on 0x080"
        assert sdo_write(raw, 0x0A, 0x1005, 0, (0x81).to_bytes(4, "little")) == 0x60
        raw.send(can.Message(arbitration_id=0x081, data=b"", is_extended_id=False))
        assert wait_for(raw, 0x18A, timeout=1), "no TPDO at a SYNC on the new COB-ID 0x081"
        raw.send(can.Message(arbitration_id=0x080, data=b"", is_extended_id=False))
        assert wait_for(raw, 0x18A, timeout=0.3) is None, "the old SYNC COB-ID still served"
        # LSS: switch global, configure node-ID 0x25, store, waiting; reset communication.
        for data in ("0401", "1125", "1700", "0400"):
            raw.send(can.Message(arbitration_id=0x7E5, data=bytes.fromhex(data).ljust(8, b"\0"),
                                 is_extended_id=False))
            time.sleep(0.05)
        raw.send(can.Message(arbitration_id=0x000, data=b"\x82\x0A", is_extended_id=False))
        assert wait_for(raw, 0x725, data=b"\0"), "no boot-up at the new node-ID 0x25"
        assert sdo_write(raw, 0x25, 0x1017, 0, (200).to_bytes(2, "little")) == 0x60
        assert sdo_write(raw, 0x0A, 0x1017, 0, (200).to_bytes(2, "little"), timeout=0.3) is None
    finally:
        assert s.stop() == 0
