#!/bin/sh
# A log that lcm-logger itself recorded (not our writer): `mpm replay`
# publishes a simulated recording over LCM loopback, lcm-logger records it,
# and `mpm diagnose` on the log gives the report it gives on the CSV.
# Run inside tests/daemon/run_isolated.sh (its own network namespace).
# usage: lcm_logger_test.sh MPM SOURCE_DIR WORK_DIR
set -eu
mpm=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work"
plant="$src/config/wood-berry.yaml"
url="udpm://239.255.76.67:7681?ttl=0"  # a port of its own
"$mpm" simulate --scenario wood-berry-g21-gain --samples 3000 --seed 1 --out run.csv >/dev/null
lcm-logger -f --lcm-url="$url" run.lcmlog >logger.out 2>&1 &
logger=$!
trap 'kill $logger 2>/dev/null || true' EXIT
sleep 1
"$mpm" replay --plant "$plant" --data run.csv --rate 400 --transport lcm --lcm-url "$url" \
  --controller column-7 --wait-readers 0 >/dev/null
sleep 1
kill $logger && wait $logger 2>/dev/null || true
"$mpm" diagnose --plant "$plant" --data run.csv --json csv.json --quiet
"$mpm" diagnose --plant "$plant" --data run.lcmlog --json log.json 2>log.err
grep -q "run.lcmlog: LCM log, 3000 samples of MPM_SAMPLE from controller 'column-7' in 3000 events$" log.err || {
  echo "FAIL: the log is not the 3000 samples, in order:"; cat log.err; exit 1; }
cmp csv.json log.json || { echo "FAIL: the report on the log differs from the one on the CSV"; diff csv.json log.json | head; exit 1; }
grep -q '"mismatch": true' log.json
echo "PASS: lcm-logger's log of 3000 samples gives the CSV's report"
