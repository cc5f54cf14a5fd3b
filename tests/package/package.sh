#!/bin/sh
# tests/package/package.sh MODE SOURCE CMAKE GENERATOR: the stack as a
# library (docs/library.md), in a temporary directory each time.
#   find_package_host  build and install this tree (host), then build
#                      examples/my-sensor against the prefix and run it
#                      (--help; a missing interface is a clear error),
#                      compile a program with pkg-config's flags, link one
#                      on the registry and the Linux port that calls no
#                      lp_* function, and add a Debug install to the
#                      prefix: its own .pc file, the first one kept
#   find_package_m0    the same for the Cortex-M0 (cmake/arm-none-eabi.cmake):
#                      the stack and the Nucleo board installed, my-sensor's
#                      .elf built with them, its size printed; a host
#                      project refuses that installation
#   add_subdirectory   a parent project links canopen::stack; the tree's
#                      program and tests are not part of its build
# A missing tool fails the test, naming it.
set -eu
mode=$1 src=$2 cmake=$3 gen=$4
fail() { echo "package.$mode: $*" >&2; exit 1; }
need() { for t in "$@"; do command -v "$t" >/dev/null || fail "$t is missing (tools/setup installs it)"; done; }
need "$cmake" cc
tmp=$(mktemp -d "${TMPDIR:-/tmp}/co-package.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
jobs=${CO_PACKAGE_JOBS:-2}
cfg() { "$cmake" -G "$gen" --no-warn-unused-cli -Wno-dev "$@" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; fail "configure failed: $*"; }; }
bld() { "$cmake" --build "$@" -j "$jobs" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; fail "build failed: $*"; }; }
inst() { "$cmake" --install "$1" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; fail "install failed: $1"; }; }
ex=$src/examples/my-sensor

case $mode in
find_package_host)
  need pkg-config
  # A prefix with a blank in its name: the package and its .pc file find
  # their files from their own place, whatever it is called.
  cfg -S "$src" -B "$tmp/b" -DCO_BUILD_PROGRAM=OFF -DCO_BUILD_TESTS=OFF \
    -DCMAKE_INSTALL_PREFIX="$tmp/an install"
  bld "$tmp/b"
  inst "$tmp/b"
  cfg -S "$ex" -B "$tmp/ex" -DCMAKE_PREFIX_PATH="$tmp/an install"
  bld "$tmp/ex"
  "$tmp/ex/my-sensor" --help | grep -q '^usage: my-sensor' || fail "my-sensor --help: no usage"
  rc=0
  "$tmp/ex/my-sensor" no-such-can0 2>"$tmp/err" || rc=$?
  [ "$rc" = 1 ] || fail "my-sensor no-such-can0: exit $rc, not 1"
  grep -q '^my-sensor: no-such-can0: ' "$tmp/err" || { cat "$tmp/err" >&2; fail "my-sensor no-such-can0: no clear error"; }
  echo "my-sensor no-such-can0: $(grep '^my-sensor' "$tmp/err")"
  flags=$(PKG_CONFIG_PATH="$tmp/an install/lib/pkgconfig" pkg-config --cflags --libs canopen_sensors) ||
    fail "pkg-config canopen_sensors failed"
  echo "pkg-config --cflags --libs canopen_sensors: $flags"
  # The flags as a shell reads them: pkg-config escapes the prefix's blank.
  eval "cc -std=c11 -Wall -Wextra -Werror \"\$src/tests/package/tiny.c\" -o \"\$tmp/tiny\" $flags" ||
    fail "the pkg-config program does not build"
  "$tmp/tiny" || fail "the pkg-config program fails"
  # A program on the registry and the Linux port, as docs/library.md
  # links them, that calls no lp_* function: the port's archive comes
  # before the stack's on its link line, and the stack calls the port.
  mkdir -p "$tmp/rp"
  cp "$src/tests/package/registry_port.c" "$tmp/rp/"
  cat >"$tmp/rp/CMakeLists.txt" <<'EOT'
cmake_minimum_required(VERSION 3.20)
project(registry_port C)
find_package(canopen_sensors 0.1 CONFIG REQUIRED)
add_executable(registry_port registry_port.c)
target_link_libraries(registry_port PRIVATE canopen::registry canopen::linux_port)
EOT
  cfg -S "$tmp/rp" -B "$tmp/rp/b" -DCMAKE_PREFIX_PATH="$tmp/an install"
  bld "$tmp/rp/b"
  "$tmp/rp/b/registry_port" | grep -q '^jd2xxx: node-ID 0x' || fail "the registry and port program fails"
  # A Debug install into the same prefix: its libraries are
  # libcanopen_<name>d.a, and its .pc file, canopen_sensorsd.pc, names
  # them; the first install's canopen_sensors.pc stays and still links.
  pc="$tmp/an install/lib/pkgconfig"
  before=$(cat "$pc/canopen_sensors.pc")
  case $flags in
  *-lcanopen_product\ *-lcanopen_stack*) ;;
  *) fail "canopen_sensors.pc: not the libraries of its build: $flags" ;;
  esac
  cfg -S "$src" -B "$tmp/bd" -DCMAKE_BUILD_TYPE=Debug -DCO_BUILD_PROGRAM=OFF -DCO_BUILD_TESTS=OFF \
    -DCMAKE_INSTALL_PREFIX="$tmp/an install"
  bld "$tmp/bd"
  inst "$tmp/bd"
  [ "$(cat "$pc/canopen_sensors.pc")" = "$before" ] || fail "the Debug install replaced canopen_sensors.pc"
  dflags=$(PKG_CONFIG_PATH="$pc" pkg-config --cflags --libs canopen_sensorsd) ||
    fail "pkg-config canopen_sensorsd (the Debug install's) failed"
  echo "pkg-config --cflags --libs canopen_sensorsd: $dflags"
  case $dflags in
  *-lcanopen_productd\ *-lcanopen_stackd*) ;;
  *) fail "canopen_sensorsd.pc: not the Debug libraries: $dflags" ;;
  esac
  eval "cc -std=c11 -Wall -Wextra -Werror \"\$src/tests/package/tiny.c\" -o \"\$tmp/tiny-d\" $dflags" ||
    fail "the pkg-config program does not build with canopen_sensorsd"
  "$tmp/tiny-d" || fail "the pkg-config program fails with canopen_sensorsd"
  rm "$tmp/tiny"
  eval "cc -std=c11 -Wall -Wextra -Werror \"\$src/tests/package/tiny.c\" -o \"\$tmp/tiny\" $flags" ||
    fail "the pkg-config program no longer builds after the Debug install"
  "$tmp/tiny" || fail "the pkg-config program fails after the Debug install"
  ;;
find_package_m0)
  need arm-none-eabi-gcc arm-none-eabi-size
  # As an MCU product installs it: the sizes its dictionary needs.
  cfg -S "$src" -B "$tmp/b" -DCMAKE_TOOLCHAIN_FILE="$src/cmake/arm-none-eabi.cmake" \
    -DCO_BUILD_IMAGES=OFF -DCMAKE_INSTALL_PREFIX="$tmp/prefix" \
    "-DCO_STACK_DEFINITIONS=CO_TPDO_MAX=1u;CO_SDO_BUF=4u;CO_EMCY_HIST_MAX=0u;CO_EMCY_ACTIVE_MAX=1u;CO_INCL_CIRCULAR=0"
  bld "$tmp/b"
  inst "$tmp/b"
  cfg -S "$ex" -B "$tmp/ex" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
    -DCMAKE_TOOLCHAIN_FILE="$tmp/prefix/share/canopen_sensors/arm-none-eabi.cmake"
  bld "$tmp/ex"
  [ -f "$tmp/ex/my-sensor.elf" ] || fail "no my-sensor.elf"
  arm-none-eabi-size "$tmp/ex/my-sensor.elf"
  # A host project does not take the Cortex-M0 installation.
  if "$cmake" -G "$gen" -S "$ex" -B "$tmp/ex-host" -DCMAKE_PREFIX_PATH="$tmp/prefix" >"$tmp/log" 2>&1; then
    fail "a host build found the Cortex-M0 package"
  fi
  grep -q 'canopen_sensors' "$tmp/log" || { cat "$tmp/log" >&2; fail "the refusal does not name the package"; }
  ;;
add_subdirectory)
  mkdir -p "$tmp/parent"
  cp "$src/tests/package/tiny.c" "$tmp/parent/"
  cat >"$tmp/parent/CMakeLists.txt" <<EOT
cmake_minimum_required(VERSION 3.20)
project(parent C)
enable_testing()
add_subdirectory("$src" canopen)
add_executable(tiny tiny.c)
target_link_libraries(tiny PRIVATE canopen::stack canopen::product)
add_test(NAME tiny COMMAND tiny)
EOT
  cfg -S "$tmp/parent" -B "$tmp/b"
  bld "$tmp/b"
  "$tmp/b/tiny" || fail "the parent's program fails"
  # The parent's "all" built what it links, nothing else of this tree.
  for lib in libcanopen_registry.a libcanopen_linux_port.a libcanopen_family_dst.a; do
    if [ -n "$(find "$tmp/b/canopen" -name "$lib")" ]; then
      fail "the parent's build made $lib, which it does not link"
    fi
  done
  for t in canopen-sensor co_firmware co_firmware_test test_dst_manual bench fw-dst-x730-xy10; do
    if "$cmake" --build "$tmp/b" --target "$t" >/dev/null 2>&1; then
      fail "the parent's build has the target $t"
    fi
  done
  n=$(cd "$tmp/b" && "$(dirname "$cmake")/ctest" -N | sed -n 's/^Total Tests: //p')
  [ "$n" = 1 ] || fail "the parent's ctest lists $n tests, not its 1"
  [ ! -e "$tmp/b/canopen/bin" ] || fail "the subproject made a bin/ folder"
  ;;
*)
  fail "unknown mode"
  ;;
esac
echo "package.$mode: ok"
