#!/usr/bin/env bash
# Installs the Debian packages mpm needs that this machine lacks (idempotent:
# does nothing, and needs no network, when everything is there).
set -euo pipefail
packages=(
  cmake g++ pkg-config
  libeigen3-dev libboost-dev libyaml-cpp-dev libcli11-dev
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev
  cyclonedds-dev cyclonedds-tools
  libsystemd-dev systemd
  libgtest-dev libgmock-dev libbenchmark-dev
  iproute2 openjdk-17-jdk-headless
  # lcm-spy screenshot test
  libjchart2d-java xvfb xdotool imagemagick
  # the HTML report inlines dygraphs; its test renders it in headless Chromium
  libjs-dygraphs chromium python3 python3-jsonschema
  # outside the suite: the shared cases' scorer, ../shared/tools/score.py
  python3-numpy python3-yaml
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "mpm: installing missing packages: ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
