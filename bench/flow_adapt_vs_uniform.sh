#!/usr/bin/env bash
# What the adaptive machinery costs per cell (issue #7): the Re = 100 cavity on
# a uniform 64^3 grid (bench/flow/cavity-uniform.toml) against the same cavity
# built at 32^3 and refined to 64^3 through the adaptive machinery, with the
# wavelet criterion and the regrid still run at every step
# (bench/flow/cavity-through-adapt.toml). Both go through
# `sanguis bench flow-adaptive --case`, alternately, on the same machine.
#
#   bench/flow_adapt_vs_uniform.sh [--steps S] [--threads T] [--repeat R]
#
# Defaults: 20 steps, 1 thread, 3 repeats. Prints each JSON line and a summary
# with the medians of seconds per cell-step and
# "ratio_adapt_over_uniform_per_cell" (the issue asks <= 1.5).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
sanguis="${SANGUIS:-$root/build/app/sanguis}"
steps=20
threads=1
repeat=3
while [[ $# -gt 0 ]]; do
  case "$1" in
    --steps) steps="${2:?--steps needs a value}"; shift 2 ;;
    --threads) threads="${2:?--threads needs a value}"; shift 2 ;;
    --repeat) repeat="${2:?--repeat needs a value}"; shift 2 ;;
    -h|--help) sed -n '2,14p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "flow_adapt_vs_uniform: unknown option $1" >&2; exit 2 ;;
  esac
done
[[ -x "$sanguis" ]] || { echo "flow_adapt_vs_uniform: $sanguis not found (build first)" >&2; exit 2; }

# Seconds per cell-step of one JSON line of flow-adaptive (cells at the end:
# both grids are 64^3 from the first step).
per_cell() { sed 's/.*"cells":\([0-9]*\).*"seconds_per_step":\([0-9.e+-]*\).*/\2 \1/' | awk '{ printf "%.6g", $1 / $2 }'; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : 0.5 * (v[NR / 2] + v[NR / 2 + 1]) }'; }

uniform=()
adapt=()
for ((r = 1; r <= repeat; ++r)); do
  for kind in uniform through-adapt; do
    echo "flow_adapt_vs_uniform: run $r/$repeat, $kind ..." >&2
    line=$("$sanguis" bench flow-adaptive --case "$root/bench/flow/cavity-$kind.toml" \
      --steps "$steps" --threads "$threads")
    echo "$line"
    if [[ $kind == uniform ]]; then uniform+=("$(echo "$line" | per_cell)"); else adapt+=("$(echo "$line" | per_cell)"); fi
  done
done
mu=$(printf '%s\n' "${uniform[@]}" | median)
ma=$(printf '%s\n' "${adapt[@]}" | median)
awk -v u="$mu" -v a="$ma" -v s="$steps" -v t="$threads" -v r="$repeat" \
  'BEGIN { printf "{\"benchmark\":\"flow-adapt-vs-uniform\",\"summary\":true,\"steps\":%d,\"threads\":%d,\"repeat\":%d,\"uniform_s_per_cell_step\":%s,\"through_adapt_s_per_cell_step\":%s,\"ratio_adapt_over_uniform_per_cell\":%.3f}\n", s, t, r, u, a, a / u }'
