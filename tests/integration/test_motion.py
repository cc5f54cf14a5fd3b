"""The simulator's motion end to end: a `ramp` sent through the control socket moves
the slope a DST X730 puts in its TPDO over time, at the ramp's rate; bad
motion lines are answered and change nothing; --seed is checked."""
import struct
import subprocess
import time

from conftest import BINARY, boot

NODE = 0x7F
COB_TPDO1 = 0x1FF


def slope(frame):
    """Slope longitudinal (0x6010, int16, the first mapped object)."""
    return struct.unpack_from("<h", bytes(frame.data), 0)[0]


def test_ramp_moves_the_tpdo_slope(sensor_factory, network, bus):
    sensor = sensor_factory("dst-x730-xy45")
    node = boot(sensor, network, bus, NODE)
    node.sdo.download(0x6000, 0, struct.pack("<H", 10))  # 0.01 deg
    node.nmt.state = "OPERATIONAL"
    time.sleep(3)  # the angle filter settles at 0
    # Malformed lines first: each refused with its cause, the input and the
    # slope stay where they are.
    for line, cause in [("ramp x=30 in 0s", "'0s': not a duration"),
                        ("ramp x=30 in 4", "'4': not a duration"),
                        ("sine x amp=5", "usage: sine x|y amp=A"),
                        ("ramp q=30 in 4s", "usage: ramp x|y=VALUE in DURATION")]:
        answer = sensor.command(line)
        assert answer.startswith("error: ") and cause in answer, (line, answer)
    bus.clear()
    still = bus.collect(COB_TPDO1, 1.0)
    assert len(still) >= 8 and all(slope(f) == 0 for f in still), [slope(f) for f in still]
    assert sensor.get()["x"] == 0.0
    # 0 -> 30 deg in 4 s: 750 (0.01 deg) a second, then held at 3000.
    sensor.send("ramp x=30 in 4s")
    frames = bus.collect(COB_TPDO1, 7.0)
    assert len(frames) >= 60
    pts = [(f.timestamp, slope(f)) for f in frames]
    values = [v for _, v in pts]
    assert values[-1] == 3000, values
    # It moves over time, never backwards (the filter only smooths it) ...
    assert all(b >= a for a, b in zip(values, values[1:])), values
    mid = [(t, v) for t, v in pts if 600 <= v <= 2400]
    assert len(mid) >= 15, values  # 24 deg at 7.5 deg/s: 2.4 s of 100 ms frames
    # ... at the ramp's rate: a straight line through the middle part.
    n = len(mid)
    mt = sum(t for t, _ in mid) / n
    mv = sum(v for _, v in mid) / n
    rate = sum((t - mt) * (v - mv) for t, v in mid) / sum((t - mt) ** 2 for t, _ in mid)
    print(f"ramp rate seen in the TPDO: {rate:.0f} (0.01 deg)/s over {len(mid)} frames")
    assert 650 <= rate <= 850, rate
    assert sensor.get()["x"] == 30.0  # the ramp's end, held
    assert sensor.stop() == 0


def test_seed_option():
    r = subprocess.run([BINARY, "--product", "dst-x730-xy45", "--iface", "vcan0",
                        "--seed", "banana"], capture_output=True, text=True, timeout=10)
    assert r.returncode == 2
    assert "--seed takes a number" in r.stderr
    r = subprocess.run([BINARY, "--help"], capture_output=True, text=True, timeout=10)
    for word in ("--seed N", "ramp NAME=VALUE in DUR", "sine NAME amp=A period=DUR",
                 "noise NAME sd=S", "replay FILE.csv"):
        assert word in r.stdout
