#!/bin/sh
# `cpack -G DEB` builds a package that holds what it should, and the package
# unpacked into an empty root runs: `mpm --version`, `mpmd --version`, and
# a diagnosis with its HTML report from the installed example plant.
# usage: deb_test.sh BUILD_DIR WORK_DIR VERSION
set -eu
build=$1; work=$2; version=$3
rm -rf "$work"; mkdir -p "$work/root"
(cd "$build" && cpack -G DEB -B "$work" >"$work/cpack.log" 2>&1) || { cat "$work/cpack.log"; exit 1; }
deb=$(ls "$work"/mpm_*.deb)
dpkg-deb -c "$deb" | awk '{print $6}' >"$work/contents.txt"
missing=0
for f in ./usr/bin/mpm ./usr/bin/mpmd ./usr/bin/mpm-lcm-spy \
         ./usr/lib/systemd/system/mpmd.service ./usr/lib/systemd/system/mpmd@.service \
         ./etc/mpm/mpmd.yaml ./etc/mpm/wood-berry.yaml ./etc/mpm/cyclonedds-loopback.xml \
         ./usr/share/doc/mpm/README.md ./usr/share/doc/mpm/formats.md ./usr/share/doc/mpm/diagnosis.schema.json \
         ./usr/share/mpm/java/mpm-lcm-types.jar ./usr/share/mpm/examples/mpmd-wood-berry-lcm.yaml \
         ./usr/share/man/man1/mpm.1 ./usr/share/man/man8/mpmd.8; do
  grep -qx "$f" "$work/contents.txt" || { echo "missing from the .deb: $f"; missing=1; }
done
# /etc files once, not under a doubled prefix (the old DESTDIR bug).
if grep -q "etc/.*etc/\|usr/etc" "$work/contents.txt"; then echo "misplaced /etc files:"; grep "etc" "$work/contents.txt"; missing=1; fi
[ "$missing" = 0 ]
dpkg-deb -I "$deb" conffiles | grep -qx /etc/mpm/mpmd.yaml || { echo "mpmd.yaml is not a conffile"; exit 1; }
dpkg-deb -f "$deb" Depends | grep -q libjs-dygraphs || { echo "Depends lacks libjs-dygraphs"; exit 1; }
[ "$(dpkg-deb -f "$deb" Version)" = "$version" ] || { echo "package version is not $version"; exit 1; }
# The units name binaries where the package puts them.
grep -q "ExecStart=/usr/bin/mpmd" "$(dpkg-deb -x "$deb" "$work/root" && echo "$work/root/usr/lib/systemd/system/mpmd.service")" \
  || { echo "mpmd.service does not run /usr/bin/mpmd"; exit 1; }
root=$work/root
[ "$("$root/usr/bin/mpm" --version)" = "mpm $version" ] || { echo "mpm --version"; exit 1; }
[ "$("$root/usr/bin/mpmd" --version)" = "mpmd $version" ] || { echo "mpmd --version"; exit 1; }
"$root/usr/bin/mpm" simulate --scenario wood-berry-g21-gain --samples 1500 --seed 1 --out "$work/run.csv" >/dev/null
"$root/usr/bin/mpm" diagnose --quiet --plant "$root/etc/mpm/wood-berry.yaml" --data "$work/run.csv" \
  --json "$work/d.json" --html "$work/d.html" --write-plant "$work/fixed.yaml"
grep -q '"schema": "mpm.diagnosis/1"' "$work/d.json"
grep -q "drawn" "$work/d.html"
echo "ok: $(basename "$deb"), $(wc -l <"$work/contents.txt") entries, runs from $root"
