"""tools/mutate's own pieces: the tokeniser, which mutants a C text gets,
and the stability of their ids (python3 -m unittest, no build needed)."""

import importlib.machinery
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
_loader = importlib.machinery.SourceFileLoader("mutate", os.path.join(ROOT, "tools", "mutate"))
_spec = importlib.util.spec_from_loader("mutate", _loader)
mutate = importlib.util.module_from_spec(_spec)
_loader.exec_module(mutate)

SRC = """\
#include <stdint.h>
#define LIMIT(a, b) ((a) < (b) ? \\
                     (a) : (b))
/* a < b in a comment, 0 and 1 */
static const char *const name = "x < 1 && y";
static const uint8_t table[4] = {1, 2, 3, 5};

int f(int *p, int n)
{
    int *q = p;   // n + 1 in a comment
    char c = '<';
    if (n <= 0 && p != NULL) {
        return 0;
    }
    for (int i = 0; i < n; i++) {
        q[i] = q[i] + (int)table[i & 3];
        if (!q[i]) {
            break;
        }
    }
    g(&q[0], c);
    return n;
}

const void *h(void)
{
    return NULL;
}
"""


def mutants_of(src):
    return mutate.make_mutants("src/x.c", src)


class Tokeniser(unittest.TestCase):
    def test_comments_strings_chars_and_directives_are_not_tokens(self):
        texts = [t.text for t in mutate.tokenise(SRC)]
        self.assertNotIn("LIMIT", texts)       # #define with a continuation line
        self.assertNotIn("include", texts)
        self.assertNotIn("'<'", texts)
        self.assertNotIn('"x < 1 && y"', texts)
        self.assertEqual(texts.count("<"), 1)  # only the for loop's
        self.assertIn("table", texts)

    def test_positions(self):
        toks = mutate.tokenise(SRC)
        le = [t for t in toks if t.text == "<="][0]
        self.assertEqual((le.line, le.col), (12, 11))
        self.assertEqual(SRC[le.start:le.end], "<=")


class Mutants(unittest.TestCase):
    def setUp(self):
        self.ms = mutants_of(SRC)
        self.by_line = {}
        for m in self.ms:
            self.by_line.setdefault(m.line, []).append(m.desc)

    def test_nothing_in_comments_strings_or_directives(self):
        for line in (1, 2, 3, 4, 5, 11):
            self.assertNotIn(line, self.by_line, self.by_line.get(line))

    def test_operators(self):
        self.assertEqual(sorted(self.by_line[12]), sorted([
            "<= -> <", "<= -> >", "<= -> >=", "0 -> 1", "&& -> ||", "!= -> ==",
            "cond -> 1", "cond -> 0", "operand -> 1", "operand -> 0", "operand -> 1", "operand -> 0"]))
        self.assertIn("< -> <=", self.by_line[15])
        self.assertIn("< -> >=", self.by_line[15])
        self.assertIn("< -> >", self.by_line[15])   # swapped
        self.assertIn("++ -> --", self.by_line[15])
        self.assertIn("+ -> -", self.by_line[16])
        self.assertIn("& -> |", self.by_line[16])   # binary &
        self.assertIn("! -> (removed)", self.by_line[17])

    def test_unary_and_declarations_are_left_alone(self):
        # int *q (a declarator) and &q[0] (an address) are not operators
        self.assertNotIn("* -> /", self.by_line.get(10, []))
        self.assertNotIn("& -> |", self.by_line.get(21, []))
        self.assertNotIn(8, self.by_line)           # the parameter list

    def test_constants_in_tables_but_not_array_sizes(self):
        self.assertEqual(sorted(self.by_line[6]), sorted([
            "1 -> 0", "2 -> 3", "2 -> 1", "2 -> 0", "3 -> 4", "3 -> 2", "3 -> 0", "5 -> 6", "5 -> 4",
            "5 -> 0"]))

    def apply(self, src, line, desc, col=None):
        """The text of src with the mutant of line (and column) desc."""
        ms = [m for m in mutants_of(src) if m.line == line and m.desc == desc
              and (col is None or m.col == col)]
        self.assertEqual(len(ms), 1, [(m.line, m.col, m.desc) for m in mutants_of(src) if m.line == line])
        return src[:ms[0].start] + ms[0].repl + src[ms[0].end:]

    def test_conditions_true_and_false(self):
        # if, for and ?: conditions; each operand of && and || on its own
        src = ("int f(int a, int b, int *p)\n{\n"
               "    if (a < b && (p != 0 || b > 2)) {\n"      # line 3
               "        return a ? b : (a + b > 1 ? 1 : 2);\n"  # line 4
               "    }\n"
               "    for (int i = 0; i < b; i++) {\n"          # line 6
               "        p[i] = 0;\n    }\n"
               "    while (1) {\n        break;\n    }\n"     # line 9
               "    return 0;\n}\n")
        self.assertIn("    if (1) {\n", self.apply(src, 3, "cond -> 1"))
        self.assertIn("    if (0) {\n", self.apply(src, 3, "cond -> 0"))
        self.assertIn("if (1 && (p != 0 || b > 2))", self.apply(src, 3, "operand -> 1", 9))
        self.assertIn("if (a < b && (0 || b > 2))", self.apply(src, 3, "operand -> 0", 19))
        self.assertIn("if (a < b && (p != 0 || 1))", self.apply(src, 3, "operand -> 1", 29))
        self.assertIn("return 1 ? b : (a + b > 1 ? 1 : 2);", self.apply(src, 4, "cond -> 1", 16))
        self.assertIn("return a ? b : (0 ? 1 : 2);", self.apply(src, 4, "cond -> 0", 25))
        self.assertIn("for (int i = 0; 0; i++)", self.apply(src, 6, "cond -> 0"))
        # while (1) is true already: only made false
        self.assertIn("while (0)", self.apply(src, 9, "cond -> 0"))
        self.assertNotIn("cond -> 1", [m.desc for m in mutants_of(src) if m.line == 9])

    def test_a_digit_changed_or_dropped(self):
        src = "unsigned f(unsigned x)\n{\n    return (x & 0x7FFu) + 1000u + 3;\n}\n"
        descs = [m.desc for m in mutants_of(src) if m.line == 3]
        for d in ("0x7FFu -> 0x0FFu", "0x7FFu -> 0x70Fu", "0x7FFu -> 0x7F0u", "0x7FFu -> 0x7Fu",
                  "0x7FFu -> 0x800u", "1000u -> 100u", "1000u -> 1001u", "1000u -> 1100u",
                  "3 -> 0", "3 -> 4", "3 -> 2"):
            self.assertIn(d, descs)
        # no value twice, no decimal made octal (0000u, 000u)
        self.assertEqual(len([d for d in descs if d.startswith("1000u")]),
                         len({d for d in descs if d.startswith("1000u")}))
        self.assertFalse([d for d in descs if d.startswith("1000u -> 0") and d != "1000u -> 0u"], descs)

    def test_array_index(self):
        src = ("int f(const int *a, int i)\n{\n    uint8_t buf[8];\n    int m[2][3];\n"
               "    return a[i] + a[0] + (int)buf[i + 1] + m[1][i];\n}\n")
        out = self.apply(src, 5, "[i] -> [0]", 13)
        self.assertIn("return a[0] + a[0]", out)
        self.assertIn("return a[(i) + 1] + a[0]", self.apply(src, 5, "[i] -> [+1]", 13))
        self.assertIn("a[(0) + 1] + (int)", self.apply(src, 5, "[0] -> [+1]"))
        self.assertIn("(int)buf[0] + m", self.apply(src, 5, "[i + 1] -> [0]"))
        self.assertIn("m[1][0]", self.apply(src, 5, "[i] -> [0]", 48))
        # declared sizes are not indices
        self.assertNotIn(3, {m.line for m in mutants_of(src) if m.kind == "index"})
        self.assertNotIn(4, {m.line for m in mutants_of(src) if m.kind == "index"})

    def test_statements(self):
        self.assertIn("return -> (removed)", self.by_line[13])
        self.assertIn("return -> 1", self.by_line[13])   # return 0 -> return 1
        self.assertIn("break -> (removed)", self.by_line[18])
        self.assertIn("stmt -> (removed)", self.by_line[16])
        self.assertIn("stmt -> (removed)", self.by_line[21])
        self.assertIn("return -> 0", self.by_line[22])
        self.assertNotIn("stmt -> (removed)", self.by_line.get(10, []))  # a declaration
        self.assertEqual(self.by_line[27], ["return -> (removed)"])  # NULL is 0 already

    def test_applying_a_mutant(self):
        m = [m for m in self.ms if m.line == 15 and m.desc == "< -> >="][0]
        out = SRC[:m.start] + m.repl + SRC[m.end:]
        self.assertIn("for (int i = 0; i >= n; i++) {", out)
        m = [m for m in self.ms if m.line == 21 and m.kind == "statement"][0]
        out = SRC[:m.start] + m.repl + SRC[m.end:]
        self.assertIn("\n    ;\n    return n;", out)

    def test_ids_survive_unrelated_edits(self):
        moved = SRC.replace("int f(int *p, int n)\n{\n",
                            "int f(int *p, int n)\n{\n    /* new */\n    extra(n);\n")
        before = {m.id: m.desc for m in self.ms}
        after = {m.id: m.desc for m in mutants_of(moved)}
        for i, d in before.items():
            self.assertEqual(after.get(i), d, i)
        self.assertEqual(len(set(before)), len(self.ms))

    def test_identical_lines_get_distinct_ids(self):
        src = "void f(int *a)\n{\n    a[0] = 1;\n    a[0] = 1;\n}\n"
        ids = [m.id for m in mutants_of(src)]
        self.assertEqual(len(ids), len(set(ids)))
        self.assertTrue(any(".1#" in i for i in ids))
        self.assertTrue(all(i.startswith("f@") for i in ids))

    def test_every_project_file_tokenises(self):
        files = mutate.source_files()
        self.assertTrue(any(f.startswith("boards/common/") for f in files))
        for f in files:
            with open(os.path.join(ROOT, f)) as fh:
                ms = mutants_of(fh.read())
            self.assertEqual(len({m.id for m in ms}), len(ms), f)


class UniversalMutator(unittest.TestCase):
    """universalmutator's mutant files made into this tool's mutants: a
    stand-in for its command writes them as it does (<name>.mutant.N.c in
    --mutantDir); the real one runs in `tools/mutate --generator
    universalmutator`."""

    SRC = "int f(int a)\n{\n    /* a < 1 */\n    if (a < 1) {\n        return 0;\n    }\n    return a;\n}\n"

    def mutants(self, texts):
        with tempfile.TemporaryDirectory() as d:
            fake = os.path.join(d, "fake-mutate")
            with open(fake, "w") as fh:
                fh.write("#!%s\nimport sys, os\nd = sys.argv[sys.argv.index('--mutantDir') + 1]\n"
                         "for n, t in enumerate(%r):\n"
                         "    open(os.path.join(d, 'x.mutant.%%d.c' %% n), 'w').write(t)\n"
                         % (sys.executable, texts))
            os.chmod(fake, 0o755)
            return mutate.um_mutants("src/x.c", self.SRC, fake, d)

    def test_changed_inserted_and_removed_lines(self):
        texts = [self.SRC.replace("if (a < 1)", "if (a > 1)"),
                 self.SRC.replace("        return 0;\n", "        return 0;\n        break;\n"),
                 self.SRC.replace("    return a;\n", ""),
                 self.SRC,                                          # unchanged: no mutant
                 self.SRC.replace("if (a < 1)", "if (a > 1)")]      # the same again: one mutant
        ms = self.mutants(texts)
        self.assertEqual([(m.line, m.kind) for m in ms],
                         [(4, "universalmutator"), (5, "universalmutator"), (7, "universalmutator")])
        for m, t in zip(ms, texts):
            self.assertEqual(self.SRC[:m.start] + m.repl + self.SRC[m.end:], t)
        self.assertTrue(ms[0].id.startswith("f@") and "#um:" in ms[0].id, ms[0].id)
        # ids as stable as ours: the same change of the same line after an unrelated edit
        moved = self.SRC.replace("{\n", "{\n    g();\n", 1)
        self.SRC, old = moved, self.SRC
        again = self.mutants([moved.replace("if (a < 1)", "if (a > 1)")])
        self.SRC = old
        self.assertEqual(again[0].id, ms[0].id)


class Merge(unittest.TestCase):
    """--merge: a full run's results with a later re-run's on top."""
    FILE = "src/sync.c"

    def setUp(self):
        with open(os.path.join(ROOT, self.FILE)) as fh:
            self.ms = mutants_of(fh.read())
        for m in self.ms:
            m.file = self.FILE
        self.dir = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.dir.cleanup()

    def write(self, name, statuses):
        path = os.path.join(self.dir.name, name)
        with open(path, "w") as fh:
            json.dump({"seconds": 1.0, "mutants": [dict(m.to_json(), status=s, test=None)
                                                     for m, s in statuses]}, fh)
        return path

    def merge(self, *paths, gate="all=50"):
        return subprocess.run([sys.executable, os.path.join(ROOT, "tools", "mutate"), "--files",
                               self.FILE, "--gate", gate, "--merge"] + list(paths),
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)

    def row(self, out):
        line = [l for l in out.splitlines() if l.startswith(self.FILE + " ")][0]
        return [int(x) for x in line.split()[1:8]]

    def test_a_later_run_wins(self):
        n = len(self.ms)
        first = self.write("full.json", [(m, "survived") for m in self.ms])
        half = self.ms[: n // 2]
        rerun = self.write("rerun.json", [(m, "killed") for m in half])
        # the second half survives, less those the reviewed list calls
        # equivalent (read today, whatever the runs said)
        eq = mutate.read_equivalents()
        n_eq = sum(1 for m in self.ms[n // 2:] if (self.FILE, m.id) in eq)
        r = self.merge(first, rerun)
        score = 100.0 * (n // 2) / (n - n_eq)
        self.assertEqual(r.returncode, 0 if score >= 50 else 1, r.stdout)
        made, compiled, killed, _, survived, equiv, _ = self.row(r.stdout)
        self.assertEqual((made, compiled, killed, survived, equiv),
                         (n, n, n // 2, n - n // 2 - n_eq, n_eq))
        r = self.merge(rerun, first)   # the order matters: the last file wins
        self.assertEqual(self.row(r.stdout)[2], 0)
        self.assertEqual(r.returncode, 1)

    def test_a_mutant_without_a_result_fails_the_gate(self):
        part = self.write("part.json", [(m, "killed") for m in self.ms[1:]])
        r = self.merge(part, gate="all=0")
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("not run", r.stdout)
        self.assertIn(self.ms[0].id, r.stdout)


class Arguments(unittest.TestCase):
    """Mistakes in the arguments stop the tool before it runs anything."""

    def test_gate(self):
        self.assertEqual(mutate.parse_gate("src=95, od = 95 ,boards/common/=90%,all=0"),
                         [("src", 95.0), ("od", 95.0), ("boards/common", 90.0), ("all", 0.0)])
        for bad in ("src", "src=abc", "src=95,", "nosuchdir=90", "ALL=90", "od=101", "od=95=3",
                    "src=95,od=90,src/=80"):
            with self.assertRaises(SystemExit, msg=bad):
                mutate.parse_gate(bad)

    def test_every_usage_error_exits_2_with_its_message(self):
        # the exit status does not depend on which check refuses (argparse's
        # own, or the tool's); 1 is left to a failed gate
        with tempfile.TemporaryDirectory() as d:
            ids = os.path.join(d, "ids.txt")
            with open(ids, "w") as fh:
                fh.write("src/sync.c nosuch@0#0:a:b\n")
            cases = [(["--gate", "src=95,src=90"], "src given twice"),
                     (["--gate", "src=95", "--gate", "src=90"], "src given twice"),
                     (["--gate", "nosuch=9"], "want DIR=PCT"),
                     (["--jobs", "0"], "--jobs wants 1 or more"),
                     (["--sample", "0"], "--sample wants 1 or more"),
                     (["--files", "nosuch.c"], "no file of"),
                     (["--json", os.path.join(d, "no", "x.json")], "cannot write in"),
                     (["--files", "src/sync.c", "--ids", ids, "--list"], "no mutant"),
                     (["--merge", os.path.join(d, "none.json")], "--merge"),
                     (["--generator", "nosuch"], "invalid choice"),
                     (["--nosuchoption"], "unrecognized arguments")]
            for argv, msg in cases:
                r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "mutate")] + argv,
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                   env=dict(os.environ, MUTATE_DIR=d))
                self.assertEqual(r.returncode, 2, (argv, r.stdout))
                self.assertIn(msg, r.stdout, argv)

    def test_ids(self):
        ms = mutants_of(SRC)
        for m in ms:
            m.file = "src/x.c"
        with tempfile.NamedTemporaryFile("w", suffix=".txt") as fh:
            fh.write("# a comment\n\nsrc/x.c %s\n%s\n" % (ms[0].id, ms[3].id))
            fh.flush()
            self.assertEqual([m.id for m in mutate.select_ids(fh.name, ms)], [ms[0].id, ms[3].id])
            fh.write("src/x.c nosuch@0#0:a:b\n")
            fh.flush()
            with self.assertRaises(SystemExit):
                mutate.select_ids(fh.name, ms)
        with self.assertRaises(SystemExit):
            mutate.select_ids("/nonexistent/ids.txt", ms)


if __name__ == "__main__":
    unittest.main()
