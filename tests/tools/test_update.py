"""tools/update without a bus: the image header it reads (tools/mkimage's
reader, against the format of include/co_image.h written out here byte by
byte), and its
command line's refusals (exit 2, the cause on stderr, nothing sent). The
updates themselves: tests/integration/test_progdl.py (vcan)."""
import importlib.machinery
import importlib.util
import pathlib
import struct
import subprocess
import sys
import tempfile
import unittest
import zlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
UPDATE = ROOT / "tools" / "update"


def load():
    loader = importlib.machinery.SourceFileLoader("update_tool", str(UPDATE))
    spec = importlib.util.spec_from_loader("update_tool", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod


tool = load()


def image(pid=0x10203, payload=b"\x01\x02\x03", product="dst-x730-xy30", board=0x100,
          identity=(0x8019A, 0x93, 0x64, 1), length=None, crc=None, magic=b"COIM"):
    """An image as co_image.h lays it out."""
    n = 64 + len(payload) if length is None else length
    rest = struct.pack("<8I", board, *identity, pid, 0, 0) + product.encode().ljust(16, b"\0")
    body = rest + payload
    c = zlib.crc32(body) & 0xFFFFFFFF if crc is None else crc
    return magic + struct.pack("<HHII", 64, 1, n, c) + body


class Header(unittest.TestCase):
    def test_fields(self):
        h = tool.parse_header(image())
        self.assertEqual((h["length"], h["board"], h["device_type"], h["vendor"], h["product"],
                          h["revision"], h["program_id"], h["load_addr"], h["id"]),
                         (67, 0x100, 0x8019A, 0x93, 0x64, 1, 0x10203, 0, "dst-x730-xy30"))
        self.assertEqual(tool.describe(h),
                         "dst-x730-xy30 for linux, program ID 0x00010203, 67 bytes")

    def test_refused_headers(self):
        for data, why in ((image()[:63], "shorter than the 64-byte header"),
                          (image(magic=b"ELF\x7f"), "not an image"),
                          (image()[:4] + b"\x40\x00\x02\x00" + image()[8:], "version 2"),
                          (image()[:4] + b"\x20\x00\x01\x00" + image()[8:], "header size 32"),
                          (image(product="two words"), "product ID field"),
                          (image(product=""), "product ID field"),
                          (image()[:44] + b"\1\0\0\0" + image()[48:], "reserved word"),
                          (image(length=10), "length 10: shorter than the header")):
            with self.assertRaises(tool.ImageError) as e:
                tool.parse_header(data)
            self.assertIn(why, str(e.exception))

    def test_files(self):
        with tempfile.TemporaryDirectory() as d:
            p = pathlib.Path(d) / "a.img"
            p.write_bytes(image())
            h, data = tool.read_image(p)
            self.assertEqual((h["program_id"], data), (0x10203, image()))
            for data, why in ((image()[:-1], "the header says 67 bytes, the file has 66"),
                              (image() + b"\xff", "the header says 67 bytes, the file has 68"),
                              (image(crc=0x1234), "the header says 00001234 (damaged)")):
                p.write_bytes(data)
                with self.assertRaises(tool.ImageError) as e:
                    tool.read_image(p)
                self.assertIn(why, str(e.exception))
            with self.assertRaises(tool.ImageError) as e:
                tool.read_image(pathlib.Path(d) / "missing.img")
            self.assertIn("No such file", str(e.exception))


class CommandLine(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)
        self.dir = pathlib.Path(self.tmp.name)
        self.good = self.dir / "good.img"
        self.good.write_bytes(image())

    def run_tool(self, *args):
        return subprocess.run([sys.executable, str(UPDATE), *map(str, args)],
                              capture_output=True, text=True, timeout=60)

    def refused(self, text, *args):
        r = self.run_tool(*args)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(text, r.stderr)
        self.assertEqual(r.stdout, "")

    def test_help(self):
        r = self.run_tool("--help")
        self.assertEqual(r.returncode, 0)
        for word in ("--node", "--interface", "--channel", "--force", "--segmented", "--timeout",
                     "1F51h:1 = 3", "1F57h:1"):
            self.assertIn(word, r.stdout)

    def test_refusals(self):
        self.refused("the following arguments are required: --node", self.good)
        self.refused("the following arguments are required: IMAGE", "--node", "5")
        self.refused("0: a node-ID is 1..127", "--node", "0", self.good)
        self.refused("0x80: a node-ID is 1..127", "--node", "0x80", self.good)
        self.refused("'x': not a number", "--node", "x", self.good)
        self.refused("--node: a node-ID given twice", "--node", "5", "--node", "0x05", self.good)
        self.refused("--timeout: 0.5 to 3600 s", "--node", "5", "--timeout", "0.1", self.good)
        bad = self.dir / "bad.img"
        bad.write_bytes(image(crc=1))
        self.refused(f"{bad}: CRC-32", "--node", "5", bad)
        bad.write_bytes(b"\x7fELF" + bytes(100))
        self.refused(f"{bad}: magic b'\\x7fELF', not b'COIM': not an image", "--node", "5", bad)
        self.refused("No such file", "--node", "5", self.dir / "none.img")
        twin = self.dir / "twin.img"
        twin.write_bytes(image(pid=7))
        self.refused(f"{twin} and {self.good}: both for device type 0x0008019a", "--node", "5",
                     self.good, twin)


if __name__ == "__main__":
    unittest.main()
