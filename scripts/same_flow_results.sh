#!/usr/bin/env bash
# Do two builds give the same flow results? Runs three short flow cases
# (the cavity, the channel constriction and the adaptive obstacle wake) with
# each binary and compares, byte for byte, every frame (.vtu), the
# diagnostics.csv and the checkpoint. Frames and diagnostics are the physics;
# the checkpoint also holds the ghost cells, which a change to what is
# filled (and never read) may leave different.
#
#   scripts/same_flow_results.sh OLD_SANGUIS NEW_SANGUIS [WORK_DIR]
#
# Exit status 0 when frames and diagnostics agree for every case, 1 when one
# differs, 2 on bad arguments or a failed run. Takes about a minute on 2 cores.
set -euo pipefail
old="${1:-}"; new="${2:-}"
work="${3:-$(mktemp -d)}"
mkdir -p "$work"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
for bin in "$old" "$new"; do
  [[ -n "$bin" && -x "$bin" ]] || {
    echo "same_flow_results: usage: $0 OLD_SANGUIS NEW_SANGUIS [WORK_DIR] (executables)" >&2
    exit 2
  }
done
status=0
# The cavity's blocks set (8^3, what both binaries give it whatever their
# default): a binary from before 2026-12-03 would otherwise compare other blocks.
for entry in cavity-re100:1.0:8 channel-constriction:1.0: obstacle-wake:2.0:; do
  name="${entry%%:*}"; rest="${entry#*:}"; end="${rest%%:*}"; blocks="${rest#*:}"
  extra=(); [[ -n "$blocks" ]] && extra=(--set "flow.grid.block_cells=$blocks")
  for side in old new; do
    bin="$old"; [[ "$side" == new ]] && bin="$new"
    rm -rf "$work/$name-$side"
    if ! "$bin" run "$root/cases/flow/$name.toml" -q -t 2 --set "simulation.end_time_s=$end" "${extra[@]}" \
      -o "$work/$name-$side" > /dev/null 2> "$work/$name-$side.err"; then
      echo "same_flow_results: $bin failed on $name:" >&2
      cat "$work/$name-$side.err" >&2
      exit 2
    fi
  done
  differing=()
  while IFS= read -r file; do
    cmp -s "$work/$name-old/$file" "$work/$name-new/$file" || differing+=("$file")
  done < <(cd "$work/$name-old" && find . \( -name '*.vtu' -o -name diagnostics.csv \) | sort)
  checkpoint=same
  cmp -s "$work/$name-old/checkpoint.bin" "$work/$name-new/checkpoint.bin" || checkpoint=differs
  if ((${#differing[@]} == 0)); then
    echo "$name: frames and diagnostics the same; checkpoint bytes $checkpoint"
  else
    echo "$name: DIFFER in ${differing[*]}; checkpoint bytes $checkpoint"
    status=1
  fi
done
exit "$status"
