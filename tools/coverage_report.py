"""Print the coverage table of tools/coverage from gcovr's JSON summary,
and with --check fail below the gate.

usage: coverage_report.py SUMMARY.json BUILD_DIR MIN_LINES MIN_BRANCHES [--check]

One line per source file of the measured directories (lines executed /
lines, branches taken / branches), a subtotal per directory, the total.
A C file of those directories that no unit test compiles (no .gcno in the
build tree) has no figure at all, so it is named and fails the check:
the figures cover every file or they say which they leave out. A file that
is compiled but has no executable line (a dictionary table) is named as such.
"""
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DIRS = ("src", "od", "boards/common")


def pct(done, total):
    return 100.0 * done / total if total else 100.0


def row(name, lc, lt, bc, bt):
    return (f"{name:<28} {lc:5d}/{lt:<5d} {pct(lc, lt):6.1f} %   "
            f"{bc:5d}/{bt:<5d} {pct(bc, bt):6.1f} %")


def main(argv):
    summary, build, min_lines, min_branches = argv[1], Path(argv[2]), float(argv[3]), float(argv[4])
    check = "--check" in argv[5:]
    files = {f["filename"]: f for f in json.load(open(summary))["files"]}
    compiled = {p.name[: -len(".gcno")] for p in build.rglob("*.gcno")}

    print(f"{'file':<28} {'lines':>11} {'':>8}   {'branches':>11} {'':>8}")
    total = [0, 0, 0, 0]
    missing, tables = [], []
    for d in DIRS:
        sub = [0, 0, 0, 0]
        for src in sorted((ROOT / d).rglob("*.c")):  # od/<family>/ too
            rel = src.relative_to(ROOT).as_posix()
            f = files.get(rel)
            if f is None:
                (tables if src.name in compiled else missing).append(rel)
                continue
            v = [f["line_covered"], f["line_total"], f["branch_covered"], f["branch_total"]]
            print(row(rel, *v))
            sub = [a + b for a, b in zip(sub, v)]
        print(row(f"  {d}/ (all)", *sub))
        print()
        total = [a + b for a, b in zip(total, sub)]
    print(row("TOTAL", *total))
    if tables:
        print("no executable line (tables only): " + ", ".join(tables))
    lines, branches = pct(total[0], total[1]), pct(total[2], total[3])
    ok = True
    if missing:
        print("NOT MEASURED (no unit test compiles it): " + ", ".join(missing))
        ok = False
    if lines < min_lines:
        print(f"line coverage {lines:.1f} % is below {min_lines:g} %")
        ok = False
    if branches < min_branches:
        print(f"branch coverage {branches:.1f} % is below {min_branches:g} %")
        ok = False
    if check:
        print(f"coverage gate (lines >= {min_lines:g} %, branches >= {min_branches:g} %): "
              + ("passed" if ok else "FAILED"))
        return 0 if ok else 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
