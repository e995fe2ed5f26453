#!/usr/bin/env bash
# Installs what smtcal needs to build and test, from Debian 12's packages.
# Idempotent: only missing packages are installed. Run as root.
set -euo pipefail

packages=(
  build-essential cmake
  antlr4 libantlr4-runtime-dev default-jre-headless
  libeigen3-dev libfmt-dev libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libfast-float-dev
  libgtest-dev libbenchmark-dev libmimalloc-dev
  clang-14 libclang-rt-14-dev  # the fuzz harnesses: clang and its libFuzzer runtime (tests/fuzz/)
  linuxcnc-uspace iproute2
  linuxcnc-uspace-dev  # halcompile: the simulated robot of the measurement scenarios (tests/linuxcnc-sim/smtcal_robot_model.comp)
  locales
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
else
  echo "install-deps: installing ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then
    echo "install-deps: run as root (or with sudo) to install packages" >&2
    exit 3
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# A decimal-comma locale, so the tests can show that reading numbers does not
# depend on the user's locale (tests/unit/frontend/table_csv_test.cpp).
if ! locale -a 2>/dev/null | grep -qi '^de_DE\.utf-\?8$'; then
  if [ "$(id -u)" -eq 0 ]; then
    sed -i 's/^# *de_DE.UTF-8 UTF-8/de_DE.UTF-8 UTF-8/' /etc/locale.gen
    grep -q '^de_DE.UTF-8 UTF-8' /etc/locale.gen || echo 'de_DE.UTF-8 UTF-8' >> /etc/locale.gen
    locale-gen >/dev/null
  else
    echo "install-deps: no de_DE.UTF-8 locale (needs root); one locale test will be skipped" >&2
  fi
fi
