#!/usr/bin/env bash
# tests/new_family.sh SOURCE_DIR: a new family is its folder and one
# declaration. In a copy of the source tree, tools/new-family makes the
# family "demo" from the template (od/skeleton); without any other edit
# the host build then lists its product in the Linux program (with its
# family and MCU config in --list-products --json), builds and passes its
# unit test (also with its fixed MCU config), the integration suite has
# its facts and runs it in CI on every target, tools/demo.py has a session
# for it and tools/emu knows its image, and the Cortex-M0 build makes its
# firmware image. Then broken declarations must fail the configure with a
# message naming the mistake. (ctest build.new_family)
# The Python checks take the venv tools/setup makes ($CO_PYTHON, else
# SOURCE_DIR/build/venv).
set -euo pipefail
src=$(cd "$1" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The tree as git sees it (tracked and new files), without any build tree
# (a directory holding a CMakeCache.txt) a developer keeps in it.
skip=$(cd "$src" && find . -name CMakeCache.txt -not -path './.git/*' -printf '%h\n' | sed 's#^\./##')
git -C "$src" ls-files -z --cached --others --exclude-standard |
  { if [ -n "$skip" ]; then grep -zv -F -f <(printf '%s/\n' $skip); else cat; fi; } |
  (cd "$src" && tar --null -T - -cf - 2>/dev/null) | tar -xf - -C "$tmp"
cd "$tmp"
tools/new-family demo
# Twice: the family exists (not a "header clash" with its own header).
if out=$(tools/new-family demo 2>&1); then
  echo "FAIL: tools/new-family demo accepted twice" >&2; exit 1
fi
[ "$out" = "new-family: family 'demo' exists already (od/demo); choose another name" ] ||
  { echo "FAIL: tools/new-family demo twice said: $out" >&2; exit 1; }
cmake -S . -B .nf-host -G Ninja -DCO_SANITIZE=OFF >/dev/null
ninja -C .nf-host canopen-sensor test_demo test_demo.demo_cfg >/dev/null
.nf-host/bin/test_demo
.nf-host/bin/test_demo.demo_cfg
.nf-host/bin/canopen-sensor --list-products | tee list.txt
grep -q '^demo-incl ' list.txt || { echo "FAIL: demo-incl not in --list-products" >&2; exit 1; }
if grep -q '^skeleton-incl' list.txt; then
  echo "FAIL: the template is listed as a product" >&2; exit 1
fi
py=${CO_PYTHON:-$src/build/venv/bin/python}
[ -x "$py" ] || { echo "FAIL: $py missing (tools/setup makes it)" >&2; exit 1; }
CANOPEN_SENSOR=$PWD/.nf-host/bin/canopen-sensor "$py" - <<'PY'
import dataclasses, importlib.machinery, importlib.util, json, os, subprocess, sys
binary = os.environ["CANOPEN_SENSOR"]
listed = json.loads(subprocess.run([binary, "--list-products", "--json"], check=True,
                                   capture_output=True, text=True).stdout)
p = {q["id"]: q for q in listed}["demo-incl"]
want = {"family": "demo", "template": False, "mcu_image": True, "mcu_config": "demo_cfg"}
assert {k: p[k] for k in want} == want, p
# The integration suite: the template's facts at the product's node-ID, in
# CI on every target.
sys.path[:0] = ["tests/integration", "tools"]
import facts
f = facts.PRODUCTS["demo-incl"]
assert (f.family, f.nodes) == ("demo", tuple(p["default_node_ids"])), f
assert f == dataclasses.replace(facts.TEMPLATE, family="demo", nodes=f.nodes)
assert all("demo-incl" in ids for ids in facts.CI_PRODUCTS.values()), facts.CI_PRODUCTS
# The demo: a session from the product's inputs and faults.
import demo
d = demo.family_of("demo-incl")
assert d.steps[:3] == ["set x=0", "set x=12.5", "fault sensor on"], d.steps
# tools/emu: an MCU image of that ID is one it runs.
loader = importlib.machinery.SourceFileLoader("emu", "tools/emu")
emu = importlib.util.module_from_spec(importlib.util.spec_from_loader("emu", loader))
loader.exec_module(emu)
assert "demo-incl" in emu.product_ids()
print("new family: in --list-products --json, facts.py, CI_PRODUCTS, tools/demo.py, tools/emu")
PY
command -v arm-none-eabi-gcc >/dev/null ||
  { echo "FAIL: arm-none-eabi-gcc missing (tools/setup installs it)" >&2; exit 1; }
cmake -S . -B .nf-m0 -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake >/dev/null
ninja -C .nf-m0 fw-demo-incl.elf >/dev/null
arm-none-eabi-size .nf-m0/bin/fw-demo-incl.elf

# Broken declarations: the configure fails and says what is wrong.
decl=od/demo/family.cmake
cp "$decl" good.cmake
broken() { # what, expected message, sed script
  sed -e "$3" good.cmake > "$decl"
  if cmake -S . -B ".nf-bad" -G Ninja >bad.log 2>&1; then
    echo "FAIL: $1 was accepted" >&2; exit 1
  fi
  grep -q "$2" bad.log || { echo "FAIL: $1: no '$2' in:" >&2; cat bad.log >&2; exit 1; }
  echo "refused: $1"
  rm -rf .nf-bad
}
broken "a product ID twice" "declared twice" 's/demo-incl /inx360d /'
broken "SIZES for an unknown config" "which no PRODUCTS row" 's/^    demo_cfg CO_TPDO/    demo_cgf CO_TPDO/'
broken "an unknown size switch" "is no size switch" 's/CO_SDO_BUF=4u/CO_SDO_BUFF=4u/'
broken "a misspelt keyword" "needs TESTS" 's/^  TESTS /  TEST /'
broken "a test that does not exist" "does not exist" 's/^  TESTS test_demo/  TESTS test_dmeo/'
broken "a source that does not exist" "does not exist" 's/^  SOURCES demo.c/  SOURCES demo.c demo_tables.c/'
broken "a family named unlike its folder" "must be named" 's/^co_family(demo/co_family(demo2/'
broken "no declaration" "must declare its family" 's/^co_family(demo/set(x/;s/)$//'
cp good.cmake "$decl"
echo "new family: ok"
