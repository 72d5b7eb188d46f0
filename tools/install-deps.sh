#!/usr/bin/env bash
# Installs the Debian packages candela builds and tests with (Debian 12).
# chromium: tests/report_page.sh opens bench/report.py's page headless.
# Runs apt-get only for what is missing, so it is cheap to call again.
set -eu
pkgs="build-essential cmake pkg-config libembree-dev libopenexr-dev libpng-dev libassimp-dev libstb-dev libpugixml-dev zlib1g-dev libopenmpi-dev openmpi-bin
      python3-matplotlib python3-numpy python3-pytest python3-openimageio clang libclang-rt-14-dev libomp-14-dev
      chromium"
missing=""
for p in $pkgs; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  echo "installing:$missing"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq $missing
fi
