#!/usr/bin/env bash
# Reruns every benchmark quoted in docs/performance.md, one after the other,
# and collects their JSON lines. The machine should be otherwise idle (two
# programs with OpenMP threads on the same cores slow each other down many
# times over); the peers (LAMMPS, Gerris) are skipped with a note when they
# are not installed (scripts/install-deps.sh --bench installs them).
#
#   bench/run_all.sh [--quick] [--out DIR]
#
# Writes DIR/results.jsonl (one JSON line per benchmark run, default
# bench-results/<date>/) and DIR/<name>.log (each command's stderr), and
# prints each command with its JSON lines. --quick runs every command at a
# small size (a smoke check of the script, not figures to quote).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
sanguis="${SANGUIS:-$root/build/app/sanguis}"
quick=0
out="$root/bench-results/$(date +%Y-%m-%d_%H%M)"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --quick) quick=1; shift ;;
    --out) out="${2:?--out needs a folder}"; shift 2 ;;
    -h|--help) sed -n '2,13p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "run_all: unknown option $1" >&2; exit 2 ;;
  esac
done
[[ -x "$sanguis" ]] || { echo "run_all: $sanguis not found (build first: make build)" >&2; exit 2; }
mkdir -p "$out"
results="$out/results.jsonl"
: > "$results"
export SANGUIS="$sanguis"
mpirun_cmd=(mpirun --oversubscribe)
[[ $(id -u) -eq 0 ]] && mpirun_cmd+=(--allow-run-as-root)

failed=0
# run NAME COMMAND...: runs it, keeps the JSON lines of its stdout.
run() {
  local name="$1"
  shift
  echo "== $name: $*"
  local start=$SECONDS
  if "$@" 2> "$out/$name.log" | tee -a "$out/$name.out" | grep '^{' | tee -a "$results"; then
    echo "   ($((SECONDS - start)) s)"
  else
    echo "   FAILED after $((SECONDS - start)) s (see $out/$name.log)"
    failed=1
  fi
}
have() { command -v "$1" > /dev/null; }

if ((quick)); then
  spheres=(--particles 4000 --steps 200); crosses=(--particles 300 --steps 50)
  big=(--particles 100000 --steps 2); repeat=1; flow_n=16; flow_steps=2; wake_steps=5
  flow_big_n=32
  membrane=(--triangles 320 --capsules 4 --steps 2); lammps=(--particles 4000 --steps 200)
  pour=(--end-time 0.002)
else
  spheres=(); crosses=(); big=(--particles 1000000 --steps 3); repeat=3; flow_n=64
  flow_steps=20; wake_steps=100; membrane=(--triangles 5120 --capsules 100); lammps=()
  flow_big_n=128
  pour=()
fi

# Granular solver (issues #3, #5).
if have "${LMP:-lmp}"; then
  run dem-spheres-vs-lammps "$root/bench/dem_spheres_vs_lammps.sh" "${lammps[@]}" --repeat "$repeat"
  run dem-spheres-vs-lammps-2proc "$root/bench/dem_spheres_vs_lammps.sh" "${lammps[@]}" \
    --processes 2 --repeat "$repeat"
else
  echo "== dem-spheres-vs-lammps: skipped (LAMMPS not installed: scripts/install-deps.sh --bench)"
fi
# One and two threads alternated, the median of the pairs' speed-ups (issue #5: 1.8x).
run dem-spheres-thread-speedup "$root/bench/dem_thread_speedup.sh" --repeat "$repeat" -- \
  "${spheres[@]}"
# A pour, where lists are rebuilt every few dozen steps (the broad phase on the threads).
run dem-pour-thread-speedup "$root/bench/dem_pour_threads.sh" --repeat "$repeat" "${pour[@]}"
run dem-spheres-2proc "${mpirun_cmd[@]}" -np 2 "$sanguis" bench dem-spheres "${spheres[@]}"
# The storage sort (docs/performance.md): ids scattered in space, sorted and never sorted.
for sort in 2000 0; do
  for t in 1 2; do
    run "dem-spheres-scattered-sort${sort}-${t}threads" "$sanguis" bench dem-spheres \
      "${spheres[@]}" --scatter --storage-sort "$sort" --threads "$t"
  done
done
run dem-spheres-memory "$sanguis" bench dem-spheres "${big[@]}" --threads 1
run dem-crosses-1thread "$sanguis" bench dem-crosses "${crosses[@]}" --threads 1
run dem-crosses-2threads "$sanguis" bench dem-crosses "${crosses[@]}" --threads 2

# Capsule membranes (issue #8).
run membrane-1thread "$sanguis" bench membrane "${membrane[@]}" --threads 1
run membrane-2threads "$sanguis" bench membrane "${membrane[@]}" --threads 2

# Flow solver (issues #6, #7).
if have "${GERRIS:-gerris3D}"; then
  # As many Gerris runs as repeats, alternated with sanguis' (the median of the pairs'
  # ratios counts: the host's load moves the two codes differently).
  # The default blocks (16^3 at 64^3: the grid does not adapt), then the 8^3 blocks of
  # adaptive grids (docs/performance.md, "Block size", "Automatic block size"); the quick
  # run's 16^3 cavity takes 8^3 blocks by default, so it runs once.
  run flow-cavity-vs-gerris "$root/bench/flow_cavity_vs_gerris.sh" --cells-per-side "$flow_n" \
    --steps "$((flow_steps / 2 > 0 ? flow_steps / 2 : 1))" --pairs "$repeat"
  if ((!quick)); then
    run flow-cavity-vs-gerris-b8 "$root/bench/flow_cavity_vs_gerris.sh" --cells-per-side "$flow_n" \
      --steps "$((flow_steps / 2 > 0 ? flow_steps / 2 : 1))" --block-cells 8 --pairs "$repeat"
  fi
else
  echo "== flow-cavity-vs-gerris: skipped (Gerris not installed: scripts/install-deps.sh --bench)"
fi
run flow-cavity "$sanguis" bench flow-cavity --cells-per-side "$flow_n" --steps "$flow_steps" --threads 1
# The same out of the last-level cache (128^3: x and the right-hand side about 48 MB on the
# 32^3 blocks such a grid gets), where issue #6's smoother bandwidth target is hardest.
run flow-cavity-large "$sanguis" bench flow-cavity --cells-per-side "$flow_big_n" --steps 2 --threads 1
run flow-adaptive "$sanguis" bench flow-adaptive --steps "$wake_steps" --threads 2
run flow-adapt-vs-uniform "$root/bench/flow_adapt_vs_uniform.sh" --steps "$flow_steps" \
  --threads 1 --repeat "$repeat"

echo "results: $results ($(wc -l < "$results") JSON lines)"
exit "$failed"
