#!/usr/bin/env bash
# Installs what smtcal needs to build and test, from Debian 12's packages.
# Idempotent: only missing packages are installed. Run as root.
set -euo pipefail

packages=(
  build-essential cmake
  antlr4 libantlr4-runtime-dev default-jre-headless
  libeigen3-dev libfmt-dev libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libfast-float-dev
  libgtest-dev libbenchmark-dev
  linuxcnc-uspace
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: run as root (or with sudo) to install packages" >&2
  exit 3
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
