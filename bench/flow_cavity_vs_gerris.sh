#!/usr/bin/env bash
# Side-by-side benchmark "flow-cavity": Gerris (Debian package `gerris`,
# bench/gerris/cavity.gfs.in) against `sanguis bench flow-cavity`, the same
# lid-driven cubic cavity (Re = 100, lid velocity 1, nu = 0.01, uniform N^3
# cells, fixed dt = 0.01, projection tolerance 1e-3), one core each.
#
#   bench/flow_cavity_vs_gerris.sh [--cells-per-side N] [--steps S] [--block-cells B]
#                                  [--repeat R] [--pairs P] [--unmerged-solver]
#
# B: sanguis' cells per block edge (default: what a case file without
# block_cells gets, 16 where N is a multiple of 16 and at least 64, else 8;
# docs/performance.md, "Automatic block size"; --block-cells 8 for the
# adaptive grids' default). Blocks below 16^3 are merged 8 by 8 for the
# multigrid (Multigrid's merge_blocks); --unmerged-solver solves on the
# blocks themselves instead (A/B).
# N must be a power of two for Gerris (2^level); default 64 and 10 steps.
# Gerris' time is the wall time between its step 0 and its last step (its own
# log), so its set-up is excluded as for sanguis. A pair is one Gerris run
# (about 1-2 minutes at 64^3, 10 steps) and R sanguis runs beside it (default
# 5; about a second each at that size, so one run feels every hiccup of a
# shared machine), whose median is that pair's sanguis figure. P pairs
# (default 1) alternate which code goes first, so a host that speeds up or
# slows down during the run weighs on both codes alike. Prints one JSON line
# per run, one per pair with its ratio, and a summary with the medians of
# both codes over the pairs and "ratio_sanguis_over_gerris", the median of the
# pairs' ratios (> 1: sanguis is faster; with P >= 3 one disturbed minute no
# longer sets the figure).
# Install the peer with `scripts/install-deps.sh --bench`.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"
sanguis="${SANGUIS:-$root/build/app/sanguis}"
gerris="${GERRIS:-gerris3D}"
cells=64
steps=10
block=0
repeat=5
pairs=1
unmerged=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --cells-per-side) cells="${2:?--cells-per-side needs a value}"; shift 2 ;;
    --steps) steps="${2:?--steps needs a value}"; shift 2 ;;
    --block-cells) block="${2:?--block-cells needs a value}"; shift 2 ;;
    --repeat) repeat="${2:?--repeat needs a value}"; shift 2 ;;
    --pairs) pairs="${2:?--pairs needs a value}"; shift 2 ;;
    --unmerged-solver) unmerged=(--unmerged-solver); shift ;;
    -h|--help) sed -n '2,28p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "flow_cavity_vs_gerris: unknown option $1" >&2; exit 2 ;;
  esac
done
[[ "$repeat" =~ ^[1-9][0-9]*$ ]] || { echo "flow_cavity_vs_gerris: --repeat must be a positive integer" >&2; exit 2; }
[[ "$pairs" =~ ^[1-9][0-9]*$ ]] || { echo "flow_cavity_vs_gerris: --pairs must be a positive integer" >&2; exit 2; }
level=0
while (( (1 << level) < cells )); do level=$((level + 1)); done
(( (1 << level) == cells )) || { echo "flow_cavity_vs_gerris: N must be a power of two" >&2; exit 2; }
command -v "$gerris" >/dev/null || { echo "flow_cavity_vs_gerris: $gerris not found (scripts/install-deps.sh --bench)" >&2; exit 2; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
sed "s/LEVEL/$level/; s/STEPS/$steps/" "$root/bench/gerris/cavity.gfs.in" > "$work/cavity.gfs"
# One Gerris run: prints its JSON line, leaves its rate in gerris_rate.
run_gerris() {
  echo "flow-cavity: N=$cells steps=$steps; gerris (pair $1 of $pairs) ..." >&2
  "$gerris" "$work/cavity.gfs" 2> "$work/gerris.log" > /dev/null
  local seconds
  seconds=$(awk '/^step:/ { if ($2 == 0) t0 = $10; t1 = $10 } END { printf "%.6f", t1 - t0 }' "$work/gerris.log")
  gerris_rate=$(awk -v n="$cells" -v s="$steps" -v t="$seconds" 'BEGIN { printf "%.6g", n * n * n * s / t }')
  echo "{\"benchmark\":\"flow-cavity\",\"code\":\"gerris\",\"cells\":$((cells * cells * cells)),\"steps\":$steps,\"seconds\":$seconds,\"cell_updates_per_s\":$gerris_rate}"
}
# R sanguis runs: prints their JSON lines, leaves their median in sanguis_rate.
run_sanguis() {
  local rates=() r line
  for ((r = 1; r <= repeat; r++)); do
    echo "flow-cavity: sanguis run $r of $repeat (pair $1 of $pairs) ..." >&2
    line=$("$sanguis" bench flow-cavity --cells-per-side "$cells" --steps "$steps" --threads 1 --block-cells "$block" "${unmerged[@]}")
    echo "$line"
    rates+=("$(echo "$line" | sed 's/.*"cell_updates_per_s":\([0-9.e+-]*\).*/\1/')")
    block_used="$(echo "$line" | sed 's/.*"block_cells":\([0-9]*\).*/\1/')"
  done
  sanguis_rate=$(printf '%s\n' "${rates[@]}" | median)
}
gerris_rates=()
sanguis_rates=()
ratios=()
for ((p = 1; p <= pairs; p++)); do
  if ((p % 2 == 1)); then
    run_gerris "$p"
    run_sanguis "$p"
  else
    run_sanguis "$p"
    run_gerris "$p"
  fi
  ratio=$(awk -v a="$sanguis_rate" -v b="$gerris_rate" 'BEGIN { printf "%.6g", a / b }')
  echo "{\"benchmark\":\"flow-cavity\",\"pair\":$p,\"gerris_cell_updates_per_s\":$gerris_rate,\"sanguis_median_cell_updates_per_s\":$sanguis_rate,\"ratio_sanguis_over_gerris\":$ratio}"
  gerris_rates+=("$gerris_rate")
  sanguis_rates+=("$sanguis_rate")
  ratios+=("$ratio")
done
gerris_median=$(printf '%s\n' "${gerris_rates[@]}" | median)
sanguis_median=$(printf '%s\n' "${sanguis_rates[@]}" | median)
ratio_median=$(printf '%s\n' "${ratios[@]}" | median)
ratio_list=$(IFS=,; echo "${ratios[*]}")
awk -v a="$sanguis_median" -v b="$gerris_median" -v q="$ratio_median" -v list="$ratio_list" \
  -v n="$cells" -v s="$steps" -v blk="$block_used" -v r="$repeat" -v np="$pairs" \
  'BEGIN { printf "{\"benchmark\":\"flow-cavity\",\"summary\":true,\"block_cells\":%d,\"cells_per_side\":%d,\"steps\":%d,\"pairs\":%d,\"sanguis_runs_per_pair\":%d,\"gerris_cell_updates_per_s\":%s,\"sanguis_median_cell_updates_per_s\":%s,\"pair_ratios\":[%s],\"ratio_sanguis_over_gerris\":%.3g}\n", blk, n, s, np, r, b, a, list, q }'
