#!/usr/bin/env bash
# The main job, end to end on a fresh Debian 12 machine: install what is
# missing, build (Release), then reproduce the paper's Wood-Berry G21 x 1.2
# case: simulate it under the MPC, run the online monitor over the recording
# and print the located channel with F, p and gamma beside the paper's figures.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
mkdir -p out
build/daemon/mpm paper --out out
