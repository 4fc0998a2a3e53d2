#!/usr/bin/env bash
# Long fuzzing runs: builds the libFuzzer targets of tests/fuzz with clang
# (build-fuzz/) and runs each for SECONDS (default 600), one after another,
# growing a corpus kept outside the tree (out/fuzz/<target>/, seeds from
# tests/fuzz/corpus/<target>/). A crash is written to out/fuzz/crash-*; copy
# it into tests/fuzz/corpus/<target>/ with the fix so the suite replays it.
#   scripts/fuzz.sh [SECONDS] [TARGET...]     e.g. scripts/fuzz.sh 3600 csv plant_yaml
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
shift || true
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMPM_FUZZ=ON \
  -DMPM_BUILD_TESTS=OFF -DMPM_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target mpm_fuzzers
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for f in build-fuzz/tests/fuzz/fuzz_*; do [ -x "$f" ] && targets+=("${f##*/fuzz_}"); done
fi
status=0
for t in "${targets[@]}"; do
  mkdir -p "out/fuzz/$t"
  echo "== fuzz_$t for ${seconds} s"
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "build-fuzz/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="out/fuzz/crash-$t-" \
    "out/fuzz/$t" "tests/fuzz/corpus/$t" 2>&1 | grep -E "^(#[0-9]+ +DONE|stat::number_of_executed_units|==[0-9]+==ERROR|SUMMARY)" \
    || status=1
done
exit $status
