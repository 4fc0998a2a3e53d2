#!/bin/sh
# The long soak of issue 12, outside CI: `mpm bench --soak N` (default 10^8
# samples, about half an hour here) through mpmd's service, in a Release
# build of its own. The suite runs the same soak for 10^6 samples
# (tests/daemon/test_soak.cpp). Usage: scripts/soak.sh [SAMPLES] [SEED]
set -eu
samples=${1:-100000000}
seed=${2:-1}
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MPM_SOAK_BUILD:-$root/build-soak}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j"$(nproc)" --target mpm >/dev/null
exec "$build/daemon/mpm" bench --soak "$samples" --seed "$seed"
