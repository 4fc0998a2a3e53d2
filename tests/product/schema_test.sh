#!/bin/sh
# Diagnosis reports of cases with different physics (none, gain, actuator,
# saturation, a recorded signal, a changed disturbance model, a diverging
# loop) and every report the rest of the suite left behind, against
# docs/diagnosis.schema.json. usage: schema_test.sh MPM SOURCE_DIR WORK_DIR
set -eu
mpm=$1; src=$2; work=$3
mkdir -p "$work"
reports=""
for case in wood-berry-nominal:wood-berry wood-berry-g21-gain:wood-berry wood-berry-actuator-u2:wood-berry \
            wood-berry-saturation-u1:wood-berry wood-berry-feed-flow:wood-berry \
            wood-berry-unmeasured-feed:wood-berry quad-tank-g32-integrator:quad-tank-4x4; do
  scenario=${case%%:*}; plant=${case##*:}
  "$mpm" simulate --scenario "$scenario" --samples 3000 --seed 1 --out "$work/$scenario.csv" >/dev/null
  "$mpm" diagnose --quiet --plant "$src/config/$plant.yaml" --data "$work/$scenario.csv" --json "$work/$scenario.json"
  reports="$reports $work/$scenario.json"
done
/usr/bin/python3 "$src/tests/product/validate_reports.py" "$src/docs/diagnosis.schema.json" $reports
