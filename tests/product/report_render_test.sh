#!/bin/sh
# The HTML report of a diagnosed gain mismatch, rendered in headless
# Chromium: every plot drew, no console output (render_report.py); the
# paper's plots of the located loop are there and the live detector's trace
# crosses its threshold where `mpm monitor` raises on the same recording
# (check_report_detector.py); the report states its false-alarm level.
# usage: report_render_test.sh MPM SOURCE_DIR WORK_DIR
set -eu
mpm=$1; src=$2; work=$3
mkdir -p "$work"
"$mpm" simulate --scenario wood-berry-nominal --edit y2.u1.gain=1.5 --samples 3000 --seed 5 --out "$work/run.csv" >/dev/null
"$mpm" diagnose --quiet --plant "$src/config/wood-berry.yaml" --data "$work/run.csv" --json "$work/report.json" \
  --html "$work/report.html"
grep -q '"physics": "gain"' "$work/report.json"
# The level the report was made at, in both products.
grep -q '"alpha": 0.001,' "$work/report.json"
grep -q 'false-alarm level 0.001 per look' "$work/report.html"
"$mpm" monitor --plant "$src/config/wood-berry.yaml" --data "$work/run.csv" --json >"$work/monitor.json"
/usr/bin/python3 "$src/tests/product/check_report_detector.py" "$work/report.html" "$work/monitor.json"
/usr/bin/python3 "$src/tests/product/render_report.py" "$work/report.html" "$work/report.png"
