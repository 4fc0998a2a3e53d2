#!/bin/sh
# Installs the build into a scratch prefix, then checks what landed there:
# the binaries, the units (systemd-analyze verify: any message fails, since
# unknown keys only warn), their hardening score, and that the installed
# example configuration is valid for the installed mpmd.
#   verify_units.sh BUILD_DIR
# Exit 77 (skipped) where systemd-analyze is not installed.
set -u
build=$1
if ! command -v systemd-analyze >/dev/null 2>&1; then
  echo "systemd-analyze not found: units not verified"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cmake --install "$build" --prefix "$tmp/usr" >"$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; fail "cmake --install"; }
units="$tmp/usr/lib/systemd/system"
etc="$tmp/usr/etc/mpm"
for f in "$tmp/usr/bin/mpmd" "$tmp/usr/bin/mpm" "$tmp/usr/bin/mpm-lcm-spy"; do [ -x "$f" ] || fail "$f not installed"; done
if [ -f "$build/transport/mpm-lcm-types.jar" ]; then
  [ -f "$tmp/usr/share/mpm/java/mpm-lcm-types.jar" ] || fail "the lcm-spy type jar is not installed"
fi
for f in "$units/mpmd.service" "$units/mpmd@.service" "$etc/mpmd.yaml" "$etc/wood-berry.yaml" \
         "$etc/cyclonedds-loopback.xml" "$etc/cyclonedds-plant-network.xml"; do
  [ -f "$f" ] || fail "$f not installed"
done
grep -q "^ExecStart=$tmp/usr/bin/mpmd --config $etc/mpmd.yaml\$" "$units/mpmd.service" ||
  fail "mpmd.service does not start the installed mpmd with the installed configuration"

# An instance of the template, as `systemctl start mpmd@column-a` would load it.
cp "$units/mpmd@.service" "$tmp/mpmd@column-a.service"
for unit in "$units/mpmd.service" "$units/mpmd@.service" "$tmp/mpmd@column-a.service"; do
  out=$(systemd-analyze verify "$unit" 2>&1) || { echo "$out"; fail "systemd-analyze verify $unit"; }
  [ -z "$out" ] || { echo "$out"; fail "systemd-analyze verify $unit printed warnings"; }
  # Exposure 0 (locked down) .. 10 (unprotected), threshold in tenths.
  systemd-analyze security --offline=yes --threshold=25 "$unit" >"$tmp/security.txt" 2>&1 ||
    { tail -3 "$tmp/security.txt"; fail "$unit: hardening exposure above 2.5"; }
  echo "ok: $(basename "$unit"): $(grep 'Overall exposure' "$tmp/security.txt")"
  # Resource and network bounds (issue 12: without them only the OOM killer
  # stopped a 16 GB allocation).
  for key in MemoryMax TasksMax IPAddressDeny IPAddressAllow; do
    grep -q "^$key=" "$unit" || fail "$unit: no $key="
  done
done

# What the unit checks before starting: the installed example is valid.
"$tmp/usr/bin/mpmd" --config "$etc/mpmd.yaml" --check || fail "installed mpmd.yaml is invalid"

# A reinstall keeps an operator's edited configuration.
echo "# edited by the operator" >>"$etc/mpmd.yaml"
cmake --install "$build" --prefix "$tmp/usr" >"$tmp/install2.log" 2>&1 || fail "second install"
grep -q "edited by the operator" "$etc/mpmd.yaml" || fail "reinstall overwrote /etc/mpm/mpmd.yaml"
echo "ok: units, hardening, configuration"
