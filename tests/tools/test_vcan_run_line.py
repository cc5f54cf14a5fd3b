"""tools/vcan-run and User-Mode Linux's kernel command line, on any host:
a stand-in for linux.uml (first on PATH) reads its arguments as UML and
the kernel do, and runs the command as vcan-run's init would, without CAN
(it runs neither init itself nor the probe's poweroff). The real thing is
tests/integration/test_vcan_run.py, which needs a host where UML runs.

UML joins its arguments with blanks into the kernel command line; the
kernel splits that at white space outside double quotes (its isspace()
takes byte A0h too, Latin-1's no-break space), and takes quotes off a
value (lib/cmdline.c, next_arg). A work directory path with any of those
left init= naming nothing: UML stopped, the probe failed the same way, and
vcan-run answered 77, ctest's skip, for a fault of its own."""
import os
import pathlib
import subprocess
import sys
import tempfile
import textwrap
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
VCAN_RUN = str(ROOT / "tools" / "vcan-run")

FAKE_UML = textwrap.dedent('''\
    #!{python}
    import os, subprocess, sys

    SPACE = b" \\t\\n\\v\\f\\r\\xa0"

    def next_arg(line):
        """(param, value or None, rest): the kernel's next_arg()."""
        quoted = in_quote = line[:1] == b'"'
        if quoted:
            line = line[1:]
        i, equals = 0, 0
        while i < len(line):
            if line[i] in SPACE and not in_quote:
                break
            if equals == 0 and line[i:i + 1] == b"=":
                equals = i
            if line[i:i + 1] == b'"':
                in_quote = not in_quote
            i += 1
        word, rest = line[:i], line[i + 1:]
        if quoted and word.endswith(b'"'):
            word = word[:-1]
        if not equals:
            return word, None, rest.lstrip(SPACE)
        value = word[equals + 1:]
        if value.startswith(b'"'):
            value = value[1:]
            if value.endswith(b'"'):
                value = value[:-1]
        return word[:equals], value, rest.lstrip(SPACE)

    line = b" ".join(os.fsencode(a) for a in sys.argv[1:]).lstrip(SPACE)
    params = {{}}
    while line:
        param, value, line = next_arg(line)
        params.setdefault(param, value)
    init = params.get(b"init") or b""
    with open(os.environ["FAKE_UML_LOG"], "ab") as log:
        log.write(init + b"\\n")
    if not os.path.isfile(init):
        sys.exit(1)  # the kernel: "Requested init ... failed", a panic
    t = os.path.dirname(init)
    if os.path.basename(init) == b"probe":  # vcan-run's bare boot
        open(os.path.join(t, b"probe-ok"), "w").write("ok\\n")
        sys.exit(0)
    # As init runs the command (its script "run"), CAN left out.
    rc = subprocess.call(["/bin/bash", os.path.join(t, b"run")], stdin=subprocess.DEVNULL)
    open(os.path.join(t, b"rc"), "w").write(f"{{rc}}\\n")
    ''').format(python=sys.executable)


class KernelLine(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)
        self.top = pathlib.Path(self.tmp.name)
        bin_dir = self.top / "bin"
        bin_dir.mkdir()
        uml = bin_dir / "linux.uml"
        uml.write_text(FAKE_UML)
        uml.chmod(0o755)
        self.log = self.top / "inits"
        self.env = dict(os.environ, VCAN_RUN_MODE="uml", FAKE_UML_LOG=str(self.log),
                        PATH=f"{bin_dir}:{os.environ['PATH']}")

    def run_in(self, tmpdir):
        """vcan-run of a command that prints its TMPDIR and exits 7, with
        TMPDIR=tmpdir: its result and the init paths the kernel read."""
        tmpdir.mkdir(parents=True)
        p = subprocess.Popen([VCAN_RUN, "bash", "-c", 'echo "$TMPDIR"; exit 7'],
                             env=dict(self.env, TMPDIR=str(tmpdir)), stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE)
        out, err = p.communicate(timeout=60)
        inits = self.log.read_bytes().splitlines() if self.log.exists() else []
        self.log.unlink(missing_ok=True)
        return p, out, err.decode(errors="replace"), inits

    def test_a_plain_tmpdir_holds_the_work_directory(self):
        d = self.top / "plain"
        p, out, err, inits = self.run_in(d)
        self.assertEqual(p.returncode, 7, err)
        self.assertEqual(out, os.fsencode(d) + b"\n")
        self.assertEqual(len(inits), 1, inits)
        self.assertTrue(inits[0].startswith(os.fsencode(d) + f"/vcan-run.{p.pid}.".encode()),
                        inits)
        self.assertEqual(list(d.iterdir()), [])

    def test_a_tmpdir_the_line_cannot_carry(self):
        # A blank, a quote, U+00A0 (its UTF-8 holds byte A0h), a tab, and
        # a letter outside ASCII (carried, but not a plain character).
        for name in ("a b", 'a"b', "a\u00a0b", "a\tb", "caf\u00e9"):
            with self.subTest(name=name):
                d = self.top / name
                p, out, err, inits = self.run_in(d)
                self.assertNotEqual(p.returncode, 77, err)
                self.assertEqual(p.returncode, 7, err)
                self.assertNotIn("SKIPPED", err)
                self.assertEqual(out, os.fsencode(d) + b"\n")  # the command's TMPDIR as given
                self.assertEqual(len(inits), 1, inits)
                self.assertTrue(inits[0].startswith(f"/tmp/vcan-run.{p.pid}.".encode()), inits)
                self.assertEqual(list(d.iterdir()), [])
                self.assertEqual(list(pathlib.Path("/tmp").glob(f"vcan-run.{p.pid}.*")), [])


if __name__ == "__main__":
    sys.exit(unittest.main())
