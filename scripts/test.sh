#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds and runs every test
# twice, as a Release build and as an ASan+UBSan build, then every fuzz target
# for a bounded time (tests/fuzz; 20 s each under CI=true).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
jobs=$(nproc)
status=0

echo "== Release build and tests"
# This machine's build: x86-64-v3 (AVX2, FMA) where the processor has it, the
# monitor's update is ~3.7x faster so; the CMake default stays portable (the .deb).
native=OFF
grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo && native=ON
# Warnings (MPM_STRICT_WARNINGS, on by default) are errors in the suite's
# builds (the tree is clean of them: GCC 12, Release and ASan).
werror=ON
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DMPM_NATIVE_ARCH=$native -DMPM_WERROR=$werror >/dev/null
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs" --timeout 600 || status=1

echo "== ASan+UBSan build and tests"
# -O1 and line tables only (-g1): the instrumented build is most of the
# suite's time (an Eigen-heavy file compiles 4-5x slower than in Release at
# -O2 -g); AddressSanitizer's documentation asks for -O1 or higher, and
# line tables are all its and UBSan's reports need to name file and line.
# Measured on three of the heaviest files: 150/38/34 s at -O2 -g against
# 83/21/18 s so.
sanitizer_flags="-O1 -g1 -DNDEBUG"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMPM_SANITIZER=address,undefined \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$sanitizer_flags" -DCMAKE_C_FLAGS_RELWITHDEBINFO="$sanitizer_flags" \
      -DMPM_BUILD_BENCH=OFF -DMPM_WERROR=$werror >/dev/null
cmake --build build-asan -j"$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j"$jobs" --timeout 900 -LE no-sanitizer || status=1

echo "== Fuzz targets (clang, libFuzzer + ASan/UBSan), a bounded run of each on its corpus"
# Only the libraries the fuzz targets link are built; scripts/fuzz.sh runs longer.
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMPM_FUZZ=ON \
      -DMPM_BUILD_TESTS=OFF -DMPM_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$jobs" --target mpm_fuzzers
ctest --test-dir build-fuzz --output-on-failure -j"$jobs" -L fuzz || status=1

exit $status
