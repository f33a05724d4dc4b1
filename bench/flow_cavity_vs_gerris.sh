#!/usr/bin/env bash
# Side-by-side benchmark "flow-cavity": Gerris (Debian package `gerris`,
# bench/gerris/cavity.gfs.in) against `sanguis bench flow-cavity`, the same
# lid-driven cubic cavity (Re = 100, lid velocity 1, nu = 0.01, uniform N^3
# cells, fixed dt = 0.01, projection tolerance 1e-3), one core each.
#
#   bench/flow_cavity_vs_gerris.sh [--cells-per-side N] [--steps S] [--block-cells B] [--repeat R]
#
# B: sanguis' cells per block edge (default 8, its case-file default; 16 runs
# a uniform grid about twice as fast per cell, see docs/performance.md).
# N must be a power of two for Gerris (2^level); default 64 and 10 steps.
# Gerris' time is the wall time between its step 0 and its last step (its own
# log), so its set-up is excluded as for sanguis. Gerris runs once (about a
# minute at 64^3, 10 steps); sanguis runs R times (default 5; about a second
# each at that size, so one run feels every hiccup of a shared machine) and its
# median counts. Prints one JSON line per run and a summary with
# "ratio_sanguis_over_gerris" (> 1: sanguis is faster).
# Install the peer with `scripts/install-deps.sh --bench`.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"
sanguis="${SANGUIS:-$root/build/app/sanguis}"
gerris="${GERRIS:-gerris3D}"
cells=64
steps=10
block=8
repeat=5
while [[ $# -gt 0 ]]; do
  case "$1" in
    --cells-per-side) cells="${2:?--cells-per-side needs a value}"; shift 2 ;;
    --steps) steps="${2:?--steps needs a value}"; shift 2 ;;
    --block-cells) block="${2:?--block-cells needs a value}"; shift 2 ;;
    --repeat) repeat="${2:?--repeat needs a value}"; shift 2 ;;
    -h|--help) sed -n '2,20p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "flow_cavity_vs_gerris: unknown option $1" >&2; exit 2 ;;
  esac
done
[[ "$repeat" =~ ^[1-9][0-9]*$ ]] || { echo "flow_cavity_vs_gerris: --repeat must be a positive integer" >&2; exit 2; }
level=0
while (( (1 << level) < cells )); do level=$((level + 1)); done
(( (1 << level) == cells )) || { echo "flow_cavity_vs_gerris: N must be a power of two" >&2; exit 2; }
command -v "$gerris" >/dev/null || { echo "flow_cavity_vs_gerris: $gerris not found (scripts/install-deps.sh --bench)" >&2; exit 2; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
sed "s/LEVEL/$level/; s/STEPS/$steps/" "$root/bench/gerris/cavity.gfs.in" > "$work/cavity.gfs"
echo "flow-cavity: N=$cells steps=$steps; gerris ..." >&2
"$gerris" "$work/cavity.gfs" 2> "$work/gerris.log" > /dev/null
gerris_seconds=$(awk '/^step:/ { if ($2 == 0) t0 = $10; t1 = $10 } END { printf "%.6f", t1 - t0 }' "$work/gerris.log")
gerris_rate=$(awk -v n="$cells" -v s="$steps" -v t="$gerris_seconds" 'BEGIN { printf "%.6g", n * n * n * s / t }')
echo "{\"benchmark\":\"flow-cavity\",\"code\":\"gerris\",\"cells\":$((cells * cells * cells)),\"steps\":$steps,\"seconds\":$gerris_seconds,\"cell_updates_per_s\":$gerris_rate}"
rates=()
for ((r = 1; r <= repeat; r++)); do
  echo "flow-cavity: sanguis run $r of $repeat ..." >&2
  line=$("$sanguis" bench flow-cavity --cells-per-side "$cells" --steps "$steps" --threads 1 --block-cells "$block")
  echo "$line"
  rates+=("$(echo "$line" | sed 's/.*"cell_updates_per_s":\([0-9.e+-]*\).*/\1/')")
done
sanguis_rate=$(printf '%s\n' "${rates[@]}" | median)
awk -v a="$sanguis_rate" -v b="$gerris_rate" -v n="$cells" -v s="$steps" -v blk="$block" -v r="$repeat" \
  'BEGIN { printf "{\"benchmark\":\"flow-cavity\",\"summary\":true,\"block_cells\":%d,\"cells_per_side\":%d,\"steps\":%d,\"sanguis_runs\":%d,\"gerris_cell_updates_per_s\":%s,\"sanguis_median_cell_updates_per_s\":%s,\"ratio_sanguis_over_gerris\":%.3g}\n", blk, n, s, r, b, a, a / b }'
