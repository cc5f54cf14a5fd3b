"""tools/apidoc and the folder it is given (API_DIR): it replaces only what
it made there and refuses a folder that holds anything else, removing
nothing. Needs doxygen (tools/setup), as tools/apidoc does."""
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
APIDOC = str(ROOT / "tools" / "apidoc")


def apidoc(api_dir):
    return subprocess.run([APIDOC], env=dict(os.environ, API_DIR=str(api_dir)),
                          capture_output=True, text=True, timeout=300)


class ApiDir(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)
        self.top = pathlib.Path(self.tmp.name)

    def test_a_folder_of_other_files_is_refused_and_kept(self):
        # What API_DIR=docs or API_DIR=$HOME names: files of someone's.
        d = self.top / "docs"
        (d / "sub").mkdir(parents=True)
        (d / "notes.md").write_text("mine\n")
        (d / "sub" / "more.md").write_text("mine too\n")
        r = apidoc(d)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(f"API_DIR={d} holds files that apidoc did not make", r.stderr)
        self.assertEqual(sorted(p.relative_to(d).as_posix() for p in d.rglob("*")),
                         ["notes.md", "sub", "sub/more.md"])
        self.assertEqual((d / "notes.md").read_text(), "mine\n")

    def test_a_folder_holding_only_a_hidden_file_is_refused(self):
        d = self.top / "home"
        d.mkdir()
        (d / ".profile").write_text("x\n")
        r = apidoc(d)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual([p.name for p in d.iterdir()], [".profile"])

    def test_a_file_is_refused(self):
        f = self.top / "a-file"
        f.write_text("keep\n")
        r = apidoc(f)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("is not a folder", r.stderr)
        self.assertEqual(f.read_text(), "keep\n")

    def test_a_new_folder_then_a_rerun_replaces_only_its_own(self):
        d = self.top / "new" / "api"
        r = apidoc(d)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue((d / "html" / "index.html").is_file())
        self.assertTrue((d / ".apidoc-output").is_file())
        # A page of a symbol since removed goes; a file of the user's stays.
        (d / "html" / "stale.html").write_text("old\n")
        (d / "mine.txt").write_text("mine\n")
        r = apidoc(d)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue((d / "html" / "index.html").is_file())
        self.assertFalse((d / "html" / "stale.html").exists())
        self.assertEqual((d / "mine.txt").read_text(), "mine\n")

    def test_an_empty_folder_is_taken(self):
        d = self.top / "empty"
        d.mkdir()
        r = apidoc(d)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue((d / "html" / "index.html").is_file())


if __name__ == "__main__":
    sys.exit(unittest.main())
