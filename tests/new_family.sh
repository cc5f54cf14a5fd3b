#!/usr/bin/env bash
# tests/new_family.sh SOURCE_DIR: a new family is its folder and one
# declaration. In a copy of the source tree, tools/new-family makes the
# family "demo" from the template (od/skeleton); without any other edit
# the host build then lists its product in the Linux program, builds and
# passes its unit test (also with its fixed MCU config), and the Cortex-M0
# build makes its firmware image. (ctest build.new_family)
set -euo pipefail
src=$(cd "$1" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The tree as git sees it (tracked and new files, no build trees).
git -C "$src" ls-files -z --cached --others --exclude-standard |
  (cd "$src" && tar --null -T - -cf - 2>/dev/null) | tar -xf - -C "$tmp"
cd "$tmp"
tools/new-family demo
cmake -S . -B b -G Ninja -DCO_SANITIZE=OFF >/dev/null
ninja -C b canopen-sensor test_demo test_demo.demo_cfg >/dev/null
b/bin/test_demo
b/bin/test_demo.demo_cfg
b/bin/canopen-sensor --list-products | tee list.txt
grep -q '^demo-incl ' list.txt || { echo "FAIL: demo-incl not in --list-products" >&2; exit 1; }
if grep -q '^skeleton-incl' list.txt; then
  echo "FAIL: the template is listed as a product" >&2; exit 1
fi
if command -v arm-none-eabi-gcc >/dev/null; then
  cmake -S . -B m0 -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake >/dev/null
  ninja -C m0 fw-demo-incl.elf >/dev/null
  arm-none-eabi-size m0/bin/fw-demo-incl.elf
else
  echo "FAIL: arm-none-eabi-gcc missing (tools/setup installs it)" >&2; exit 1
fi
echo "new family: ok"
