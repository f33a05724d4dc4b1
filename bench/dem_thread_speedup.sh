#!/usr/bin/env bash
# Thread speed-up of a granular benchmark (issue #5 asks 1.8x from 1 to 2
# threads on dem-spheres): `sanguis bench BENCH --threads 1` and `--threads T`
# alternated K times, each pair run back to back so that both see the same
# minute of a shared machine, and the median of the pairs' ratios.
#
#   bench/dem_thread_speedup.sh [--bench dem-spheres|dem-crosses] [--threads T]
#                               [--repeat K] [-- EXTRA BENCH OPTIONS]
#
# Defaults: dem-spheres, T = 2, K = 5. Environment: SANGUIS (default
# build/app/sanguis under the repository root).
# stdout: each run's JSON line, then a summary line with the medians of each
# thread count, every pair's ratio and "median_pair_speedup". Progress on stderr.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
sanguis="${SANGUIS:-$root/build/app/sanguis}"
bench=dem-spheres
threads=2
repeat=5
extra=()

usage() { sed -n '2,13p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
die() { echo "dem_thread_speedup: $*" >&2; exit 2; }

while [[ $# -gt 0 ]]; do
  case "$1" in
    --bench) bench="${2:?--bench needs a value}"; shift 2 ;;
    --threads) threads="${2:?--threads needs a value}"; shift 2 ;;
    --repeat) repeat="${2:?--repeat needs a value}"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) usage; exit 0 ;;
    *) die "unknown option $1 (see --help)" ;;
  esac
done
[[ "$bench" == dem-spheres || "$bench" == dem-crosses ]] || die "--bench must be dem-spheres or dem-crosses"
[[ "$threads" =~ ^[1-9][0-9]*$ ]] || die "--threads must be a positive integer"
[[ "$repeat" =~ ^[1-9][0-9]*$ ]] || die "--repeat must be a positive integer"
[[ -x "$sanguis" ]] || die "$sanguis not found (build first: make build)"

rate() { sed 's/.*"particle_steps_per_s":\([0-9.e+-]*\).*/\1/'; }
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"

one=() many=() ratios=()
for ((r = 1; r <= repeat; r++)); do
  echo "dem_thread_speedup: pair $r of $repeat ($bench, 1 and $threads threads) ..." >&2
  line1=$("$sanguis" bench "$bench" "${extra[@]}" --threads 1 | tail -n 1)
  lineT=$("$sanguis" bench "$bench" "${extra[@]}" --threads "$threads" | tail -n 1)
  echo "$line1"
  echo "$lineT"
  a=$(echo "$line1" | rate)
  b=$(echo "$lineT" | rate)
  one+=("$a")
  many+=("$b")
  ratios+=("$(ratio "$b" "$a")")
done
m1=$(printf '%s\n' "${one[@]}" | median)
mT=$(printf '%s\n' "${many[@]}" | median)
mr=$(printf '%s\n' "${ratios[@]}" | median)
list=$(IFS=,; echo "${ratios[*]}")
echo "{\"benchmark\":\"$bench\",\"summary\":true,\"threads\":$threads,\"pairs\":$repeat,\"median_1thread_particle_steps_per_s\":$m1,\"median_${threads}threads_particle_steps_per_s\":$mT,\"pair_speedups\":[$list],\"median_pair_speedup\":$mr}"
