#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Compile time and peak memory of every public header, each on its own in an otherwise empty
# translation unit (`#include <h>` and `int main() {}`), compiled to an object file.
#
#   scripts/header-cost.sh [-j N] [--cxx g++] [--flags "-O2"] [header-glob ...]
#
# Prints a Markdown table (header, seconds, peak MiB), slowest first. Each header is compiled
# once; with -j N, N compilations run at once (time and memory are per compiler process, but
# parallel runs compete for the machine: use -j 1 for the figures you publish).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
cxx=${CXX:-g++}
flags="-O2"
jobs=1
patterns=()
while (($#)); do
  case $1 in
  -j) jobs=$2; shift 2 ;;
  --cxx) cxx=$2; shift 2 ;;
  --flags) flags=$2; shift 2 ;;
  -h | --help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  -*) echo "header-cost.sh: unknown option '$1'" >&2; exit 2 ;;
  *) patterns+=("$1"); shift ;;
  esac
done

eigen=$(pkg-config --cflags eigen3 2>/dev/null || echo -I/usr/include/eigen3)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cd "$root/include"
mapfile -t headers < <(find taxel -name '*.hpp' -not -path 'taxel/drivers/*' | sort)
if ((${#patterns[@]})); then
  selected=()
  for h in "${headers[@]}"; do
    for p in "${patterns[@]}"; do
      # shellcheck disable=SC2053
      if [[ $h == $p ]]; then selected+=("$h"); break; fi
    done
  done
  headers=("${selected[@]}")
fi

measure() {
  local h=$1 id=$2
  local src="$work/$id.cpp"
  printf '#include <%s>\nint main() { return 0; }\n' "$h" >"$src"
  # shellcheck disable=SC2086
  if ! /usr/bin/time -f '%e %M' -o "$work/$id.time" \
    "$cxx" -std=c++20 $flags $eigen -I"$root/include" -c "$src" -o "$work/$id.o" 2>"$work/$id.err"; then
    echo "header-cost.sh: $h does not compile on its own:" >&2
    cat "$work/$id.err" >&2
    echo "$h FAILED 0" >"$work/$id.row"
    return
  fi
  read -r secs kib <"$work/$id.time"
  echo "$h $secs $((kib / 1024))" >"$work/$id.row"
}
export -f measure
export work cxx flags eigen root

i=0
for h in "${headers[@]}"; do
  printf '%s\t%d\n' "$h" "$i"
  i=$((i + 1))
done | xargs -P "$jobs" -L 1 bash -c 'measure "$0" "$1"'

echo "| header | seconds | peak MiB |"
echo "|---|---:|---:|"
cat "$work"/*.row | sort -k2,2 -g -r | awk '{printf "| `%s` | %s | %s |\n", $1, $2, $3}'
