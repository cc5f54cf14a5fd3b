"""Worst-case stack depth of a Cortex-M0 image, by static analysis of its
machine code (tools/footprint prints it; usage: stack_depth.py image.elf).

Each function's frame is read from its prologue (push, sub sp); calls are
its bl instructions and its tail branches to other functions. A call
through a pointer (blx) may reach any function whose address is stored in
flash (dictionary hooks, product ops, services): all of them are assumed.
The depth is the deepest chain from reset_handler, plus the deepest
interrupt handler with the 32-byte exception frame the core pushes (the
board's interrupts share one priority, so they do not nest).

A chain that comes back to a function already on it is cut there: the
code has no recursion, and such cycles exist only in this conservative
graph (a write hook that reads through a read hook). The figure is still
an upper bound of every real chain the graph contains.
"""
import re
import subprocess
import sys
from pathlib import Path

EXCEPTION_FRAME = 32


def functions(elf):
    """{name: (address, size)} of the image's functions."""
    out = {}
    nm = subprocess.run(["arm-none-eabi-nm", "-S", str(elf)], check=True, capture_output=True,
                        text=True).stdout
    for line in nm.splitlines():
        m = re.match(r"^([0-9a-f]+) ([0-9a-f]+) [Tt] (\S+)$", line)
        if m:
            out[m.group(3)] = (int(m.group(1), 16) & ~1, int(m.group(2), 16))
    return out


def address_taken(elf, funcs):
    """Functions whose address (with the Thumb bit) is a word in flash."""
    blob = subprocess.run(["arm-none-eabi-objcopy", "-O", "binary", "-j", ".isr_vector", "-j",
                           ".text", "-j", ".data", str(elf), "/dev/stdout"], check=True,
                          capture_output=True).stdout
    words = {int.from_bytes(blob[i:i + 4], "little") for i in range(0, len(blob) - 3, 2)}
    return {name for name, (addr, _) in funcs.items() if addr | 1 in words}


def parse(elf, funcs):
    """{name: (frame bytes, set of callees, calls through a pointer)}."""
    text = subprocess.run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", str(elf)],
                          check=True, capture_output=True, text=True).stdout
    info = {}
    cur = None
    for line in text.splitlines():
        head = re.match(r"^[0-9a-f]+ <(\S+)>:$", line)
        if head:
            cur = head.group(1) if head.group(1) in funcs else None
            if cur is not None:
                info[cur] = [0, set(), False]
            continue
        if cur is None:
            continue
        ins = line.split("\t")[1:] if "\t" in line else []
        if not ins:
            continue
        op = ins[0].strip()
        arg = ins[1].strip() if len(ins) > 1 else ""
        if op == "push":
            info[cur][0] += 4 * len(arg.strip("{}").split(","))
        elif op == "sub" and arg.startswith("sp, #"):
            info[cur][0] += int(arg.split("#")[1], 0)
        elif op.startswith("bl") and not op.startswith("blx"):
            m = re.search(r"<([^>+]+)>", arg)
            if m:
                info[cur][1].add(m.group(1))
        elif op.startswith("blx"):
            info[cur][2] = True
        elif op.startswith("b") and re.search(r"<([^>+]+)>$", arg):
            target = re.search(r"<([^>+]+)>$", arg).group(1)
            if target != cur and target in funcs:
                info[cur][1].add(target)  # a tail call
        elif op == "add" and arg.startswith("sp, r"):
            raise SystemExit(f"stack_depth: {cur} moves sp by a register; cannot bound it")
    return info


def depth(elf):
    funcs = functions(elf)
    info = parse(elf, funcs)
    indirect = address_taken(elf, funcs)
    memo = {}

    def worst(name, path):
        if name in path or name not in info:
            return 0, []  # a cycle of the conservative graph, or code without a frame
        if name in memo:
            return memo[name]
        frame, callees, through_pointer = info[name]
        targets = set(callees) | (indirect if through_pointer else set())
        best, chain = 0, []
        path.add(name)
        for t in sorted(targets):
            d, c = worst(t, path)
            if d > best:
                best, chain = d, c
        path.discard(name)
        memo[name] = (frame + best, [name] + chain)
        return memo[name]

    main_depth, main_chain = worst("reset_handler", set())
    handlers = [n for n in indirect if n.endswith("_handler") and n != "reset_handler"]
    irq_depth, irq_chain = max((worst(h, set()) for h in handlers), default=(0, []))
    return main_depth + irq_depth + EXCEPTION_FRAME, main_chain, irq_chain


def main(argv):
    total, chain, irq = depth(Path(argv[0]))
    print(f"{total} bytes: {' > '.join(chain)}; interrupt: {' > '.join(irq)}")


if __name__ == "__main__":
    main(sys.argv[1:])
