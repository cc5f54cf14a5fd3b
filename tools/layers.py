#!/usr/bin/env python3
"""tools/layers.py [--graph]: the stack's modules must form layers.

A module is src/<m>.c with include/co_<m>.h (src/sdo_*.c and
sdo_internal.h belong to sdo). Module a depends on module b when a's files
include co_<b>.h or use a function, type or object co_<b>.h declares. The
node object (co_node.h, node.c) is the one allowed meeting point: it owns
every module's state and calls them all, and they reach each other's work
through it; co_common.h (shared types) and co_port.h (the board) are no
modules. Among the other modules the graph must have no cycle: exit 1
names each cycle found. --graph prints every edge with the symbols that
make it. Run by ctest (layers.src).
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUTSIDE = {"node", "common", "port"}


def module_of(path):
    stem = path.stem
    if path.suffix == ".h":
        stem = stem[3:] if stem.startswith("co_") else stem
    if stem.startswith("sdo"):
        return "sdo"
    return stem


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", " ", text)


def declared(header_text):
    """Names a header declares at file scope: functions, types, objects, macros."""
    names = set()
    text = strip_comments(header_text)
    for m in re.finditer(r"^[A-Za-z].*?\b(co_\w+)\s*\(", text, re.M):
        names.add(m.group(1))
    for m in re.finditer(r"^#define\s+(co_\w+|CO_\w+)", text, re.M):
        names.add(m.group(1))
    for m in re.finditer(r"\}\s*(co_\w+_t)\s*;", text):
        names.add(m.group(1))
    for m in re.finditer(r"typedef\s+[^;{]*?\b(co_\w+_t)\s*;", text):
        names.add(m.group(1))
    for m in re.finditer(r"\(\s*\*\s*(co_\w+_fn)\s*\)", text):
        names.add(m.group(1))
    for m in re.finditer(r"^extern\s+[^;]*?\b(co_\w+)\s*(?:\[[^\]]*\])?\s*;", text, re.M):
        names.add(m.group(1))
    return names


def main():
    headers = sorted((ROOT / "include").glob("co_*.h"))
    owner = {"co_node_t": "node"}  # forward-declared where needed; co_node.h defines it
    for h in headers:
        for name in declared(h.read_text()):
            owner.setdefault(name, module_of(h))
    files = {}
    for f in sorted((ROOT / "src").glob("*.[ch]")) + headers:
        files.setdefault(module_of(f), []).append(f)
    edges = {}
    for mod, fs in files.items():
        if mod in OUTSIDE:
            continue
        for f in fs:
            text = strip_comments(f.read_text())
            used = set(re.findall(r"\b(?:co|CO)_\w+", text))
            for inc in re.findall(r'#include\s+"co_(\w+)\.h"', f.read_text()):
                used.add(f"#include co_{inc}.h")
                dep = inc
                if dep != mod and dep not in OUTSIDE:
                    edges.setdefault((mod, dep), set()).add(f"{f.name}: #include co_{inc}.h")
            for name in used:
                dep = owner.get(name)
                if dep and dep != mod and dep not in OUTSIDE:
                    edges.setdefault((mod, dep), set()).add(f"{f.name}: {name}")
    if "--graph" in sys.argv[1:]:
        for (a, b), why in sorted(edges.items()):
            print(f"{a} -> {b}: {', '.join(sorted(why))}")
    graph = {}
    for a, b in edges:
        graph.setdefault(a, set()).add(b)
    cycles = []
    state = {}

    def visit(n, path):
        state[n] = 1
        for m in sorted(graph.get(n, ())):
            if state.get(m) == 1:
                cycles.append(path[path.index(m):] + [m])
            elif m not in state:
                visit(m, path + [m])
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n, [n])
    for c in cycles:
        steps = [f"{a} -> {b} ({'; '.join(sorted(edges[(a, b)])[:3])})" for a, b in zip(c, c[1:])]
        print("layers: cycle " + " -> ".join(c) + ":\n  " + "\n  ".join(steps), file=sys.stderr)
    mods = sorted(m for m in files if m not in OUTSIDE)
    if cycles:
        return 1
    print(f"layers: {len(mods)} modules, {len(edges)} dependencies, no cycle outside the node object")
    return 0


if __name__ == "__main__":
    sys.exit(main())
