#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds taxel-demo in Release and runs it: everything taxel does, end to end, on simulated
# data, into one folder with an index.html (open it in a browser; no server needed).
# Installs missing Debian packages first (libpng for the pictures, libusb for the drivers).
# Usage: scripts/demo.sh [--quick] [OUTPUT-FOLDER]   (default taxel-demo-output)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh demo
cmake -S . -B build/demo -DCMAKE_BUILD_TYPE=Release -DTAXEL_BUILD_TESTS=OFF \
  -DTAXEL_BUILD_BENCHMARKS=OFF -DTAXEL_INSTALL=OFF >/dev/null
cmake --build build/demo -j2 --target taxel-demo
./build/demo/examples/taxel-demo "$@"
