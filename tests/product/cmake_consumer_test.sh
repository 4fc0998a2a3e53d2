#!/bin/sh
# The exported CMake package: `cmake --install --component dev` into a
# DESTDIR, then a small project outside the tree (tests/product/consumer)
# configures with find_package(mpm), builds against mpm::core and runs.
# usage: cmake_consumer_test.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -eu
build=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
DESTDIR="$work/root" cmake --install "$build" --prefix /usr --component dev >"$work/install.log"
# lib/ or lib/<multiarch>/, as GNUInstallDirs chose for the prefix at configure time.
config=$(find "$work/root/usr" -name mpmConfig.cmake)
for f in "$config" "$(dirname "$config")/mpmTargets.cmake" "$work/root/usr/include/mpm/core/granger_monitor.hpp" \
         "$(find "$work/root/usr" -name libmpm_core.a)" "$(find "$work/root/usr" -name libmpm_diagnosis.a)"; do
  [ -n "$f" ] && [ -e "$f" ] || { echo "FAIL: not installed: $f"; cat "$work/install.log"; exit 1; }
done
# Both libraries are exported, the diagnosis on top of the monitor.
grep -q "add_library(mpm::diagnosis STATIC IMPORTED)" "$(dirname "$config")/mpmTargets.cmake" ||
  { echo "FAIL: mpm::diagnosis is not exported"; exit 1; }
# The installed interface names no build or source folder and no instruction-set flag.
if grep -n "$src\|$build\|-march" "$(dirname "$config")"/*.cmake; then
  echo "FAIL: the exported targets refer to the build tree or carry -march"; exit 1
fi
cmake -S "$src/tests/product/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/root/usr" \
  -DCMAKE_BUILD_TYPE=Release >"$work/configure.log" 2>&1 || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/consumer" >"$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
out=$("$work/consumer/consumer")
[ "$out" = "dc_gain 2.000000 pole 0.904837" ] || { echo "FAIL: consumer printed '$out'"; exit 1; }
echo "PASS: find_package(mpm) from a DESTDIR install builds and runs a consumer of mpm::core ($out)"
