"""What the one integration suite (test_targets.py) expects of each product,
as a table: the checks are the same code for every product and target,
and every way a family differs is a value here (the product's manual is
the source of each; its section is given where a value is not plain
CiA 301, "decision:" where the manual leaves it open).

A family without a table here (one tools/new-family just made) is
expected to do what the template it was made from does (TEMPLATE below),
at the node-IDs the Linux program lists for it; CI runs its first product
on every target. Its own table replaces that once it differs.

A value written ID(base) means base + the node's node-ID.
"""
from dataclasses import dataclass, replace
import json
import struct
import subprocess

from conftest import BINARY

SAVE = b"save"  # 0x1010 signature, CiA 301


def u8(v):
    return struct.pack("<B", v)


def u16(v):
    return struct.pack("<H", v)


def i16(v):
    return struct.pack("<h", v)


def u32(v):
    return struct.pack("<I", v)


@dataclass(frozen=True)
class ID:
    """A value relative to the node-ID (COB-IDs)."""
    base: int

    def of(self, node_id):
        return self.base + node_id


@dataclass(frozen=True)
class Read:
    index: int
    sub: int
    value: object  # bytes, or ID(base) read as UNSIGNED32


@dataclass(frozen=True)
class Abort:
    """An SDO access that must be refused with this abort code."""
    op: str  # "r" upload, "w" download
    index: int
    sub: int
    code: int
    data: bytes = b""


@dataclass(frozen=True)
class Fault:
    """An injected fault and what the master must see of it."""
    on: tuple            # simulated input lines that raise it
    off: tuple           # lines that clear it
    emcy: bytes = None   # the EMCY frame it raises (None: the product sends none)
    emcy_off: bytes = None  # the EMCY frame that clears it (error reset)
    pdo_alarm: tuple = None  # (byte, mask) of TPDO1 that shows it instead


@dataclass(frozen=True)
class Corrupt:
    """How the product reports a corrupt stored set at boot: a bit of an
    object, or an EMCY code; None where it only falls back to defaults."""
    sdo_bit: tuple = None  # (index, sub, mask)
    emcy_code: int = None


# Steps of a node-ID change, as the product's manual gives it:
#   ("sdo", index, sub, data)   download to the node (its current ID)
#   ("lss-node-id", new)        CiA 305: configure node-ID, store, back to waiting
#   ("nmt", command)            NMT to the node (0x81 reset node, 0x82 reset comm)
#   ("power-cycle",)            clean power off, power on
@dataclass(frozen=True)
class NodeIdChange:
    steps: tuple
    new_id: int


@dataclass(frozen=True)
class Facts:
    family: str
    nodes: tuple                 # factory node-IDs, one per node of the device
    device_type: int             # 0x1000
    identity: dict               # 0x1018 sub -> value (sub 4, the serial, is per unit)
    name: bytes                  # 0x1008; None: the product has none
    boot_state: int              # heartbeat state after boot-up: 0x7F pre-op, 0x05 operational
    reads: tuple                 # more SDO reads (Read)
    rw: tuple                    # (index, sub, data): written, read back the same
    app_param: tuple             # (index, sub, new, default): an application parameter
    aborts: tuple                # Abort
    sync_type: int               # 0x1800:2 value "every 2nd SYNC"; None: no SYNC transmission
    sync_refused: int            # abort code of writing 0x1800:2 where sync_type is None
    event_mode: tuple            # (index, sub, data) writes for one TPDO1 per event timer
                                 # period (test_targets.EVENT_MS, 50 ms)
    fault: Fault
    stored: tuple                # two (index, sub, struct format) objects of one stored set
    defaults: tuple              # their factory values
    set_a: tuple                 # their values of the first save
    set_b: tuple                 # and of the second (the one a power cut hits)
    autosave: bool               # every SDO write is stored on its own (after a pause)
    corrupt: Corrupt
    node_id_change: NodeIdChange  # None: no way to change it (the template)
    tpdo_cob: ID = ID(0x180)
    sdo_block: bool = True       # SDO block download (CiA 301)
    sync_cobid_writable: bool = True  # 1005h rw (where the product has SYNC types);
                                      # None: no 1005h, SYNC fixed at 080h
    dynamic_mapping: bool = False  # 0x1A00.. writable (CiA 301 dynamic mapping)


# Heartbeat and event timer: every product has a rw 0x1017 and 0x1800:5.
HEARTBEAT = (0x1017, 0, "<H")
EVENT_TIMER = (0x1800, 5, "<H")

COMMON_ABORTS = (
    Abort("r", 0x2FFF, 0, 0x06020000),            # no such object
    Abort("r", 0x1018, 5, 0x06090011),            # no such sub-index
    Abort("w", 0x1000, 0, 0x06010002, u32(0)),    # read-only
    Abort("w", 0x1010, 1, 0x08000020, b"sav!"),   # wrong signature
)

DST = Facts(
    family="dst",
    nodes=(0x7F,),
    device_type=0x0008019A,
    identity={1: 0x93, 2: 0x64, 3: 1},                     # sub 4 per unit
    name=b"GIB",
    boot_state=0x7F,
    reads=(Read(0x1009, 0, b"1.00"), Read(0x1200, 1, ID(0x600)), Read(0x1200, 2, ID(0x580)),
           Read(0x1800, 5, u16(100)), Read(0x1010, 1, u32(1)), Read(0x1005, 0, u32(0x80)),
           Read(0x1800, 1, ID(0x40000180))),                 # bit 30: no RTR (docs/decisions.md)
    rw=((0x1017, 0, u16(250)), (0x2001, 0, u8(2))),
    app_param=(0x6014, 0, i16(-120), i16(0)),
    aborts=COMMON_ABORTS + (
        Abort("w", 0x1017, 0, 0x06090030, u16(10)),        # 1..19 not accepted (DST guides, 12)
        Abort("w", 0x1800, 2, 0x06090030, u8(255)),        # 1..240, 254 only (DST guides, 12)
        Abort("w", 0x20F0, 0, 0x06090032, u8(0)),          # node-ID 1..127 (DST guides, 20F0h)
        Abort("w", 0x2001, 0, 0x06070012, bytes(9)),       # segmented, longer than the object
    ),
    sync_type=2,
    sync_refused=None,
    event_mode=(),                                         # 254 + event timer by default
    fault=Fault(on=("fault sensor on",), off=("fault sensor off",),
                emcy=bytes.fromhex("0010000001000000"),    # 0x1000, 0x4001 = 0x01 (DST guides, 9)
                emcy_off=bytes(8)),
    stored=(HEARTBEAT, EVENT_TIMER),
    defaults=(0, 100),
    set_a=(300, 40),
    set_b=(500, 60),
    autosave=False,
    # 0x4001 bit 6: the LSS set's checksum (DST guides, 9); decision:
    # a bad PARA set (no bit for it) only brings the defaults back, which the
    # stored-set checks catch.
    corrupt=Corrupt(sdo_bit=(0x4001, 0, 0x40)),
    # DST guides, 20F0h and example 2: both copies, active after a power cycle;
    # decision: stored by the device itself (the example has no save).
    node_id_change=NodeIdChange(steps=(("sdo", 0x20F0, 0, u8(6)), ("sdo", 0x20F1, 0, u8(6)),
                                       ("power-cycle",)), new_id=6),
    sdo_block=False,                         # expedited and segmented (docs/decisions.md)
    sync_cobid_writable=False,               # 1005h constant (docs/decisions.md)
)

GSH = Facts(
    family="gsh",
    nodes=(0x13,),
    device_type=0xFFFF0196,
    identity={1: 0x93, 2: 0x67, 3: 1},                     # sub 4 per unit
    name=b"GSHA",
    boot_state=0x05,                                       # auto-start: 5000h (GSH-A manual, 12)
    reads=(Read(0x100A, 0, b"1.00"), Read(0x1200, 1, ID(0x600)), Read(0x1800, 1, ID(0x180)),
           Read(0x1800, 2, u8(254)), Read(0x5000, 0, u8(1)), Read(0x1010, 1, u32(1))),
    rw=((0x1017, 0, u16(250)), (0x1800, 5, u16(200))),
    app_param=(0x5000, 0, u8(0), u8(1)),
    aborts=COMMON_ABORTS + (
        Abort("r", 0x1011, 1, 0x06020000),                 # no 0x1011 (nor in the GSH-A manual)
        Abort("w", 0x3001, 0, 0x06090032, u8(0)),          # node-ID 01h..7Fh (GSH-A manual, 4)
        # 4..65535 ms (GSH-A manual, 11); decision: 0 accepted, as "off".
        Abort("w", 0x1800, 5, 0x06090032, u16(3)),
    ),
    sync_type=None,                                        # type 254, ro (GSH-A manual, 12)
    sync_refused=0x06010002,
    event_mode=(),
    # No EMCY at all (the GSH-A manual has no EMCY object): the alarm word of
    # TPDO1 (bytes 4-5, GSH-A manual, 9) shows it.
    fault=Fault(on=("fault extension-element on",), off=("fault extension-element off",),
                pdo_alarm=(5, 0x02)),
    stored=(HEARTBEAT, EVENT_TIMER),
    defaults=(0, 100),
    set_a=(300, 40),
    set_b=(500, 60),
    autosave=False,
    corrupt=Corrupt(),                                     # decision: defaults only (manual silent)
    # GSH-A manual, 13, example 1: write, save, reset (a power cycle).
    node_id_change=NodeIdChange(steps=(("sdo", 0x3001, 0, u8(6)), ("sdo", 0x1010, 1, SAVE),
                                       ("power-cycle",)), new_id=6),
)

JD = Facts(
    family="jd",
    nodes=(10,),
    device_type=0x0002019A,
    identity={1: 0x0069666D, 2: 0, 3: 0x00010000},        # sub 4 per unit
    name=b"JD2xxx",
    boot_state=0x7F,
    reads=(Read(0x1009, 0, b"HW 1.0"), Read(0x1800, 1, ID(0x180)), Read(0x1801, 1, ID(0x280)),
           Read(0x1800, 2, u8(1)), Read(0x3000, 0, u8(9)), Read(0x1010, 1, u32(1))),
    rw=((0x1017, 0, u16(250)), (0x3100, 0, u16(4))),
    app_param=(0x3100, 0, u16(4), u16(0)),
    aborts=COMMON_ABORTS + (
        Abort("w", 0x3000, 0, 0x06090031, u8(0x7F)),       # node number 0..0x7E (JD manual, 9.21)
        # Inhibit time only while the TPDO is invalid (JD manual, 8.9.4).
        Abort("w", 0x1800, 3, 0x06090030, u16(10)),
    ),
    sync_type=2,
    sync_refused=None,
    event_mode=((0x1800, 2, u8(254)),),
    fault=Fault(on=("can passive",), off=("can active",),
                # 8120h CAN error passive: CiA 301's code (the JD manual lists none).
                emcy=bytes.fromhex("2081110000000000"),
                emcy_off=bytes(8)),
    stored=(HEARTBEAT, EVENT_TIMER),
    defaults=(0, 10),
    set_a=(300, 40),
    set_b=(500, 60),
    autosave=False,
    corrupt=Corrupt(emcy_code=0x6300),
    # LSS (JD manual, 6.3; CiA 305): configure node-ID + store, then reset comm.
    node_id_change=NodeIdChange(steps=(("lss-node-id", 32), ("nmt", 0x82)), new_id=32),
    dynamic_mapping=True,
)

PF = Facts(
    family="pf",
    nodes=(1,),
    device_type=0x0000019A,
    identity={1: 0, 2: 0, 3: 0},                           # placeholders: the manual has none
    name=b"INY360D-F99-B16-V15",
    boot_state=0x7F,
    reads=(Read(0x1010, 1, u32(3)), Read(0x1800, 1, ID(0x180)), Read(0x1800, 2, u8(1)),
           Read(0x2000, 0, u8(1)), Read(0x2001, 0, u8(2)), Read(0x6000, 0, u16(100))),
    rw=((0x1017, 0, u16(250)), (0x6014, 0, i16(-200))),
    app_param=(0x6014, 0, i16(-200), i16(0)),
    aborts=COMMON_ABORTS + (
        Abort("r", 0x1200, 0, 0x06020000),                 # fixed SDO COB-IDs: no 0x1200
        Abort("w", 0x2001, 0, 0x06090030, u8(3)),          # 1, 2, 4, 8 only
        Abort("w", 0x6014, 0, 0x06090031, i16(5000)),      # -3599..3599
        Abort("w", 0x1800, 2, 0x06090030, u8(245)),        # F1h-FBh refused
    ),
    sync_type=2,
    sync_refused=None,
    # FEh is sent after each calculation, like FFh (decision: the P+F manual,
    # 7.1.1, lists only FFh), the event timer (CiA 301) only adds to that: the
    # inhibit time (P+F manual, 7.1.1) makes the 50 ms here.
    event_mode=((0x1800, 2, u8(0xFE)), (0x1800, 3, u16(500))),
    fault=Fault(on=("fault range-x on",), off=("fault range-x off",),
                emcy=bytes.fromhex("1050110000000000"),    # 5010h, register 0x11
                emcy_off=bytes(8)),
    stored=(HEARTBEAT, EVENT_TIMER),
    defaults=(0, 0),
    set_a=(300, 40),
    set_b=(500, 60),
    # Decision: every write is stored at once (no save step in the P+F manual).
    autosave=True,
    corrupt=Corrupt(emcy_code=0x6300),                     # EEPROM checksum (P+F manual, 7.2.1)
    # P+F manual, 6.2: write 2000h, active after Reset Node or a power cycle.
    node_id_change=NodeIdChange(steps=(("sdo", 0x2000, 0, u8(15)), ("nmt", 0x81)), new_id=15),
    dynamic_mapping=True,
)

# The template (od/skeleton, tests/unit/test_skeleton.c): CiA 301 and CiA
# 410 defaults, no 1008h, no 1005h (SYNC on 080h), no node-ID object, no LSS.
TEMPLATE = Facts(
    family="template",
    nodes=(0x20,),
    device_type=0x0000019A,
    identity={1: 0, 2: 1, 3: 0x00010000},                 # sub 4 per unit
    name=None,
    boot_state=0x7F,
    reads=(Read(0x1010, 1, u32(1)), Read(0x1800, 1, ID(0x180)), Read(0x1800, 2, u8(254)),
           Read(0x1800, 5, u16(0)), Read(0x6000, 0, u16(10))),
    rw=((0x1017, 0, u16(250)), (0x6013, 0, i16(-200))),
    app_param=(0x6013, 0, i16(-200), i16(0)),
    aborts=COMMON_ABORTS + (
        Abort("w", 0x6000, 0, 0x06090030, u16(7)),         # 1, 10, 100, 1000 only (CiA 410)
    ),
    sync_type=2,
    sync_refused=None,
    event_mode=(),                                         # 254 + event timer by default
    fault=Fault(on=("fault sensor on",), off=("fault sensor off",),
                emcy=bytes.fromhex("0050010000000000"),    # 5000h, generic error
                emcy_off=bytes(8)),
    stored=(HEARTBEAT, EVENT_TIMER),
    defaults=(0, 0),
    set_a=(300, 40),
    set_b=(500, 60),
    autosave=False,
    corrupt=Corrupt(emcy_code=0x6300),
    node_id_change=None,
    sdo_block=False,                                       # expedited transfers only
    sync_cobid_writable=None,
)


def _dst(pid):
    x710 = pid.startswith("dst-x710")
    reads = DST.reads + (Read(0x100A, 0, b"1.10" if x710 else b"1.24"),)
    aborts = DST.aborts + ((Abort("r", 0x5001, 0, 0x06020000),) if x710 else ())  # no 0x5001
    return replace(DST, family="dst-x710" if x710 else "dst-x730", reads=reads, aborts=aborts)


DST_IDS = tuple(f"dst-{m}-{v}" for m in ("x730", "x710")
                for v in ("xy10", "xy15", "xy20", "xy30", "xy45", "xy60", "xy90", "z360"))

PRODUCTS = {pid: _dst(pid) for pid in DST_IDS}
PRODUCTS.update({
    "gsh-a": GSH,
    # Two independent nodes in one device; on one bus here (one serial line).
    "gsh-a-redundant": replace(GSH, family="gsh-redundant", nodes=(0x13, 0x14)),
    "jd2xxx": JD,
    "jd1xxx": replace(JD, device_type=0x0001019A, name=b"JD1xxx"),
    "iny360d": PF,
    "inx360d": replace(PF, name=b"INX360D-F99-B16-V15"),
})

# What CI runs on each target: one product of each family (and the
# redundant GSH-A), the emulated boards taking the other variant of each
# pair, so that CI runs every one of them on some MCU. tools/check
# --all-products runs every product ID on each.
CI_PRODUCTS = {
    "linux": ("dst-x730-xy30", "dst-x710-z360", "gsh-a", "gsh-a-redundant", "jd2xxx", "inx360d"),
    "rv32-virt": ("dst-x730-xy10", "dst-x710-xy45", "gsh-a", "gsh-a-redundant", "jd1xxx",
                  "iny360d"),
    # The same image as rv32-virt, its frames through the SJA1000 on vcan0.
    "rv32-can": ("dst-x730-xy10", "dst-x710-xy45", "gsh-a", "gsh-a-redundant", "jd1xxx",
                 "iny360d"),
    "microbit": ("dst-x730-z360", "dst-x710-xy90", "gsh-a", "gsh-a-redundant", "jd2xxx",
                 "inx360d"),
}


def listed_products():
    """The Linux program's products (`canopen-sensor --list-products
    --json`, BINARY); none when it cannot be run (no build yet)."""
    try:
        out = subprocess.run([BINARY, "--list-products", "--json"], check=True,
                             capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return []
    return json.loads(out)


# A family none of the tables above covers: the template's facts at its
# products' own node-IDs.
_LISTED = listed_products()
_COVERED = {p["family"] for p in _LISTED if p["id"] in PRODUCTS}
PRODUCTS.update({p["id"]: replace(TEMPLATE, family=p["family"], nodes=tuple(p["default_node_ids"]))
                 for p in _LISTED if p["family"] not in _COVERED})
# A family CI_PRODUCTS names no product of on a target: its first there.
_FIRST = {}
for _p in _LISTED:
    _FIRST.setdefault(_p["family"], _p["id"])
for _target, _ids in CI_PRODUCTS.items():
    _in = {p["family"] for p in _LISTED if p["id"] in _ids}
    CI_PRODUCTS[_target] = _ids + tuple(i for fam, i in _FIRST.items() if fam not in _in)

