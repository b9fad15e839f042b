#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Python package the two documented ways and runs a short session with each:
#   cmake --install <build> --component python --prefix <dir>
#   python3 -m venv --system-site-packages <venv> && <venv>/bin/pip install --no-build-isolation <src>
# Usage: install_check.sh cmake|pip PYTHON BUILD_DIR SOURCE_DIR SITE_RELATIVE WORK_DIR
set -euo pipefail
how=$1 python=$2 build=$3 src=$4 site=$5 work=$6
rm -rf "$work" && mkdir -p "$work"
session='
import sys, numpy as np, taxel
from taxel import fusion, registration, sim
assert taxel.__file__.startswith(sys.argv[1]), taxel.__file__
cloud = fusion.ContactCloud("kalman")
cloud.insert(sim.Sphere(0.03).sample_surface(500, 1).points, sigma=2e-4)
assert 0 < len(cloud) < 500
from taxel import learn
x = np.random.default_rng(1).normal(size=(40, 3)); y = np.arange(40) % 2; x[y == 1] += 3
assert learn.LinearSvm(bias=1.0).fit(x, y).score(x, y) > 0.9
print("taxel", taxel.__version__, "from", taxel.__file__, ":", cloud)
'
case "$how" in
  cmake)
    cmake --install "$build" --component python --prefix "$work/prefix" >/dev/null
    cd "$work" && PYTHONPATH="$work/prefix/$site" "$python" -c "$session" "$work/prefix"
    ;;
  pip)
    "$python" -m venv --system-site-packages "$work/venv"
    # A copy of the sources, so that the build leaves nothing in the checkout.
    mkdir -p "$work/src" && (cd "$src" && git ls-files -z | xargs -0 cp --parents -t "$work/src")
    # Unoptimised, through TAXEL_CMAKE_ARGS (checked below): the build tree compiles the same
    # module optimised already, and -O0 takes about a third off this second compile.
    CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-2} \
      TAXEL_CMAKE_ARGS="-DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O0" \
      "$work/venv/bin/pip" install --no-build-isolation --no-deps -q "$work/src" >"$work/pip.log" 2>&1 \
      || { tail -n 40 "$work/pip.log"; exit 1; }
    caches=$(find "$work/src" -name CMakeCache.txt)
    if [ -z "$caches" ] || ! grep -q '^CMAKE_CXX_FLAGS_DEBUG:STRING=-O0$' $caches; then
      echo "install_check.sh: TAXEL_CMAKE_ARGS did not reach the module's CMake build" >&2
      exit 1
    fi
    cd "$work" && "$work/venv/bin/python" -c "$session" "$work/venv"
    ;;
  *) echo "install_check.sh: cmake or pip, not '$how'" >&2; exit 2 ;;
esac
