"""Print the MCU footprint table from the linker maps (see tools/footprint).
The shares split the flash bytes by the source file each input section
came from: src/ (the stack), od/ (dictionaries and product logic), the rest
(board, main loop, libgcc)."""
import re
import subprocess
import sys
from pathlib import Path

TARGET_FLASH, TARGET_RAM = 10 * 1024, 1024  # DST X730 on the Cortex-M0 (issue 4)


ROOT = Path(__file__).resolve().parents[1]
STACK = {p.name for p in (ROOT / "src").glob("*.c")}
OD = {p.name for p in (ROOT / "od").glob("*.c")}


def shares(map_file):
    """Bytes of allocated input sections by origin: stack, od, board."""
    out = {"stack": 0, "od": 0, "board": 0}
    cur = None
    section = None
    for line in map_file.read_text().splitlines():
        if line.startswith("Discarded input sections"):
            cur = "skip"
        if line.startswith("Memory map") or line.startswith("Linker script and memory map"):
            cur = "map"
        if cur != "map":
            continue
        top = re.match(r"^(\.\S+)", line)  # an output section of the image
        if top:
            section = top.group(1)
        m = re.match(r"^ ?(\.\S+)?\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S+)$", line)
        if not m or section not in (".isr_vector", ".text", ".data"):
            continue  # flash only: .bss is RAM, the rest is not loaded
        size, origin = int(m.group(3), 16), m.group(4)
        # "lib.a(name.c.obj)": the source file's name decides.
        name = re.sub(r"\.(obj|o)\)?$", "", origin.split("(")[-1])
        if name in STACK:
            out["stack"] += size
        elif name in OD:
            out["od"] += size
        else:
            out["board"] += size  # board files, the main loop, libgcc
    return out


def main(argv):
    check = "--check" in argv
    argv = [a for a in argv if a != "--check"]
    failed = False
    for build, size_tool, title in zip(argv[0::3], argv[1::3], argv[2::3]):
        print(f"\n{title}")
        print(f"{'product ID':<18} {'flash':>7} {'RAM':>6} {'stack':>7} {'od':>6} {'board':>6}")
        for elf in sorted(Path(build, "bin").glob("fw-*.elf")):
            pid = elf.stem[3:]
            text, data, bss = map(int, subprocess.run([size_tool, str(elf)], check=True,
                                  capture_output=True, text=True).stdout.splitlines()[1].split()[:3])
            s = shares(elf.with_suffix(".map"))
            print(f"{pid:<18} {text + data:>7} {data + bss:>6} {s['stack']:>7} {s['od']:>6} {s['board']:>6}")
            if check and "arm" in size_tool and pid == "dst-x730-xy30":
                failed |= text + data > TARGET_FLASH or data + bss > TARGET_RAM
    if check and failed:
        print("footprint: the DST X730 misses its target (10 KB flash, 1 KB RAM)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
