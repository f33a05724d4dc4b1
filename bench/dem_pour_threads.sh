#!/usr/bin/env bash
# A pour on one and on T threads: the case of `make demo` (cases/dem/dam-break-spheres.toml)
# with 12,000 beads of radius 0.9-1.1 mm instead of 3,000 (13,000 particles with the glued
# floor), run to t = 0.1 s, while the beads fall and land: the lists are rebuilt every few
# dozen steps, so the broad phase counts here, where `bench dem-spheres` rebuilds once in
# 2000 steps (docs/performance.md, "The broad phase on threads"). One and T threads
# alternated K times, back to back, and the median of the pairs' ratios.
#
#   bench/dem_pour_threads.sh [--threads T] [--repeat K] [--end-time S]
#
# Defaults: T = 2, K = 3, S = 0.1. Environment: SANGUIS (default build/app/sanguis under the
# repository root). stdout: one JSON line per run (wall seconds of the run, steps, and the
# particle-steps/s run.log reports), then a summary line. Progress on stderr.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
sanguis="${SANGUIS:-$root/build/app/sanguis}"
threads=2
repeat=3
end_time=0.1

usage() { sed -n '2,13p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
die() { echo "dem_pour_threads: $*" >&2; exit 2; }

while [[ $# -gt 0 ]]; do
  case "$1" in
    --threads) threads="${2:?--threads needs a value}"; shift 2 ;;
    --repeat) repeat="${2:?--repeat needs a value}"; shift 2 ;;
    --end-time) end_time="${2:?--end-time needs a value}"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) die "unknown option $1 (see --help)" ;;
  esac
done
[[ "$threads" =~ ^[1-9][0-9]*$ ]] || die "--threads must be a positive integer"
[[ "$repeat" =~ ^[1-9][0-9]*$ ]] || die "--repeat must be a positive integer"
[[ "$end_time" =~ ^[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$ ]] || die "--end-time must be a positive number of seconds"
[[ -x "$sanguis" ]] || die "$sanguis not found (build first: make build)"

# shellcheck source=bench/common.sh
source "$root/bench/common.sh"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# run T: one pour on T threads; prints its JSON line, returns its wall seconds in $seconds.
run() {
  local t="$1" out="$work/pour-$1"
  rm -rf "$out"
  local start end
  start=$(date +%s.%N)
  "$sanguis" run "$root/cases/dem/dam-break-spheres.toml" --output "$out" --threads "$t" -q \
    --set "simulation.end_time_s=$end_time" --set output.vtk=false \
    --set 'particles[1].count=12000' --set 'particles[1].radius_min_m=0.9e-3' \
    --set 'particles[1].radius_max_m=1.1e-3' \
    --set 'particles[1].region_min_m=[0.0, 0.0, 0.0045]' \
    --set 'particles[1].region_max_m=[0.04, 0.04, 0.24]' > /dev/null
  end=$(date +%s.%N)
  seconds=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.4g", b - a }')
  # run.log's last line: "done: t = ... s, N steps in ... (R particle-steps/s)"
  local done_line steps rate
  done_line=$(grep '^done:' "$out/run.log" | tail -n 1)
  steps=$(echo "$done_line" | sed 's/.*, \([0-9]*\) steps in.*/\1/')
  rate=$(echo "$done_line" | sed 's/.*(\([0-9.e+-]*\) particle-steps\/s).*/\1/')
  echo "{\"benchmark\":\"dem-pour\",\"code\":\"sanguis\",\"particles\":13000,\"end_time_s\":$end_time,\"threads\":$t,\"steps\":$steps,\"seconds\":$seconds,\"particle_steps_per_s\":$rate}"
}

one=() many=() ratios=()
for ((r = 1; r <= repeat; r++)); do
  echo "dem_pour_threads: pair $r of $repeat (1 and $threads threads) ..." >&2
  run 1
  a="$seconds"
  run "$threads"
  b="$seconds"
  one+=("$a")
  many+=("$b")
  ratios+=("$(ratio "$a" "$b")")
done
m1=$(printf '%s\n' "${one[@]}" | median)
mT=$(printf '%s\n' "${many[@]}" | median)
mr=$(printf '%s\n' "${ratios[@]}" | median)
list=$(IFS=,; echo "${ratios[*]}")
echo "{\"benchmark\":\"dem-pour\",\"summary\":true,\"threads\":$threads,\"pairs\":$repeat,\"median_1thread_seconds\":$m1,\"median_${threads}threads_seconds\":$mT,\"pair_speedups\":[$list],\"median_pair_speedup\":$mr}"
