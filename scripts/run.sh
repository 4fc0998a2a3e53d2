#!/usr/bin/env bash
# The main job, end to end on a fresh Debian 12 machine: install what is
# missing, build (Release), then
#  1. the mission (scripts/mission.py): simulate a gain mismatch the MPC
#     hides (control-error variance beside the matched plant's), diagnose it
#     (located channel, physics word, fitted gain beside the true one,
#     held-out improvement), write the corrected plant and the HTML report,
#     and diagnose again with the corrected plant;
#  2. the paper's table (`mpm paper`): every case study under the MPC, the
#     located channels with F, p and gamma beside the paper's figures.
# Everything written goes to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
# This machine's build: x86-64-v3 (AVX2, FMA) where the processor has it, the
# monitor's update is ~3.7x faster so; the CMake default stays portable (the .deb).
native=OFF
grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo && native=ON
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DMPM_NATIVE_ARCH=$native >/dev/null
cmake --build build -j"$(nproc)"
mkdir -p out/mission
echo
echo "=== The mission: a concealed mismatch, located, named, fitted, written back ==="
/usr/bin/python3 scripts/mission.py build/daemon/mpm config/wood-berry.yaml out/mission
echo
echo "=== The paper's case studies (Chen, Xie & Su 2021) ==="
build/daemon/mpm paper --out out
