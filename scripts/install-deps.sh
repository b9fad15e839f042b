#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian 12 packages taxel needs when they are missing.
# Usage: scripts/install-deps.sh [build|test|asan|bench|demo|fuzz|python|all]   (default: test)
set -euo pipefail

what=${1:-test}
pkgs=(cmake g++ make pkg-config libeigen3-dev libnanoflann-dev nlohmann-json3-dev)
# The Python module, and what its tests and examples compare with or plot through.
python=(pybind11-dev python3-dev python3-numpy python3-venv python3-setuptools python3-pip)
python_test=(python3-pytest python3-scipy python3-skimage python3-matplotlib python3-sklearn mypy)
case "$what" in
  build) ;;
  test) pkgs+=(catch2 libbenchmark-dev robin-map-dev libusb-1.0-0-dev libpng-dev libjpeg-dev liblinear-dev liblinear-tools libsvm-dev umockdev libumockdev-dev chromium doxygen python3-markdown "${python[@]}" "${python_test[@]}") ;;
  # The asan preset: the tests, built with clang (a second compiler beside the ci preset's GCC).
  asan) pkgs+=(catch2 libusb-1.0-0-dev libpng-dev libjpeg-dev umockdev libumockdev-dev clang libclang-rt-14-dev) ;;
  bench) pkgs+=(libbenchmark-dev libpng-dev libjpeg-dev liblinear-dev robin-map-dev) ;;
  demo) pkgs+=(libpng-dev libjpeg-dev libusb-1.0-0-dev) ;;
  fuzz) pkgs+=(catch2 clang libclang-rt-14-dev) ;;
  python) pkgs+=("${python[@]}") ;;
  all) pkgs+=(catch2 libbenchmark-dev robin-map-dev libusb-1.0-0-dev libpng-dev libjpeg-dev liblinear-dev liblinear-tools libsvm-dev umockdev libumockdev-dev chromium doxygen python3-markdown clang libclang-rt-14-dev "${python[@]}" "${python_test[@]}") ;;
  *) echo "install-deps.sh: unknown set '$what' (build|test|asan|bench|demo|fuzz|python|all)" >&2; exit 2 ;;
esac

missing=()
for p in "${pkgs[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -eq 0 ]; then
  echo "install-deps.sh: installing ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
  echo "install-deps.sh: installing ${missing[*]} with sudo" >&2
  sudo -n env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  sudo -n env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
else
  echo "install-deps.sh: missing Debian packages: ${missing[*]}" >&2
  echo "install them with: sudo apt-get install ${missing[*]}" >&2
  exit 1
fi
