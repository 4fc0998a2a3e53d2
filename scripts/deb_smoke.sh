#!/bin/sh
# The .deb installed into a clean root and run from there (issue 14, item 6):
# builds the package (a build folder of its own, prefix /usr, no tests),
# installs it with dpkg into an empty root that has only dpkg's database
# (`dpkg --root`: the package's files, conffiles and status as on a real
# system; dependencies are not in that root, so the binaries run with the
# host's shared libraries), then runs from the installed paths:
#   mpm --version, mpmd --version,
#   mpm diagnose on a recording simulated by the installed mpm, with the
#     installed example plant /etc/mpm/wood-berry.yaml (JSON, HTML, corrected plant),
#     and the HTML report rendered in headless Chromium when it is installed,
#   mpmd --check on the installed /etc/mpm/mpmd.yaml,
#   dpkg --root ... -s mpm and -L mpm (what dpkg recorded).
# usage: scripts/deb_smoke.sh [WORK_DIR]   (default out/deb-smoke; the build in build-deb/)
set -eu
src=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-$src/out/deb-smoke}
build=${MPM_DEB_BUILD_DIR:-$src/build-deb}
rm -rf "$work" && mkdir -p "$work/pkg"
echo "== build (prefix /usr) and package"
cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
  -DMPM_BUILD_TESTS=OFF -DMPM_BUILD_BENCH=OFF >"$work/configure.log"
cmake --build "$build" -j"$(nproc)" >"$work/build.log"
(cd "$build" && cpack -G DEB -B "$work/pkg" >"$work/cpack.log")
deb=$(ls "$work"/pkg/mpm_*.deb)
echo "$(basename "$deb"): $(du -k "$deb" | cut -f1) KiB, Depends: $(dpkg-deb -f "$deb" Depends)"

echo "== install into a clean root"
root=$work/root
mkdir -p "$root/var/lib/dpkg/info" "$root/var/lib/dpkg/updates"
: >"$root/var/lib/dpkg/status"
dpkg --root="$root" --force-depends --force-script-chrootless -i "$deb" 2>&1 | grep -v "^dpkg: warning: \|^ \|^dpkg: mpm: dependency problems"
dpkg --root="$root" -s mpm | grep -E "^(Package|Status|Version):"
echo "files installed: $(dpkg --root="$root" -L mpm | wc -l); conffiles: $(dpkg --root="$root" -s mpm | sed -n '/^Conffiles:/,/^[A-Z]/p' | grep -c '^ /etc')"
[ -z "$(find "$root" -path "$root/var" -prune -o -type f -print | grep -v "^$root/\(usr\|etc\)/")" ] || { echo "files outside /usr and /etc"; exit 1; }

echo "== run from the installed paths"
"$root/usr/bin/mpm" --version
"$root/usr/bin/mpmd" --version
# The scenario's plant from the installed share/mpm/config (not this source tree).
MPM_CONFIG_DIR="$root/usr/share/mpm/config" "$root/usr/bin/mpm" simulate --scenario wood-berry-g21-gain \
  --samples 3000 --seed 1 --out "$work/run.csv" | sed "s|$root||g; s|$work/||g"
"$root/usr/bin/mpm" diagnose --quiet --plant "$root/etc/mpm/wood-berry.yaml" --data "$work/run.csv" \
  --json "$work/diagnosis.json" --html "$work/report.html" --write-plant "$work/corrected.yaml"
echo "mpm diagnose: exit 0; $(grep -o '"summary": "[^"]*"' "$work/diagnosis.json")"
echo "  wrote diagnosis.json ($(wc -c <"$work/diagnosis.json") B), report.html ($(wc -c <"$work/report.html") B), corrected.yaml"
if command -v chromium >/dev/null && [ -x /usr/bin/python3 ]; then  # the report as a browser draws it
  /usr/bin/python3 "$src/tests/product/render_report.py" "$work/report.html" "$work/report.png" | sed "s|$work/||g"
fi
# mpmd.yaml names its plant file relative to /etc/mpm (where the package puts both).
"$root/usr/bin/mpmd" --config "$root/etc/mpm/mpmd.yaml" --check 2>&1 | sed "s|$root||g"
echo "ok: the .deb installed into $root and ran"
