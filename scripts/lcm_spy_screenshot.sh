#!/bin/sh
# An alarm and its physics as lcm-spy shows them: docs/lcm-spy-alarm.png.
#
#   scripts/lcm_spy_screenshot.sh [OUT.png]     (default docs/lcm-spy-alarm.png)
#
# The closed-loop Wood-Berry column under its MPC with G21's gain at 3 x
# nominal (mpm simulate) is replayed into mpmd over LCM (mpm replay); mpmd
# raises u1 -> y2 and publishes the diagnosis of the raised output. LCM's own
# lcm-spy (deploy/mpm-lcm-spy, wrapped by tests/deploy/SpyProbe, which prints
# where its channel rows are) runs on a virtual display (xvfb-run); the
# MPM_ALARM and MPM_DIAGNOSIS rows are double-clicked (xdotool), their
# viewers placed beside the channel table, and the screen saved (ImageMagick
# import). Everything runs in a private network namespace where one can be
# made (tests/daemon/run_isolated.sh). Needs a Release build in $BUILD
# (default build/) and: xvfb xdotool imagemagick openjdk-17-jdk-headless
# liblcm-java libjchart2d-java (the tests' packages, scripts/deps.sh).
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD:-$root/build}
out=${1:-$root/docs/lcm-spy-alarm.png}
case "$out" in /*) ;; *) out=$(pwd)/$out ;; esac

if [ "${MPM_SPY_INNER:-}" != 1 ]; then
  for tool in xvfb-run Xvfb xdotool import java; do
    command -v "$tool" >/dev/null 2>&1 || {
      echo "lcm_spy_screenshot: $tool is missing: apt-get install -y xvfb xdotool imagemagick" \
           "openjdk-17-jdk-headless liblcm-java libjchart2d-java" >&2
      exit 1
    }
  done
  cmake --build "$build" --target mpm mpmd mpm_lcm_jar mpm_spy_probe >/dev/null
  MPM_SPY_INNER=1 BUILD=$build exec sh "$root/tests/daemon/run_isolated.sh" \
    xvfb-run -a -s "-screen 0 1900x1000x24 -nolisten tcp" sh "$0" "$out"
fi

# --- on the virtual display ---
work=$(mktemp -d)
pids=""
cleanup() {
  for p in $pids; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
url="udpm://239.255.76.71:7671?ttl=0"

# Polls a shell condition every 0.2 s for up to $2 seconds.
wait_until() {
  n=0
  until eval "$1"; do
    n=$((n + 1))
    if [ "$n" -gt $(($2 * 5)) ]; then
      echo "lcm_spy_screenshot: timed out waiting for: $1" >&2
      tail -20 "$work/mpmd.err" "$work/spy.err" >&2 || true
      exit 1
    fi
    sleep 0.2
  done
}
# "x y" of a channel's row in lcm-spy's table, from the probe's last report.
row_xy() {
  awk -F'\t' -v ch="$1" '$1 == "row" && $2 == ch { x = $6; y = $7 } $1 == "end" && x != "" { px = x; py = y }
                         END { if (px != "") print px, py }' "$work/spy.out"
}
# Double-clicks a channel's row until its viewer window opens; prints the window id.
open_viewer() {
  wait_until "[ -n \"\$(row_xy $1)\" ]" 60
  tries=0
  while ! xdotool search --name "^$1\$" >/dev/null 2>&1; do
    # shellcheck disable=SC2046
    xdotool mousemove $(row_xy "$1") click --repeat 2 --delay 100 1
    sleep 1
    tries=$((tries + 1))
    [ "$tries" -lt 20 ] || { echo "lcm_spy_screenshot: the $1 viewer did not open" >&2; exit 1; }
  done
  xdotool search --name "^$1\$" | head -1
}

"$build/daemon/mpm" simulate --scenario wood-berry-g21-gain --edit y2.u1.gain=3 --samples 5000 --seed 1 \
  --out "$work/run.csv" >/dev/null
cat >"$work/mpmd.yaml" <<EOF
controller_id: wb
plant: $root/config/wood-berry.yaml
monitor: {forgetting: 0.999}
transport: {kind: lcm, lcm: {url: "$url"}}
status_period: 0.2
EOF
"$build/daemon/mpmd/mpmd" --config "$work/mpmd.yaml" >"$work/mpmd.out" 2>"$work/mpmd.err" &
pids="$pids $!"
MPM_LCM_TYPES_JAR=$build/transport/mpm-lcm-types.jar MPM_LCM_SPY_MAIN=SpyProbe \
  MPM_LCM_SPY_EXTRA_CLASSPATH=$build/tests/deploy/spy-probe.jar \
  sh "$root/deploy/mpm-lcm-spy" --lcm-url="$url" >"$work/spy.out" 2>"$work/spy.err" &
pids="$pids $!"
wait_until "[ -n \"\$(row_xy MPM_STATUS)\" ]" 60

# The raise and the diagnosis that follows it.
"$build/daemon/mpm" listen --config "$work/mpmd.yaml" --alarms-only --diagnoses --count 2 --timeout 120 \
  >"$work/listen.out" 2>"$work/listen.err" &
listen=$!
"$build/daemon/mpm" replay --config "$work/mpmd.yaml" --data "$work/run.csv" --rate 3000 >/dev/null
wait "$listen" || { echo "lcm_spy_screenshot: no alarm and diagnosis" >&2; cat "$work/mpmd.err" >&2; exit 1; }
cat "$work/listen.out"

# The channel table stays top left; each viewer goes to the right of it.
alarm=$(open_viewer MPM_ALARM)
xdotool windowmove "$alarm" 805 0 windowsize "$alarm" 1090 440
diagnosis=$(open_viewer MPM_DIAGNOSIS)
xdotool windowmove "$diagnosis" 805 450 windowsize "$diagnosis" 1090 545
sleep 2  # the viewers paint their fields after opening
mkdir -p "$(dirname "$out")"
import -window root "$out"
echo "screenshot: $out"
