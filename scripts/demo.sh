#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the examples in Release and runs the end-to-end demo of what taxel can do so far.
# Installs missing Debian packages first. Output goes to ./taxel-demo-output.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh bench
cmake --preset release >/dev/null
cmake --build --preset release --target taxel-demo
./build/release/examples/taxel-demo "${@:-taxel-demo-output}"
