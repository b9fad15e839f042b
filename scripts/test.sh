#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds taxel (Release, warnings as errors, examples and benchmarks) and runs the whole test
# suite. Installs missing Debian packages first.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh test
cmake --workflow --preset ci
