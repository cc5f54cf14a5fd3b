#!/usr/bin/env python3
"""m0count.py: instructions a Cortex-M0 function executes, per call.

Usage: m0count.py [--qemu QEMU] [--nm NM] [--calls N] [--expect K] ELF FUNCTION

Runs ELF (a bare-metal image for qemu-system-arm's "microbit" machine that
ends itself over semihosting, like the qemu unit tests) with QEMU's
instruction trace: -singlestep makes every translation block one
instruction, -d exec logs one "Trace" line per executed block (its PC is
the second field in brackets) and nochain stops QEMU from jumping block to
block without logging. Checked on QEMU 7.2; from 8.1 the option is
"-accel tcg,one-insn-per-tb=on", chosen by QEMU's version.

A call starts at the line whose PC is FUNCTION's entry address (from the
ELF's symbol table) and ends at the first line back in the function that
made the call (the one whose instruction branched to the entry): what the
function and everything it calls executed, the final return included, the
caller's branch not. Prints "FUNCTION: calls C, instructions T, per call
T // C (min A, max B)". Fails when the image fails, when FUNCTION is never
called, when --calls N is given and C is not N, or when --expect K is given
and a call took other than K instructions.
"""
import argparse
import bisect
import os
import re
import subprocess
import sys
import tempfile
import threading

TRACE = re.compile(rb"^Trace \d+: \S+ \[[0-9a-f]+/([0-9a-f]+)/")


def functions(nm, elf):
    """(start, end, name) of every function symbol, by start address."""
    out = subprocess.run([nm, "-S", "--defined-only", elf], check=True,
                         capture_output=True, text=True).stdout
    funcs = []
    for line in out.splitlines():
        f = line.split()
        if len(f) == 4 and f[2] in ("t", "T", "W"):
            start = int(f[0], 16) & ~1  # Thumb: bit 0 set in the symbol
            funcs.append((start, start + int(f[1], 16), f[3]))
    funcs.sort()
    return funcs


def one_insn_per_tb(qemu):
    """QEMU's option for one instruction per translation block: -singlestep
    until 8.1, which renamed it (and later releases dropped the old name)."""
    out = subprocess.run([qemu, "--version"], check=True, capture_output=True, text=True).stdout
    m = re.search(r"version (\d+)\.(\d+)", out)
    if m and (int(m.group(1)), int(m.group(2))) >= (8, 1):
        return ["-accel", "tcg,one-insn-per-tb=on"]
    return ["-singlestep"]


def count(pcs, entry, funcs):
    """Instructions of each call of the function at entry, in order, and
    the number of instructions traced."""
    starts = [f[0] for f in funcs]

    def owner(pc):
        i = bisect.bisect_right(starts, pc) - 1
        if i >= 0 and funcs[i][0] <= pc < funcs[i][1]:
            return funcs[i][0], funcs[i][1]
        return pc, pc + 2  # no symbol: the instruction itself

    calls = []
    caller = None
    n = 0
    prev = None
    traced = 0
    for pc in pcs:
        traced += 1
        if caller is not None:
            if caller[0] <= pc < caller[1]:
                calls.append(n)
                caller = None
            else:
                n += 1
        elif pc == entry and prev is not None:
            caller = owner(prev)
            n = 1
        prev = pc
    if caller is not None:
        raise SystemExit("m0count: the image ended inside the measured function")
    return calls, traced


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--qemu", default="qemu-system-arm")
    ap.add_argument("--nm", default="arm-none-eabi-nm")
    ap.add_argument("--calls", type=int, help="calls the image must make")
    ap.add_argument("--expect", type=int, help="instructions every call must take")
    ap.add_argument("elf")
    ap.add_argument("function")
    a = ap.parse_args()
    funcs = functions(a.nm, a.elf)
    entries = [f[0] for f in funcs if f[2] == a.function]
    if len(entries) != 1:
        raise SystemExit(f"m0count: {a.function}: {len(entries)} symbols of that name in {a.elf}")
    # The trace goes through a pipe, read as QEMU writes it: a thousand
    # SYNCs are 2.3 million lines, which need not land on disk.
    with tempfile.TemporaryDirectory() as tmp:
        trace = os.path.join(tmp, "trace")
        os.mkfifo(trace)
        with open(os.path.join(tmp, "out"), "w+") as out:
            qemu = subprocess.Popen([a.qemu, "-M", "microbit", "-display", "none", "-monitor", "none",
                                     "-serial", "none", "-semihosting-config", "enable=on,target=native",
                                     *one_insn_per_tb(a.qemu), "-d", "exec,nochain", "-D", trace,
                                     "-kernel", a.elf], stdout=out, stderr=subprocess.STDOUT)
            # Bounded: QEMU is killed after 300 s; and when it ends before
            # opening the trace, opening it here for writing releases the
            # reader below (it reads nothing and the failure is reported).
            def watch():
                try:
                    qemu.wait(timeout=300)
                except subprocess.TimeoutExpired:
                    qemu.kill()
                    qemu.wait()
                try:
                    os.close(os.open(trace, os.O_WRONLY | os.O_NONBLOCK))
                except OSError:
                    pass  # the reader is gone already
            threading.Thread(target=watch, daemon=True).start()
            with open(trace, "rb") as f:
                pcs = (int(m.group(1), 16) for m in map(TRACE.match, f) if m)
                calls, traced = count(pcs, entries[0], funcs)
            status = qemu.wait()
            if status != 0:
                out.seek(0)
                sys.stderr.write(out.read())
                raise SystemExit(f"m0count: {a.elf} failed (exit status {status})")
    if not calls:
        raise SystemExit(f"m0count: {a.function} was never called ({traced} instructions traced)")
    total = sum(calls)
    print(f"{a.function}: calls {len(calls)}, instructions {total}, per call {total // len(calls)}"
          f" (min {min(calls)}, max {max(calls)})")
    if a.calls is not None and len(calls) != a.calls:
        raise SystemExit(f"m0count: {len(calls)} calls, expected {a.calls}")
    if a.expect is not None and any(c != a.expect for c in calls):
        raise SystemExit(f"m0count: calls took {sorted(set(calls))} instructions, expected {a.expect}")


if __name__ == "__main__":
    main()
