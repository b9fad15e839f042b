#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Verifies the Conan recipe offline: a throw-away Conan home, the local recipe index in conan/
# (Debian's Eigen and nanoflann under ConanCenter's names), then `conan create`.
# Needs Conan 2: `conan` on PATH, or CONAN_SOURCE=<a Conan 2 source tree> run with Debian's
# python3 and its python3-requests python3-urllib3 python3-jinja2 python3-fasteners
# python3-dateutil python3-colorama python3-patch-ng python3-yaml python3-distro.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "${CONAN_SOURCE:-}" ]; then
  conan() { PYTHONPATH="$CONAN_SOURCE" /usr/bin/python3 -m conans.conan "$@"; }
elif ! command -v conan >/dev/null; then
  echo "conan-create.sh: no conan on PATH; set CONAN_SOURCE to a Conan 2 source tree" >&2
  exit 1
fi
export CONAN_HOME="${CONAN_HOME:-$(mktemp -d)}"
conan profile detect --exist-ok >/dev/null
conan remote disable conancenter >/dev/null 2>&1 || true
conan remote remove local-deps >/dev/null 2>&1 || true
conan remote add local-deps "$PWD/conan" --type=local-recipes-index
conan create . --build=missing -s compiler.cppstd=20 "$@"
