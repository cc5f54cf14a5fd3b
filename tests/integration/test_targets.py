"""One suite, four targets: the same master checks against the Linux
program on vcan, against the bare-metal images in qemu (rv32-virt,
microbit) over their SLCAN serial line, and against the rv32-virt image
on vcan through its SJA1000 (rv32-can).

    tools/vcan-run build/venv/bin/python -m pytest tests/integration/test_targets.py
    build/venv/bin/python -m pytest tests/integration/test_targets.py --target rv32-virt
    tools/vcan-run build/venv/bin/python -m pytest tests/integration/test_targets.py --target rv32-can
    ... --products all | --products gsh-a,jd1xxx

Every check runs once per product (--products, default the CI set of
facts.CI_PRODUCTS) on the one target (--target, default linux). What a
product is expected to do is in facts.py, one table, so the checks below
have no product names in them. A target that cannot do what a check
needs (no tools/emu yet, an image without the input language) fails the
check and says so: nothing here is skipped.
"""
import json
import re
import struct
import subprocess
import time
from dataclasses import dataclass, replace

import pytest
from canopen.lss import LssMaster
from canopen.sdo.exceptions import SdoAbortedError

from conftest import BINARY
from facts import CI_PRODUCTS, ID, PRODUCTS, SAVE, u16, u32
from targets import Master, list_products, make_target, period_fault

NMT_START, NMT_STOP, NMT_PREOP, NMT_RESET_NODE, NMT_RESET_COMM = 0x01, 0x02, 0x80, 0x81, 0x82
OPERATIONAL, STOPPED, PREOP = 0x05, 0x04, 0x7F
# Periods and the window they are counted in: short, so that a product's
# checks take about 10 s on a target (targets.period_fault says what the
# check forgives).
HB_MS, EVENT_MS, WINDOW_S = 50, 50, 1.0


def selected_products(config):
    """--products, then the K-th of N shares of them (--shard K/N)."""
    target = config.getoption("--target")
    want = config.getoption("--products")
    if want == "ci":
        ids = list(CI_PRODUCTS[target])
    elif want == "all":
        ids = list(PRODUCTS)
    else:
        ids = [p for p in want.split(",") if p]
        unknown = [p for p in ids if p not in PRODUCTS]
        if unknown:
            raise pytest.UsageError(f"--products: unknown product {', '.join(unknown)} "
                                    f"(known: {', '.join(PRODUCTS)})")
    shard = re.fullmatch(r"([1-9][0-9]*)/([1-9][0-9]*)", config.getoption("--shard"))
    if shard is None or int(shard[1]) > int(shard[2]):
        raise pytest.UsageError("--shard K/N: 1 <= K <= N")
    k, n = int(shard[1]), int(shard[2])
    if not ids[k - 1::n]:
        raise pytest.UsageError(f"--shard {k}/{n}: no product in it (of {len(ids)})")
    return ids[k - 1::n]


def pytest_generate_tests(metafunc):
    if "product" in metafunc.fixturenames:
        metafunc.parametrize("product", selected_products(metafunc.config))


@pytest.fixture
def facts(product):
    return PRODUCTS[product]


@pytest.fixture
def dut(request, product, tmp_path):
    """The master on the device: product on --target, not yet powered."""
    master = Master(make_target(request.config.getoption("--target"), product, tmp_path))
    yield master
    master.close()


# --- helpers: the master's SDO, NMT and heartbeat, in bytes ---------------

def up(dut, node_id, index, sub):
    return bytes(dut.node(node_id).sdo.upload(index, sub))


def down(dut, node_id, index, sub, data):
    dut.node(node_id).sdo.download(index, sub, bytes(data))


def expect(value, node_id):
    return struct.pack("<I", value.of(node_id)) if isinstance(value, ID) else value


def abort_code(fn):
    with pytest.raises(SdoAbortedError) as e:
        fn()
    return e.value.code


def nmt(dut, command, node_id):
    dut.send(0x000, bytes([command, node_id]))


def assert_period(got, period_ms, what):
    """(time, frame)s collected for WINDOW_S came every period_ms."""
    fault = period_fault([t for t, _ in got], period_ms, WINDOW_S)
    assert fault is None, f"{what}: {fault}"


def test_period_fault():
    """The period check itself, on made-up arrival times (no target): a
    late frame, two frames read together and a stall of 250 ms pass; a
    half or double period, a producer silent for half the window, a
    single frame and a flood fail."""
    def at(*gaps_ms):
        return [sum(gaps_ms[:k]) / 1000 for k in range(len(gaps_ms) + 1)]
    assert period_fault(at(*[50] * 19), 50, 1.0) is None
    assert period_fault(at(*[50] * 8, 80, 20, 50, 100, 50, 2, 48, *[50] * 5), 50, 1.0) is None
    assert period_fault(at(*[50] * 6, 300, *[50] * 8), 50, 1.0) is None  # 16 of 20
    assert period_fault(at(*[25] * 39), 50, 1.0) is not None
    assert period_fault(at(*[100] * 9), 50, 1.0) is not None
    assert period_fault(at(*[50] * 9), 50, 1.0) is not None  # stopped after 0.5 s
    assert period_fault(at(*[50] * 19, *[1] * 3), 50, 1.0) is not None
    assert period_fault([0.0], 50, 0.05) is not None
    assert period_fault([], 50, 1.0) is not None


def heartbeat_state(dut, node_id, timeout=1.0):
    """The state byte of the node's next heartbeat (None: none came)."""
    m = dut.frames.wait_for(0x700 + node_id, timeout=timeout, pred=lambda m: len(m.data) == 1)
    return None if m is None else m.data[0] & 0x7F


def wait_state(dut, node_id, state, timeout=1.0):
    """Heartbeats until one reports state; its state, or the last one seen."""
    seen = None
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        seen = heartbeat_state(dut, node_id, timeout=end - time.monotonic())
        if seen == state:
            break
    return seen


def boot_up(dut, node_id, timeout=5.0):
    return dut.frames.wait_for(0x700 + node_id, timeout=timeout,
                               pred=lambda m: bytes(m.data) == b"\0")


def sdo_answers(dut, node_id, timeout=1.0):
    """Whether node_id answers an SDO read of 0x1000 (raw, no retries)
    within timeout: long enough for an emulator the machine starves for a
    moment, and a silence that long is a real one."""
    dut.frames.clear()
    dut.send(0x600 + node_id, bytes.fromhex("4000100000000000"))
    return dut.frames.wait_for(0x580 + node_id, timeout=timeout) is not None


def write_set(dut, node_id, facts, values):
    for (index, sub, fmt), v in zip(facts.stored, values):
        down(dut, node_id, index, sub, struct.pack(fmt, v))


def read_set(dut, node_id, facts):
    return tuple(struct.unpack(fmt, up(dut, node_id, index, sub))[0]
                 for index, sub, fmt in facts.stored)


def expedited(index, sub, data):
    """A raw SDO expedited download request (CiA 301)."""
    cmd = 0x23 | ((4 - len(data)) << 2)
    return bytes([cmd, index & 0xFF, index >> 8, sub]) + bytes(data) + bytes(4 - len(data))


def assert_no_corrupt_set(dut, node_id, facts):
    """The product's own report of a corrupt stored set is absent."""
    c = facts.corrupt
    if c.sdo_bit is not None:
        index, sub, mask = c.sdo_bit
        assert up(dut, node_id, index, sub)[0] & mask == 0, "reports a corrupt stored set"
    if c.emcy_code is not None:
        bad = [m for m in dut.boot_frames if m.arbitration_id == 0x80 + node_id
               and int.from_bytes(m.data[0:2], "little") == c.emcy_code]
        late = dut.frames.wait_for(0x80 + node_id, timeout=0.2,
                                   pred=lambda m: int.from_bytes(m.data[0:2], "little")
                                   == c.emcy_code)
        assert not bad and late is None, f"EMCY {c.emcy_code:04X}h: corrupt stored set"


# --- the checks -------------------------------------------------------------

def test_boot_up(dut, facts):
    """Each node's first frame after power on is its boot-up (0x700 + ID, one
    byte 00), and nothing of it comes before. A new device (no EEPROM file,
    erased flash) runs on defaults and reports no corrupt stored set."""
    dut.power_on(facts.nodes)
    for n in facts.nodes:
        own = {0x80 + n, facts.tpdo_cob.of(n), 0x580 + n, 0x700 + n}
        first = next(m for m in dut.boot_frames if m.arbitration_id in own)
        assert first.arbitration_id == 0x700 + n and bytes(first.data) == b"\0", \
            f"node {n:#x}: first frame {first}"
        assert_no_corrupt_set(dut, n, facts)
        assert read_set(dut, n, facts) == facts.defaults


def test_identity(dut, facts):
    """0x1000, 0x1018 and 0x1008 through the canopen SDO client (0x1008
    segmented where it is longer than 4 bytes)."""
    dut.power_on(facts.nodes)
    for n in facts.nodes:
        assert up(dut, n, 0x1000, 0) == struct.pack("<I", facts.device_type)
        for sub, value in facts.identity.items():
            assert up(dut, n, 0x1018, sub) == struct.pack("<I", value), f"0x1018 sub {sub}"
        if facts.name is None:
            assert abort_code(lambda: up(dut, n, 0x1008, 0)) == 0x06020000
        else:
            assert up(dut, n, 0x1008, 0) == facts.name


def test_serial_number_per_unit(dut, facts):
    """0x1018 sub 4, the LSS address's last part (CiA 305), is the unit's
    own: not 0, each node of a device its own, the same after a restart."""
    dut.power_on(facts.nodes)
    serials = [struct.unpack("<I", up(dut, n, 0x1018, 4))[0] for n in facts.nodes]
    assert 0 not in serials and len(set(serials)) == len(serials), [hex(s) for s in serials]
    assert dut.power_off() == 0
    dut.power_on(facts.nodes)
    assert [struct.unpack("<I", up(dut, n, 0x1018, 4))[0] for n in facts.nodes] == serials


def test_sdo_reads_writes_aborts(dut, facts):
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    for r in facts.reads:
        assert up(dut, n, r.index, r.sub) == expect(r.value, n), f"{r.index:04X}h/{r.sub}"
    for index, sub, data in facts.rw:
        down(dut, n, index, sub, data)
        assert up(dut, n, index, sub) == data, f"{index:04X}h/{sub} read back"
    for a in facts.aborts:
        if a.op == "r":
            got = abort_code(lambda: up(dut, n, a.index, a.sub))
        else:
            got = abort_code(lambda: down(dut, n, a.index, a.sub, a.data))
        assert got == a.code, f"{a.op} {a.index:04X}h/{a.sub}: abort {got:08X}h, want {a.code:08X}h"
    for index, sub, data in facts.rw:  # refused writes changed nothing
        assert up(dut, n, index, sub) == data


def test_nmt_states(dut, facts):
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    index, sub, new, default = facts.app_param
    down(dut, n, 0x1017, 0, struct.pack("<H", HB_MS))
    assert heartbeat_state(dut, n) == facts.boot_state
    nmt(dut, NMT_PREOP, n)
    assert wait_state(dut, n, PREOP) == PREOP
    nmt(dut, NMT_START, n)
    assert wait_state(dut, n, OPERATIONAL) == OPERATIONAL
    nmt(dut, NMT_STOP, n)
    assert wait_state(dut, n, STOPPED) == STOPPED
    assert not sdo_answers(dut, n), "SDO answered in stopped"
    nmt(dut, NMT_PREOP, 0)  # broadcast
    assert wait_state(dut, n, PREOP) == PREOP
    down(dut, n, index, sub, new)
    # Reset communication: boot-up, 0x1000-0x1FFF from the stored set (the
    # heartbeat period with it), the application parameter kept.
    dut.frames.clear()
    nmt(dut, NMT_RESET_COMM, n)
    assert boot_up(dut, n) is not None, "no boot-up after reset communication"
    beat = heartbeat_state(dut, n, timeout=20 * HB_MS / 1000)
    assert (beat is not None) == facts.autosave, f"heartbeat after reset communication: {beat}"
    assert up(dut, n, index, sub) == new
    # Reset node: boot-up, every parameter from the stored set.
    dut.frames.clear()
    nmt(dut, NMT_RESET_NODE, n)
    assert boot_up(dut, n) is not None, "no boot-up after reset node"
    assert up(dut, n, index, sub) == (new if facts.autosave else default)
    for other in facts.nodes[1:]:  # the other node of the device went on
        assert sdo_answers(dut, other)


def test_heartbeat_period(dut, facts):
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    down(dut, n, 0x1017, 0, struct.pack("<H", HB_MS))
    heartbeat_state(dut, n)
    beats = dut.frames.collect(0x700 + n, WINDOW_S)
    assert_period(beats, HB_MS, "heartbeats")
    assert all(bytes(m.data) == bytes([facts.boot_state]) for _, m in beats)
    down(dut, n, 0x1017, 0, struct.pack("<H", 0))
    dut.frames.clear()
    assert heartbeat_state(dut, n, timeout=20 * HB_MS / 1000) is None, "heartbeat after 0x1017 = 0"


def test_tpdo_by_sync(dut, facts):
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    cob = facts.tpdo_cob.of(n)
    if facts.sync_type is None:
        # Event-driven only (its manual): 0x1800:2 refuses, and with the event
        # timer off no SYNC makes a PDO.
        assert abort_code(lambda: down(dut, n, 0x1800, 2, b"\x01")) == facts.sync_refused
        down(dut, n, 0x1800, 5, struct.pack("<H", 0))
        want = 0
    else:
        down(dut, n, 0x1800, 2, bytes([facts.sync_type]))
        want = 6 // facts.sync_type
    nmt(dut, NMT_START, n)
    time.sleep(0.1)
    dut.frames.clear()
    assert not dut.frames.collect(cob, 0.2), "TPDO without SYNC"
    for _ in range(6):
        dut.send(0x080)
        time.sleep(0.02)
    got = dut.frames.count(cob, want)
    assert len(got) == want, f"{len(got)} TPDOs for 6 SYNCs, want {want}"


def event_timer_tpdo(dut, facts, n):
    """Node n pre-operational, its TPDO1 sent by the event timer every
    EVENT_MS (the product's own steps to that mode first)."""
    nmt(dut, NMT_PREOP, n)
    for index, sub, data in facts.event_mode:
        down(dut, n, index, sub, data)
    down(dut, n, 0x1800, 5, struct.pack("<H", EVENT_MS))


def test_tpdo_by_event_timer(dut, facts):
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    cob = facts.tpdo_cob.of(n)
    event_timer_tpdo(dut, facts, n)
    dut.frames.clear()
    assert not dut.frames.collect(cob, 0.15), "TPDO in pre-operational"
    nmt(dut, NMT_START, n)
    dut.frames.wait_for(cob, timeout=2.0)
    assert_period(dut.frames.collect(cob, WINDOW_S), EVENT_MS, "TPDOs")


def test_tpdo_length_is_the_mapped_length(dut, facts):
    """CiA 301: a consumer checks a PDO's length against its mapping (EMCY
    8220h when they differ). TPDO1's mapping read over SDO: every entry is
    its object's length (the object's SDO upload has that many bytes), and
    every TPDO1 frame has as many bytes as the entries add up to."""
    dut.power_on(facts.nodes)
    for n in facts.nodes:
        count = up(dut, n, 0x1A00, 0)[0]
        total = 0
        for sub in range(1, count + 1):
            m = struct.unpack("<I", up(dut, n, 0x1A00, sub))[0]
            bits = m & 0xFF
            assert len(up(dut, n, m >> 16, (m >> 8) & 0xFF)) * 8 == bits, \
                f"node {n:#x}: 1A00h:{sub} = {m:08X}h is not its object's length"
            total += bits // 8
        cob = facts.tpdo_cob.of(n)
        event_timer_tpdo(dut, facts, n)
        dut.frames.clear()
        nmt(dut, NMT_START, n)
        got = dut.frames.collect_until(cob, 2.0, 3)
        assert got and all(len(m.data) == total for _, m in got), \
            f"node {n:#x}: TPDO1 lengths {sorted({len(m.data) for _, m in got})}, mapped {total}"


def test_emcy_on_injected_fault(dut, facts):
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    f = facts.fault
    nmt(dut, NMT_START, n)
    time.sleep(0.1)
    dut.frames.clear()
    for line in f.on:
        dut.target.inject(line)
    if f.emcy is not None:
        m = dut.frames.wait_for(0x80 + n, timeout=2)
        assert m is not None and bytes(m.data) == f.emcy, f"EMCY {m}"
    else:
        byte, mask = f.pdo_alarm
        m = dut.frames.wait_for(facts.tpdo_cob.of(n), timeout=2, pred=lambda m: m.data[byte] & mask)
        assert m is not None, "fault not in the PDO's alarm word"
        assert not dut.frames.collect(0x80 + n, 0.3), "EMCY from a product that has none"
    if f.emcy is not None:
        # The error register while the error is active: the EMCY's byte 2
        # (the register after the change, CiA 301); the DST's manual prints
        # 00 there and says 1001h is "Always ZERO", and its bytes win.
        assert up(dut, n, 0x1001, 0) == f.emcy[2:3]
    for line in f.off:
        dut.target.inject(line)
    if f.emcy_off is not None:
        m = dut.frames.wait_for(0x80 + n, timeout=2)
        assert m is not None and bytes(m.data) == f.emcy_off, f"error reset {m}"
    if f.pdo_alarm is not None:
        byte, mask = f.pdo_alarm
        m = dut.frames.wait_for(facts.tpdo_cob.of(n), timeout=2,
                                pred=lambda m: not m.data[byte] & mask)
        assert m is not None, "alarm not cleared"


# A product that stores its writes on its own (facts.autosave) does so once
# no SDO request came for a pause (CO_STORE_QUIET_US, 0.2 s, by the device's
# clock, co_store.h), not before the answer: a test that cuts the power
# after such a write waits this long first. The device's clock runs at least
# as fast as the test's; the rest is room for a loaded machine to run it.
STORE_QUIET_S = 0.2
STORE_PAUSE_S = STORE_QUIET_S + 0.8


def wait_stored(dut, facts):
    """Wait until the device stored its autosaved writes, then until what it
    stored would survive a power cut (Target.settle)."""
    if facts.autosave:
        time.sleep(STORE_PAUSE_S)
    dut.target.settle()


def test_save_restart_keeps_value(dut, facts):
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    write_set(dut, n, facts, facts.set_a)
    down(dut, n, 0x1010, 1, SAVE)
    write_set(dut, n, facts, facts.set_b)  # after the save: stored only where autosaved
    wait_stored(dut, facts)
    assert dut.power_off() == 0
    dut.power_on(facts.nodes)
    want = facts.set_b if facts.autosave else facts.set_a
    got = read_set(dut, n, facts)
    assert got == want, f"after the restart {got}, saved {want}"
    assert_no_corrupt_set(dut, n, facts)


CUTS = 6  # power cuts during saves, a product and target


def test_power_cut_during_save(dut, facts):
    """SIGKILL while a save is under way: the first cut right after the
    request, the next ones by bisection between it and the save's answer
    (a cut before the answer moves the next one later, one after it
    earlier), so that they close in on the end of the flash writes. After
    each, power on: the stored set is the old or the new one, whole, and
    not reported corrupt. (On the microbit tools/emu copies the EEPROM
    pages to the file every 100 ms, so there a cut acts at the last of those
    copies, which rarely falls inside the device's own save of about 1 ms.)"""
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    write_set(dut, n, facts, facts.set_a)
    dut.frames.clear()
    t0 = time.monotonic()
    dut.send(0x600 + n, expedited(0x1010, 1, SAVE))
    assert dut.frames.wait_for(0x580 + n, timeout=2, pred=lambda m: m.data[0] == 0x60)
    save_s = time.monotonic() - t0
    dut.target.settle()
    old, new = facts.set_a, facts.set_b
    landed, cuts = 0, []
    lo, hi, delay = 0.0, save_s, 0.0
    if facts.autosave:
        # The write is answered at once and stored after the pause: the cuts
        # close in on the store's end, judged by what power on finds.
        lo, hi, delay = 0.0, STORE_PAUSE_S + 2 * save_s, STORE_QUIET_S
    for _ in range(CUTS):
        if facts.autosave:
            # Each write stores itself: the cut hits the last write's store.
            before = (new[0],) + old[1:]
            write_set(dut, n, facts, before)
            wait_stored(dut, facts)
            index, sub, fmt = facts.stored[-1]
            request = expedited(index, sub, struct.pack(fmt, new[-1]))
        else:
            before = old
            write_set(dut, n, facts, new)
            request = expedited(0x1010, 1, SAVE)
        sent = dut.power_cut_after(0x600 + n, request, delay)
        answered = any(m.arbitration_id == 0x580 + n for m in sent)
        dut.power_on(facts.nodes)
        got = read_set(dut, n, facts)
        assert got in (before, new), f"cut {delay * 1000:.1f} ms after the request: " \
                                     f"stored {got}, want {before} or {new}"
        assert_no_corrupt_set(dut, n, facts)
        if facts.autosave:
            answered = got == new  # "a": after the store
        landed += not answered
        cuts.append(f"{delay * 1000:.1f}{'a' if answered else ''}")
        old, new = got, (old if got == new else new)
        lo, hi = (lo, delay) if answered else (delay, hi)
        delay = (lo + hi) / 2
    print(f"{dut.target.name} {facts.family}: save {save_s * 1000:.1f} ms; cuts at "
          f"{' '.join(cuts)} ms (a: after the {'store' if facts.autosave else 'answer'}); "
          f"{landed}/{CUTS} before it")
    assert landed >= 1, "every cut came after the save's answer: this proved nothing"


def test_node_id_change(dut, facts):
    """The product's own way (facts.node_id_change), then a power cycle:
    the new ID answers, the old one does not, the device's other node
    keeps its own."""
    change = facts.node_id_change
    dut.power_on(facts.nodes)
    old = facts.nodes[0]
    if change is None:  # no way to change it: the factory node-ID, power cycle or not
        assert dut.power_off() == 0
        dut.power_on(facts.nodes)
        assert all(sdo_answers(dut, n) for n in facts.nodes)
        return
    new_ids = (change.new_id,) + facts.nodes[1:]
    for i, step in enumerate(change.steps):
        last = i == len(change.steps) - 1
        kind = step[0]
        if kind == "sdo":
            down(dut, old, step[1], step[2], step[3])
        elif kind == "lss-node-id":
            lss = dut.network.lss
            lss.send_switch_state_global(LssMaster.CONFIGURATION_STATE)
            lss.configure_node_id(step[1])
            lss.store_configuration()
            lss.send_switch_state_global(LssMaster.WAITING_STATE)
        elif kind == "nmt":
            dut.frames.clear()
            nmt(dut, step[1], old)
            want = change.new_id if last else old
            assert boot_up(dut, want) is not None, f"no boot-up of {want:#x} after NMT {step[1]:#x}"
        elif kind == "power-cycle":
            assert dut.power_off() == 0
            dut.power_on(new_ids if last else facts.nodes)
        else:
            raise AssertionError(f"unknown step {step}")
    assert sdo_answers(dut, change.new_id)
    assert not sdo_answers(dut, old), f"old node-ID {old:#x} still answers"
    assert up(dut, change.new_id, 0x1000, 0) == struct.pack("<I", facts.device_type)
    assert dut.power_off() == 0
    dut.power_on(new_ids)  # stored
    for other in facts.nodes[1:]:
        assert sdo_answers(dut, other)


def test_facts_cover_every_product():
    """facts.PRODUCTS has every product the Linux program and the MCU images
    know, and no other (so a new product cannot miss this suite): the
    program's list (--list-products --json, from the families'
    declarations) says which have an image and of which family each is."""
    assert set(list_products()) == set(PRODUCTS)
    listed = json.loads(subprocess.run([BINARY, "--list-products", "--json"], check=True,
                                       capture_output=True, text=True).stdout)
    mcu = [p["id"] for p in listed if p["mcu_image"]]
    families = {}
    for p in listed:
        if p["mcu_image"]:
            families.setdefault(p["family"], set()).add(p["id"])
    assert len(mcu) == len(set(mcu))
    assert set(mcu) == set(PRODUCTS)
    # Every family runs on every target in CI (a new one cannot be left out).
    for target, ids in CI_PRODUCTS.items():
        for family, members in families.items():
            assert members & set(ids), f"no {family} product in CI_PRODUCTS[{target!r}]"
    for target, ids in CI_PRODUCTS.items():
        assert set(ids) <= set(PRODUCTS), target


# --- conformance: the CiA conformance test plan's cases ----------------------
#
# What a product's dictionary holds is read from its EDS (canopen-sensor
# --eds, the same tables the MCU images are built from), so that every
# object of every product is covered without a list here.

EDS_SIZES = {0x0001: 1, 0x0002: 1, 0x0003: 2, 0x0004: 4, 0x0005: 1, 0x0006: 2, 0x0007: 4}


@dataclass(frozen=True)
class EdsEntry:
    index: int
    sub: int
    access: str
    data_type: int
    default: str      # the DefaultValue as written, None where the EDS gives none
    comment: str      # the comment line before it ("" where none)


def eds_entries(product):
    """(index, sub) -> EdsEntry of the product's EDS, in the EDS's order."""
    text = subprocess.run([BINARY, "--product", product, "--eds"], check=True,
                          capture_output=True, text=True).stdout
    entries = {}
    for block in text.split("\n\n"):
        lines = block.strip().splitlines()
        head = re.fullmatch(r"\[([0-9A-F]{4})(?:sub([0-9A-F]+))?\]", lines[0]) if lines else None
        if head is None:
            continue
        keys = dict(l.split("=", 1) for l in lines[1:] if "=" in l and not l.startswith(";"))
        if keys.get("ObjectType") != "0x7":
            continue
        comment = next((l for l in lines if l.startswith(";")), "")
        index, sub = int(head[1], 16), int(head[2] or "0", 16)
        entries[(index, sub)] = EdsEntry(index, sub, keys["AccessType"], int(keys["DataType"], 16),
                                         keys.get("DefaultValue"), comment)
    assert entries, f"no object in the EDS of {product}"
    return entries


def eds_value(e, node_id):
    """The EDS DefaultValue of e as the bytes the device answers (node-ID resolved)."""
    text = e.default
    m = re.fullmatch(r"\$NODEID\+(0x[0-9A-Fa-f]+|[0-9]+)", text)
    if e.data_type == 0x0009:
        return text.encode()
    v = node_id + int(m[1], 0) if m else int(text, 0)
    return (v & (1 << (8 * EDS_SIZES[e.data_type])) - 1).to_bytes(EDS_SIZES[e.data_type], "little")


def abort_or_none(fn):
    """The abort code fn ends with, or None where it succeeds."""
    try:
        fn()
    except SdoAbortedError as e:
        return e.code
    return None


def test_blank_device_reads_its_eds_defaults(dut, facts, product):
    """A blank device (no stored set) reads the DefaultValue its EDS gives for
    every readable object, on every node: a live value (an input, an error
    state) has none; where the manual asks the EDS for another value (a
    comment line says so) the device reads its own, which the comment
    names; a node-relative one is $NODEID. 0x1018 sub 4, the serial number,
    is each unit's own: no comparison."""
    eds = eds_entries(product)
    dut.power_on(facts.nodes)
    for n in facts.nodes:
        wrong = []
        for (index, sub), e in eds.items():
            if e.access == "wo" or e.default is None or (index, sub) == (0x1018, 4):
                continue
            want = eds_value(e, n)
            own = re.match(r"; the device's default is (0x[0-9A-F]+|-?[0-9]+);", e.comment)
            if own:
                want = eds_value(replace(e, default=own[1]), n)
            got = up(dut, n, index, sub)
            if got != want:
                wrong.append(f"{index:04X}h/{sub}: reads {got.hex()}, EDS {e.default}")
        assert not wrong, f"node {n:#x}: " + "; ".join(wrong)


def test_segmented_download_as_expedited(dut, facts, product):
    """Every object the product can write takes the same bytes by segmented
    and by block download as by expedited: the same answer (success, or
    the same abort code) and the same value read back. The bytes are the
    object's own value as read (zeros where it is write-only), so nothing
    changes underway. The DSTs have no block transfer (docs/decisions.md): there it
    is refused with 05040001h, and changes nothing."""
    eds = eds_entries(product)
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    sdo = dut.node(n).sdo
    checked = 0
    for (index, sub), e in eds.items():
        if "w" not in e.access:
            continue
        readable = e.access != "wo"
        data = up(dut, n, index, sub) if readable else bytes(EDS_SIZES.get(e.data_type, 4))
        def block():
            with sdo.open(index, sub, "wb", size=len(data), block_transfer=True) as f:
                f.write(data)
        ways = [("expedited", lambda: sdo.download(index, sub, data)),
                ("segmented", lambda: sdo.download(index, sub, data, force_segment=True)),
                ("block", block)]
        results = {}
        for way, fn in ways:
            results[way] = abort_or_none(fn)
            if readable:
                results[way] = (results[way], up(dut, n, index, sub))
        first = results["expedited"]
        assert results["segmented"] == first, f"{index:04X}h/{sub}: {results}"
        if facts.sdo_block:
            assert results["block"] == first, f"{index:04X}h/{sub}: {results}"
        else:
            refused = (0x05040001, first[1]) if readable else 0x05040001
            assert results["block"] == refused, f"{index:04X}h/{sub}: {results}"
        checked += 1
    assert checked >= 3


def test_rtr_answers_tpdo(dut, facts):
    """CiA 301: a TPDO whose COB-ID has bit 30 clear ("RTR allowed") is sent
    at once on a remote request while operational, one frame, as long as
    the frames the TPDO sends by itself; while pre-operational none. One
    with bit 30 set (the DSTs, docs/decisions.md) is never sent on a remote request."""
    dut.power_on(facts.nodes)
    for n in facts.nodes:
        nmt(dut, NMT_PREOP, n)
        tpdos, no_rtr = [], []
        for count in range(512):
            code = abort_or_none(lambda: up(dut, n, 0x1800 + count, 1))
            if code is not None:
                assert code == 0x06020000, f"{0x1800 + count:04X}h sub 1: abort {code:08X}h"
                break
            cob = struct.unpack("<I", up(dut, n, 0x1800 + count, 1))[0]
            if cob & 0xC0000000 == 0:
                tpdos.append(cob & 0x7FF)
            elif cob & 0x80000000 == 0:
                no_rtr.append(cob & 0x7FF)
        assert tpdos or no_rtr, f"node {n:#x}: no valid TPDO"
        # Its own frames (timer or SYNC) first: their length.
        nmt(dut, NMT_START, n)
        time.sleep(0.05)
        dut.send(0x080)
        own = {}
        for _, m in dut.frames.stream(0.4):
            if m.arbitration_id in tpdos + no_rtr and not m.is_remote_frame:
                own.setdefault(m.arbitration_id, len(m.data))
        assert set(own) == set(tpdos + no_rtr), \
            f"node {n:#x}: no TPDO of its own from {set(tpdos + no_rtr) - set(own)}"
        # Quiet: no event timer (where it can be written), no SYNC.
        nmt(dut, NMT_PREOP, n)
        for k in range(count):
            abort_or_none(lambda: down(dut, n, 0x1800 + k, 5, u16(0)))
        time.sleep(0.05)
        for cob in tpdos + no_rtr:
            dut.frames.clear()
            dut.send(cob, remote=True)
            assert not dut.frames.collect(cob, 0.2), f"{cob:03X}h answered in pre-operational"
        nmt(dut, NMT_START, n)
        time.sleep(0.1)
        for cob in tpdos:
            dut.frames.clear()
            dut.send(cob, remote=True)
            got = dut.frames.count(cob, 1)
            assert len(got) == 1, f"node {n:#x}: {len(got)} TPDOs on RTR {cob:03X}h, want 1"
            assert len(got[0][1].data) == own[cob], f"{cob:03X}h: {got[0][1]}"
        for cob in no_rtr:
            dut.frames.clear()
            dut.send(cob, remote=True)
            assert not dut.frames.collect(cob, 0.3), f"{cob:03X}h (no RTR) answered an RTR"
        nmt(dut, NMT_PREOP, n)


def test_mapping_count_beyond_entries(dut, facts, product):
    """CiA 301: with the PDO invalid and sub 0 at 0, a mapping count one
    larger than the entries written is refused with 06020000h (the entry
    names no object: 0, or a sub-index the mapping lacks) or 06040042h
    (more than 8 bytes); more than 64 with 06090031h. The count goes back
    and the PDO is valid again."""
    eds = eds_entries(product)
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    writable = [i for (i, s), e in eds.items() if 0x1A00 <= i < 0x1C00 and s == 0 and e.access == "rw"]
    if not facts.dynamic_mapping:
        assert not writable, "a writable mapping the facts do not know of"
        return
    assert writable
    for mapi in writable:
        comm = mapi - 0x200
        cob = up(dut, n, comm, 1)
        count = up(dut, n, mapi, 0)[0]
        entries = [struct.unpack("<I", up(dut, n, mapi, s))[0] for s in range(1, count + 1)]
        down(dut, n, comm, 1, struct.pack("<I", struct.unpack("<I", cob)[0] | 0x80000000))
        down(dut, n, mapi, 0, b"\0")
        nxt = abort_or_none(lambda: up(dut, n, mapi, count + 1))
        nxt = 0 if nxt is not None else struct.unpack("<I", up(dut, n, mapi, count + 1))[0]
        bits = sum(m & 0xFF for m in entries) + (nxt & 0xFF)
        want = 0x06020000 if nxt == 0 else 0x06040042 if bits > 64 else None
        got = abort_or_none(lambda: down(dut, n, mapi, 0, bytes([count + 1])))
        assert got == want, f"{mapi:04X}h sub 0 := {count + 1}: {got}, want {want}"
        assert abort_code(lambda: down(dut, n, mapi, 0, bytes([65]))) == 0x06090031
        down(dut, n, mapi, 0, bytes([count]))
        down(dut, n, comm, 1, cob)
        assert up(dut, n, mapi, 0)[0] == count and up(dut, n, comm, 1) == cob


def test_sync_cobid(dut, facts):
    """A product with SYNC transmission types has CiA 301's 1005h: a TPDO of
    type 1 follows the SYNC on the COB-ID written there (on the DSTs it is
    constant, docs/decisions.md)."""
    dut.power_on(facts.nodes)
    n = facts.nodes[0]
    if facts.sync_type is None:
        return  # event-driven only: test_tpdo_by_sync shows the refusal
    if facts.sync_cobid_writable is None:  # no 1005h: SYNC on 080h (test_tpdo_by_sync)
        assert abort_code(lambda: up(dut, n, 0x1005, 0)) == 0x06020000
        return
    assert up(dut, n, 0x1005, 0) == u32(0x80)
    if not facts.sync_cobid_writable:  # constant (docs/decisions.md)
        assert abort_code(lambda: down(dut, n, 0x1005, 0, u32(0x81))) == 0x06010002
        return
    cob = facts.tpdo_cob.of(n)
    down(dut, n, 0x1800, 2, b"\x01")
    down(dut, n, 0x1005, 0, u32(0x81))
    nmt(dut, NMT_START, n)
    time.sleep(0.1)
    dut.frames.clear()
    dut.send(0x080)
    assert not dut.frames.collect(cob, 0.2), "TPDO on 080h after 1005h := 81h"
    dut.send(0x081)
    assert len(dut.frames.count(cob, 1)) == 1, "not one TPDO on SYNC 081h"
    assert abort_code(lambda: down(dut, n, 0x1005, 0, u32(0x40000081))) == 0x06090030
