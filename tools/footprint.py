"""Print the MCU footprint table (see tools/footprint).
The shares split the flash bytes by the source file each function or
constant of the final image comes from (nm -l reads it from the debug
information, which is not loaded into flash; link-time optimisation makes
the linker map useless for this): src/ (the stack), od/ (dictionaries and
product logic), the rest (board, main loop, libgcc, padding)."""
import re
import subprocess
import sys
from pathlib import Path

from stack_depth import depth

# DST X730 on the Nucleo's Cortex-M0. Flash was 10 KB (10 240 B) until the
# store erased its next slot ahead so that no SDO answer waits for a flash
# erase (co_store.h): that costs the X730 about 170 B it did not have, so
# the target was 10 368 B (10.125 KiB), and program download's application
# side (its 1F5xh objects, the hand-over to the bootloader: co_progdl.h)
# is given 128 B more: 10 496 B. RAM stays 1 KB with the stack.
TARGET_FLASH, TARGET_RAM = 10496, 1024
TARGET_BOARD = "nucleo-f042k6"
# The Cortex-M0 boards' bootloader (boot.elf, where built): the first 4 KiB
# of flash (docs/program-download.md, "Bootloaders and flash layouts").
BOOT_FLASH = 4096
# RAM of the Cortex-M0 boards: every image's RAM and worst-case stack must fit.
BOARD_RAM = {"nucleo-f042k6": 6 * 1024,  # STM32F042K6
             "microbit": 16 * 1024}  # nRF51822


ROOT = Path(__file__).resolve().parents[1]
SOURCES = sorted(ROOT.glob("src/*.c")) + sorted(ROOT.glob("od/**/*.c")) + sorted(ROOT.glob("boards/**/*.c"))


def origin_of(path):
    """stack, od or board, from a source path."""
    parts = Path(path).parts
    if ("src" in parts or "include" in parts) and "boards" not in parts:
        return "stack"  # include/: the stack's inline functions
    if "od" in parts:
        return "od"
    return "board"


def defined_in(name):
    """Where a symbol nm has no line for (constant tables) is defined."""
    pat = re.compile(r"\b" + re.escape(name) + r"\b\s*(\[[^]]*\])*\s*=")
    for src in SOURCES:
        if pat.search(src.read_text()):
            return str(src)
    return None


def shares(elf, nm_tool, flash):
    """Flash bytes by origin: stack, od, board (the rest)."""
    out = {"stack": 0, "od": 0, "board": 0}
    lines = subprocess.run([nm_tool, "-l", "-S", str(elf)], check=True, capture_output=True,
                           text=True).stdout.splitlines()
    seen = set()
    for line in lines:
        m = re.match(r"^([0-9a-f]+) ([0-9a-f]+) ([TtRrDd]) (\S+)(?:\t(\S+):\d+)?$", line)
        if not m or m.group(1) in seen:
            continue  # no size, not in flash (.bss), or an alias of bytes counted
        seen.add(m.group(1))
        size, name, path = int(m.group(2), 16), m.group(4), m.group(5)
        if name.startswith("__compound_literal"):
            path = "od/"  # only the dictionaries' limits and hooks (CO_EXT) are ones
        elif path is None:
            path = defined_in(name.split(".")[0])
        if path is not None:
            out[origin_of(path)] += size
    out["board"] = flash - out["stack"] - out["od"]  # board code, libgcc, padding
    return out


def main(argv):
    check = "--check" in argv
    argv = [a for a in argv if a != "--check"]
    failed = False
    overflow = False
    for board, size_tool, title in zip(argv[0::3], argv[1::3], argv[2::3]):
        build = f"build-{board}"
        print(f"\n{title}")
        print(f"{'product ID':<18} {'flash':>7} {'RAM':>6} {'stack':>7} {'od':>6} {'board':>6}"
              f" {'SP max':>7}")
        # The images without a bootloader (fw-ID.elf): the applications
        # under it (fw-ID-app.elf) are the same code at another address.
        # Then the bootloader (boot.elf), where the board builds it.
        elfs = [e for e in sorted(Path(build, "bin").glob("fw-*.elf")) if not e.stem.endswith("-app")]
        elfs += [e for e in [Path(build, "bin", "boot.elf")] if e.exists()]
        for elf in elfs:
            pid = elf.stem[3:] if elf.stem != "boot" else "(bootloader)"
            text, data, bss = map(int, subprocess.run([size_tool, str(elf)], check=True,
                                  capture_output=True, text=True).stdout.splitlines()[1].split()[:3])
            s = shares(elf, size_tool.replace("-size", "-nm"), text + data)
            arm = "arm" in size_tool
            sp = depth(elf)[0] if arm else None  # the analysis reads Thumb code only
            print(f"{pid:<18} {text + data:>7} {data + bss:>6} {s['stack']:>7} {s['od']:>6} {s['board']:>6}"
                  f" {sp if sp is not None else '-':>7}")
            if arm and data + bss + sp > BOARD_RAM[board]:
                print(f"footprint: {pid} needs {data + bss + sp} bytes of RAM with its stack",
                      file=sys.stderr)
                overflow = True
            if check and arm and elf.stem == "boot" and text + data > BOOT_FLASH:
                print(f"footprint: the {board} bootloader has {text + data} bytes of flash, "
                      f"more than its {BOOT_FLASH}", file=sys.stderr)
                overflow = True  # said here; the X730's message below is not its
            if check and board == TARGET_BOARD and pid.startswith("dst-x730-"):
                failed |= text + data > TARGET_FLASH or data + bss + sp > TARGET_RAM
    if overflow:
        return 1
    if check and failed:
        print("footprint: a DST X730 image misses its target (10 496 B flash, 1 KB RAM with"
              " the stack)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
