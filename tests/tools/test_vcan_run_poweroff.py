"""tools/vcan-run when User-Mode Linux does not power off after the command,
on any host: a stand-in for linux.uml (first on PATH) leads its own
session as UML does, runs the command as vcan-run's init would (no CAN),
writes its exit status, and then hangs instead of powering off. vcan-run
must end by itself within VCAN_RUN_POWEROFF seconds, say why, report the
command's status, and leave no process of the stand-in behind. Before the
bound it waited for UML without end (ctest's TIMEOUT, no word of why)."""
import os
import pathlib
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
VCAN_RUN = str(ROOT / "tools" / "vcan-run")

HANGING_UML = textwrap.dedent('''\
    #!{python}
    import os, subprocess, sys, time

    os.setsid()  # UML's first process leads the session of all of its own
    init = next(a[5:] for a in sys.argv[1:] if a.startswith("init="))
    t = os.path.dirname(init)
    if os.path.basename(init) == "probe":  # vcan-run's bare boot
        open(os.path.join(t, "probe-ok"), "w").write("ok\\n")
        sys.exit(0)
    rc = subprocess.call(["/bin/bash", os.path.join(t, "run")], stdin=subprocess.DEVNULL)
    open(os.path.join(t, "rc"), "w").write(f"{{rc}}\\n")
    with open(os.environ["HANGING_UML_PID"], "w") as f:
        f.write(f"{{os.getpid()}}\\n")
    time.sleep(3600)  # a kernel stuck on its way down
    ''').format(python=sys.executable)


class PowerOff(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)
        top = pathlib.Path(self.tmp.name)
        bin_dir = top / "bin"
        bin_dir.mkdir()
        uml = bin_dir / "linux.uml"
        uml.write_text(HANGING_UML)
        uml.chmod(0o755)
        self.pid_file = top / "uml.pid"
        self.env = dict(os.environ, VCAN_RUN_MODE="uml", VCAN_RUN_POWEROFF="2",
                        HANGING_UML_PID=str(self.pid_file), TMPDIR=str(top),
                        PATH=f"{bin_dir}:{os.environ['PATH']}")

    def test_a_uml_that_does_not_power_off_is_ended(self):
        t0 = time.monotonic()
        p = subprocess.run([VCAN_RUN, "bash", "-c", "echo done; exit 7"], env=self.env,
                           capture_output=True, text=True, timeout=60)
        took = time.monotonic() - t0
        self.assertEqual(p.returncode, 7, p.stderr)
        self.assertEqual(p.stdout, "done\n")
        self.assertIn("User-Mode Linux did not power off within 2 s of the command's end: "
                      "killed", p.stderr)
        self.assertLess(took, 15, p.stderr)
        pid = int(self.pid_file.read_text())
        with self.assertRaises(ProcessLookupError, msg="the stand-in UML was left running"):
            os.kill(pid, 0)

    def test_bad_bound_refused(self):
        p = subprocess.run([VCAN_RUN, "true"], env=dict(self.env, VCAN_RUN_POWEROFF="soon"),
                           capture_output=True, text=True, timeout=60)
        self.assertEqual(p.returncode, 2)
        self.assertIn("VCAN_RUN_POWEROFF must be whole seconds", p.stderr)


if __name__ == "__main__":
    sys.exit(unittest.main())
