"""tools/mkimage: the images it makes, read back byte by byte here and by
the firmware's own reader (co_image_parse and co_crc32, through
test_image --file), so that the writer and the reader cannot drift apart;
the identity taken from each product's EDS equal to what its dictionary
answers; the payload from an ELF file; every refusal with its exit status
and message; --show on good and broken images.

  python3 test_mkimage.py --program build/bin/canopen-sensor \\
      --test-image build/bin/test_image [unittest options]
"""
import argparse
import json
import os
import pathlib
import struct
import subprocess
import sys
import tempfile
import unittest
import zlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
MKIMAGE = str(ROOT / "tools" / "mkimage")
PROGRAM = None  # canopen-sensor, from the command line
TEST_IMAGE = None  # test_image, from the command line

HDR = struct.Struct("<4sHHIIIIIIIIII16s")  # include/co_image.h's table
BOARD_CODES = {"nucleo-f042k6": 1, "microbit": 2, "rv32-virt": 3, "linux": 0x100}


def mkimage(*args):
    return subprocess.run([MKIMAGE, *map(str, args)], capture_output=True, text=True, timeout=120)


def fields(b):
    names = ("magic", "hsize", "version", "length", "crc", "board", "device_type", "vendor",
             "product", "revision", "program_id", "load_addr", "reserved", "id")
    return dict(zip(names, HDR.unpack_from(b)))


def c_reads(path, board, program_id, load_addr):
    """test_image --file: the firmware's reader on the file (exit status, output)."""
    run = subprocess.run([TEST_IMAGE, "--file", str(path), hex(board), hex(program_id),
                          hex(load_addr)], capture_output=True, text=True, timeout=60)
    return run.returncode, run.stdout + run.stderr


def elf32(segments, machine=40, cls=1):
    """A little-endian ELF executable with these program headers:
    (p_type, paddr, bytes, memsz); the bytes follow the headers."""
    phoff, n = 52, len(segments)
    data = bytearray(52 + 32 * n)
    struct.pack_into("<4sBBBB8xHHIIIIIHHHHHH", data, 0, b"\x7fELF", cls, 1, 1, 0, 2, machine, 1,
                     0, phoff, 0, 0, 52, 32, n, 40, 0, 0)
    for i, (p_type, paddr, blob, memsz) in enumerate(segments):
        off = len(data)
        data += blob
        struct.pack_into("<8I", data, phoff + 32 * i, p_type, off, paddr | 0x10000000, paddr,
                         len(blob), memsz, 5, 4)
    return bytes(data)


def with_symbol(elf, name, value):
    """elf (elf32's) with a symbol table holding name = value (absolute),
    as a link's --defsym leaves it: a null section, .symtab, .strtab."""
    data = bytearray(elf)
    strtab = b"\0" + name.encode() + b"\0"
    symtab = bytes(16) + struct.pack("<IIIBBH", 1, value, 0, 0x10, 0, 0xFFF1)  # SHN_ABS
    sym_off = len(data)
    data += symtab
    str_off = len(data)
    data += strtab
    shoff = len(data)
    data += bytes(40)  # section 0
    data += struct.pack("<10I", 0, 2, 0, 0, sym_off, len(symtab), 2, 1, 4, 16)
    data += struct.pack("<10I", 0, 3, 0, 0, str_off, len(strtab), 0, 0, 1, 0)
    struct.pack_into("<I", data, 32, shoff)
    struct.pack_into("<HHH", data, 46, 40, 3, 0)
    return bytes(data)


class Base(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory(prefix="mkimage-")
        self.tmp = pathlib.Path(self.dir.name)

    def tearDown(self):
        self.dir.cleanup()

    def refused(self, status, words, *args):
        """mkimage args fails with status and a message with each of words,
        and leaves no file in the work directory but the inputs there."""
        before = set(self.tmp.iterdir())
        run = mkimage(*args)
        self.assertEqual(run.returncode, status, f"{args}: {run.stdout}{run.stderr}")
        for w in words:
            self.assertIn(w, run.stderr)
        self.assertEqual(set(self.tmp.iterdir()), before, "a refusal left a file behind")
        return run


class EveryProduct(Base):
    def test_linux_images_of_every_product(self):
        """Each product's Linux image: its header as the table says, the
        CRC zlib's over bytes 16 on, and the firmware's reader takes it
        with the identity its dictionary answers."""
        products = json.loads(subprocess.run([PROGRAM, "--list-products", "--json"],
                                             capture_output=True, text=True, check=True).stdout)
        ids = [p["id"] for p in products if not p["template"]]
        self.assertGreaterEqual(len(ids), 20)
        for n, pid in enumerate(ids):
            out = self.tmp / f"{pid}.img"
            run = mkimage("--product", pid, "--board", "linux", "--program-id", 1000 + n,
                          "--program", PROGRAM, "-o", out)
            self.assertEqual(run.returncode, 0, run.stderr)
            b = out.read_bytes()
            self.assertEqual(len(b), 64)
            f = fields(b)
            self.assertEqual((f["magic"], f["hsize"], f["version"], f["length"]),
                             (b"COIM", 64, 1, 64))
            self.assertEqual(f["crc"], zlib.crc32(b[16:]))
            self.assertEqual((f["board"], f["program_id"], f["load_addr"], f["reserved"]),
                             (0x100, 1000 + n, 0, 0))
            self.assertEqual(f["id"], pid.encode().ljust(16, b"\0"))
            status, said = c_reads(out, 0x100, 1000 + n, 0)
            self.assertEqual(status, 0, said)
            self.assertIn(f"{pid}, 64 bytes", said)

    def test_identity_is_the_eds_one(self):
        """1000h and 1018h:1-3 are the EDS's values (a product of another
        family too: the GSH-A)."""
        for pid in ("dst-x730-xy30", "gsh-a"):
            eds = subprocess.run([PROGRAM, "--product", pid, "--eds"], capture_output=True,
                                 text=True, check=True).stdout
            want = []
            for sec in ("[1000]", "[1018sub1]", "[1018sub2]", "[1018sub3]"):
                part = eds.split(sec + "\n", 1)[1].split("\n\n", 1)[0]
                line = [x for x in part.splitlines() if x.startswith("DefaultValue=")][0]
                want.append(int(line.split("=", 1)[1], 0))
            out = self.tmp / "x.img"
            self.assertEqual(mkimage("--product", pid, "--board", "linux", "--program-id", 5,
                                     "--program", PROGRAM, "-o", out).returncode, 0)
            f = fields(out.read_bytes())
            self.assertEqual([f["device_type"], f["vendor"], f["product"], f["revision"]], want)


class Payload(Base):
    def test_raw_payload_padded_to_words(self):
        """An MCU image of a raw payload: FFh up to whole words, the CRC
        over header and payload, read by the firmware's reader."""
        payload = bytes((i * 37 + 11) & 0xFF for i in range(1001))
        (self.tmp / "p.bin").write_bytes(payload)
        out = self.tmp / "p.img"
        run = mkimage("--product", "dst-x730-xy30", "--board", "nucleo-f042k6",
                      "--program-id", "0xA1B2C3D4", "--payload", self.tmp / "p.bin",
                      "--load-addr", "0x08001000", "--program", PROGRAM, "-o", out)
        self.assertEqual(run.returncode, 0, run.stderr)
        b = out.read_bytes()
        self.assertEqual(len(b), 64 + 1004)
        self.assertEqual(b[64:], payload + b"\xff" * 3)
        self.assertEqual(sorted(x.name for x in self.tmp.iterdir()), ["p.bin", "p.img"])
        f = fields(b)
        self.assertEqual((f["length"], f["board"], f["program_id"], f["load_addr"]),
                         (1068, 1, 0xA1B2C3D4, 0x08001000))
        self.assertEqual(f["crc"], zlib.crc32(b[16:]))
        status, said = c_reads(out, 1, 0xA1B2C3D4, 0x08001000)
        self.assertEqual(status, 0, said)
        # The firmware's reader sees a wrong field, and a changed payload byte.
        self.assertNotEqual(c_reads(out, 1, 0xA1B2C3D5, 0x08001000)[0], 0)
        bad = bytearray(b)
        bad[700] ^= 1
        (self.tmp / "bad.img").write_bytes(bad)
        self.assertNotEqual(c_reads(self.tmp / "bad.img", 1, 0xA1B2C3D4, 0x08001000)[0], 0)

    def test_payload_from_elf(self):
        """--elf: the loadable bytes at their physical addresses, the gap
        between them FFh, a segment with no file bytes (.bss) and one that
        is not loadable left out; the load address is the lowest."""
        text, data = b"\x01\x02\x03\x04\x05\x06", b"\xaa\xbb\xcc\xdd\xee"
        elf = elf32([(1, 0x80020000, text, 6), (4, 0x80000000, b"NOTE", 4),
                     (1, 0x80020008, data, 5), (1, 0x80030000, b"", 0x100)])
        (self.tmp / "a.elf").write_bytes(elf)
        out = self.tmp / "a.img"
        run = mkimage("--product", "dst-x730-xy30", "--board", "rv32-virt", "--program-id", 9,
                      "--elf", self.tmp / "a.elf", "--program", PROGRAM, "-o", out)
        self.assertEqual(run.returncode, 0, run.stderr)
        b = out.read_bytes()
        self.assertEqual(b[64:], text + b"\xff\xff" + data + b"\xff" * 3)
        self.assertEqual(fields(b)["load_addr"], 0x80020000)
        self.assertEqual(c_reads(out, 3, 9, 0x80020000)[0], 0)

    def test_program_id_from_the_elf(self):
        """An application of this tree carries the 1F56h:1 it reports
        (co_program_id): the image takes it when --program-id is left out;
        another --program-id is refused (a master would update at every
        boot) unless --other-program-id; an ELF without it needs one."""
        elf = with_symbol(elf32([(1, 0x80020000, b"\x01\x02\x03\x04", 4)]), "co_program_id",
                          0x10005)
        (self.tmp / "a.elf").write_bytes(elf)
        common = ("--product", "dst-x730-xy30", "--board", "rv32-virt", "--elf",
                  self.tmp / "a.elf", "--program", PROGRAM)
        out = self.tmp / "a.img"
        run = mkimage(*common, "-o", out)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertEqual(fields(out.read_bytes())["program_id"], 0x10005)
        run = mkimage(*common, "--program-id", "0x10005", "-o", out)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.refused(1, ["--program-id 0x00010006", "reports 1F56h:1 = 0x00010005",
                         "every boot", "--other-program-id"],
                     *common, "--program-id", "0x10006", "-o", self.tmp / "b.img")
        run = mkimage(*common, "--program-id", "0x10006", "--other-program-id", "-o", out)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertEqual(fields(out.read_bytes())["program_id"], 0x10006)
        (self.tmp / "n.elf").write_bytes(elf32([(1, 0x80020000, b"\x01\x02\x03\x04", 4)]))
        self.refused(2, ["no symbol co_program_id", "give --program-id"], "--product",
                     "dst-x730-xy30", "--board", "rv32-virt", "--elf", self.tmp / "n.elf",
                     "--program", PROGRAM, "-o", self.tmp / "c.img")

    def test_bad_elf_files(self):
        common = ("--product", "dst-x730-xy30", "--board", "rv32-virt", "--program-id", 9,
                  "--program", PROGRAM, "-o", self.tmp / "o.img")
        cases = {
            "not an ELF file": b"\x00" * 100,
            "not a 32-bit little-endian ELF": elf32([(1, 0, b"x", 1)], cls=2),
            "no loadable bytes": elf32([(1, 0x1000, b"", 8)]),
            "segments overlap": elf32([(1, 0x1000, b"abcd", 4), (1, 0x1002, b"ef", 2)]),
        }
        for i, (words, blob) in enumerate(cases.items()):
            path = self.tmp / f"bad{i}.elf"
            path.write_bytes(blob)
            self.refused(1, [words], *common, "--elf", path)


class Refusals(Base):
    def test_command_line_errors(self):
        """Exit 2, the message naming what is wrong."""
        ok = {"--product": "dst-x730-xy30", "--board": "linux", "--program-id": "7",
              "--program": PROGRAM, "-o": str(self.tmp / "o.img")}

        def args(**over):
            d = dict(ok)
            for k, v in over.items():
                key = "-o" if k == "o" else "--" + k.replace("_", "-")
                if v is None:
                    d.pop(key)
                else:
                    d[key] = v
            return [x for kv in d.items() for x in kv]

        self.refused(2, ["'abcdefghijklmnopq'", "1 to 16"], *args(product="abcdefghijklmnopq"))
        self.refused(2, ["1 to 16"], *args(product="dst x730"))
        self.refused(2, ["1 to 16"], *args(product=""))
        self.refused(2, ["unknown board 'vax'", "nucleo-f042k6"], *args(board="vax"))
        self.refused(2, ["--program-id 0"], *args(program_id="0"))
        self.refused(2, ["out of range"], *args(program_id="0x100000000"))
        self.refused(2, ["not a number"], *args(program_id="seven"))
        self.refused(2, ["load address is 0"], *args(load_addr="4"))
        self.refused(2, ["the program is needed"], *args(board="microbit"))
        (self.tmp / "p.bin").write_bytes(b"1234")
        self.refused(2, ["--payload needs --load-addr"],
                     *args(board="microbit", payload=str(self.tmp / "p.bin")))
        self.refused(2, ["not with --payload"],
                     *args(board="microbit", payload=str(self.tmp / "p.bin"), elf="x.elf"))
        self.refused(2, ["takes no --elf"], *args(elf="x.elf"))
        self.refused(2, ["--eds or --program"], *args(eds="x.eds"))
        self.refused(2, ["missing --board"], *args(board=None))
        self.refused(2, ["unrecognized arguments"], *args(), "--frobnicate")
        self.refused(2, ["--show takes no other option"], "--show", "x.img", "--board", "linux")

    def test_input_errors(self):
        """Exit 1: a payload the board does not take, a product the program
        does not know, no program, an EDS without the identity or of
        another product."""
        common = ("--program-id", 7, "-o", self.tmp / "o.img")
        big = self.tmp / "big.bin"
        big.write_bytes(b"\0" * (64 * 1024 + 1))
        self.refused(1, ["65540 bytes", "rv32-virt", "65536"], "--product", "dst-x730-xy30",
                     "--board", "rv32-virt", "--payload", big, "--load-addr", "0x80020000",
                     "--program", PROGRAM, *common)
        big.unlink()
        self.refused(1, ["unknown product 'nope'"], "--product", "nope", "--board", "linux",
                     "--program", PROGRAM, *common)
        self.refused(1, ["no such program"], "--product", "dst-x730-xy30", "--board", "linux",
                     "--program", self.tmp / "none", *common)
        # Without --program: $CANOPEN_SENSOR, as the other tools take it.
        os.environ["CANOPEN_SENSOR"] = str(self.tmp / "elsewhere")
        try:
            self.refused(1, [f"{self.tmp / 'elsewhere'}: no such program"], "--product",
                         "dst-x730-xy30", "--board", "linux", *common)
            os.environ["CANOPEN_SENSOR"] = PROGRAM
            self.assertEqual(mkimage("--product", "dst-x730-xy30", "--board", "linux",
                                     *common).returncode, 0)
            (self.tmp / "o.img").unlink()
        finally:
            del os.environ["CANOPEN_SENSOR"]
        eds = self.tmp / "x.eds"
        eds.write_text("[DeviceInfo]\nOrderCode=dst-x730-xy30\n[1000]\nDefaultValue=0x1\n"
                       "[1018sub1]\nDefaultValue=2\n[1018sub3]\nDefaultValue=4\n")
        self.refused(1, ["no [1018sub2] DefaultValue"], "--product", "dst-x730-xy30",
                     "--board", "linux", "--eds", eds, *common)
        self.refused(1, ["the EDS of product 'dst-x730-xy30', not 'jd1xxx'"], "--product",
                     "jd1xxx", "--board", "linux", "--eds", eds, *common)
        eds.write_text("[DeviceInfo]\nOrderCode=dst-x730-xy30\n[1000]\nDefaultValue=0x1\n"
                       "[1018sub1]\nDefaultValue=2\n[1018sub2]\nDefaultValue=0x30\n"
                       "[1018sub3]\nDefaultValue=4\n")
        run = mkimage("--product", "dst-x730-xy30", "--board", "linux", "--eds", eds, *common)
        self.assertEqual(run.returncode, 0, run.stderr)
        f = fields((self.tmp / "o.img").read_bytes())
        self.assertEqual((f["device_type"], f["vendor"], f["product"], f["revision"]),
                         (1, 2, 0x30, 4))

    def test_output_is_whole_or_nothing(self):
        """An existing output stays as it was when the new one fails."""
        out = self.tmp / "o.img"
        out.write_bytes(b"old")
        self.refused(1, ["unknown product"], "--product", "nope", "--board", "linux",
                     "--program-id", 7, "--program", PROGRAM, "-o", out)
        self.assertEqual(out.read_bytes(), b"old")
        self.refused(1, ["o.img"], "--product", "dst-x730-xy30", "--board", "linux",
                     "--program-id", 7, "--program", PROGRAM, "-o", self.tmp / "no" / "o.img")


class Show(Base):
    def make(self):
        out = self.tmp / "s.img"
        (self.tmp / "p.bin").write_bytes(bytes(range(200)))
        run = mkimage("--product", "jd2xxx", "--board", "microbit", "--program-id", 0x10203,
                      "--payload", self.tmp / "p.bin", "--load-addr", "0x18000",
                      "--program", PROGRAM, "-o", out)
        self.assertEqual(run.returncode, 0, run.stderr)
        (self.tmp / "p.bin").unlink()
        return out, out.read_bytes()

    def variant(self, b, name="v.img"):
        path = self.tmp / name
        path.write_bytes(bytes(b))
        return path

    def test_good(self):
        out, b = self.make()
        run = mkimage("--show", out)
        self.assertEqual(run.returncode, 0, run.stderr)
        for words in ("264 bytes (header 64, payload 200)", "product ID     jd2xxx",
                      "board          microbit (0x2)", "1F56h          0x00010203 (66051)",
                      "load address   0x00018000", f"CRC-32         0x{zlib.crc32(b[16:]):08X}",
                      "good: header, length and CRC"):
            self.assertIn(words, run.stdout)

    def test_broken(self):
        """Each fault: exit 1 and its message; where the header is what
        is broken, the firmware's reader refuses it too."""
        out, b = self.make()

        def with_crc(v):
            v = bytearray(v)
            struct.pack_into("<I", v, 12, zlib.crc32(bytes(v[16:])))
            return v

        header_faults = {
            "not an image": b"MIOC" + b[4:],
            "header size 65": b[:4] + b"\x41" + b[5:],
            "format version 2": b[:6] + b"\x02" + b[7:],
            "length 63": b[:8] + struct.pack("<I", 63) + b[12:],
            "reserved word": with_crc(b[:44] + b"\x00\x00\x00\x01" + b[48:]),
            "product ID field": with_crc(b[:48] + b"jd 2xxx".ljust(16, b"\0") + b[64:]),
        }
        for words, v in header_faults.items():
            path = self.variant(v)
            run = mkimage("--show", path)
            self.assertEqual(run.returncode, 1, words)
            self.assertIn(words, run.stderr)
            status, said = c_reads(path, 2, 0x10203, 0x18000)
            self.assertNotEqual(status, 0, f"the firmware reads an image with {words}")
            self.assertIn("no image header", said)
        faults = {
            "CRC error": b[:100] + bytes([b[100] ^ 0x80]) + b[101:],
            "truncated: 263 bytes of the 264": b[:-1],
            "1 bytes after the 264": b + b"\0",
            "board code 0x7 is none": with_crc(b[:16] + struct.pack("<I", 7) + b[20:]),
            "shorter than the 64-byte header": b[:63],
        }
        for words, v in faults.items():
            run = mkimage("--show", self.variant(v))
            self.assertEqual(run.returncode, 1, words)
            self.assertIn(words, run.stderr)
        run = mkimage("--show", self.tmp / "none.img")
        self.assertEqual(run.returncode, 1)
        self.assertIn("No such file", run.stderr)


def main():
    global PROGRAM, TEST_IMAGE
    ap = argparse.ArgumentParser()
    ap.add_argument("--program", required=True, help="the host's canopen-sensor")
    ap.add_argument("--test-image", required=True, help="the unit test test_image")
    args, rest = ap.parse_known_args()
    PROGRAM, TEST_IMAGE = os.path.abspath(args.program), os.path.abspath(args.test_image)
    unittest.main(argv=[sys.argv[0], *rest], verbosity=2)


if __name__ == "__main__":
    main()
