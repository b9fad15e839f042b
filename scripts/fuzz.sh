#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the libFuzzer targets with clang and runs each for the given number of seconds.
# Usage: scripts/fuzz.sh [seconds-per-target=60] [target ...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
bash scripts/install-deps.sh fuzz
cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DTAXEL_BUILD_FUZZERS=ON -DTAXEL_BUILD_TESTS=OFF -DTAXEL_BUILD_EXAMPLES=OFF \
  -DTAXEL_BUILD_BENCHMARKS=OFF -DTAXEL_BUILD_DRIVERS=OFF -DTAXEL_INSTALL=OFF >/dev/null
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(grep -o 'taxel_add_fuzzer(\w*' tests/fuzz/CMakeLists.txt |
    sed 's/taxel_add_fuzzer(//' | grep -v '^name$')
fi
cmake --build build/fuzz -j2 --target "${targets[@]}"
for t in "${targets[@]}"; do
  corpus="build/fuzz/corpus/$t"
  mkdir -p "$corpus"
  if [ "$t" = fuzz_session ] && [ ! -e "$corpus/seed" ]; then  # the committed session and its poses
    { cat data/sessions/cylinder_grasp.session; printf '#poses\n'
      cat data/sessions/cylinder_grasp_poses.csv; } > "$corpus/seed"
  fi
  echo "== $t: ${seconds}s"
  "build/fuzz/tests/fuzz/$t" -max_total_time="$seconds" -print_final_stats=1 \
    -artifact_prefix="build/fuzz/" "$corpus"
done
