#!/usr/bin/env bash
# Side-by-side benchmark "dem-spheres": LAMMPS (bench/lammps/in.dem-spheres)
# against `sanguis bench dem-spheres`, same N and number of steps, one thread per
# MPI process, P processes each (default 1; P > 1 runs both under mpirun). The case
# is defined in bench/README.md.
#
#   bench/dem_spheres_vs_lammps.sh [--particles N] [--steps S] [--repeat K]
#                                  [--seed SEED] [--processes P] [--logdir DIR]
#
# Environment: SANGUIS (default build/app/sanguis under the repository root),
#              LMP (default lmp).
#
# stdout: one JSON line per run, alternating LAMMPS and sanguis K times, e.g.
#   {"benchmark":"dem-spheres","code":"lammps","particles":32000,"steps":2000,
#    "threads":1,"seconds":8.1,"particle_steps_per_s":7.9e6}
# then one summary line with the median particle_steps_per_s of each code and
# "ratio_sanguis_over_lammps" (> 1: sanguis is faster). Progress goes to stderr.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
input="$root/bench/lammps/in.dem-spheres"
sanguis="${SANGUIS:-$root/build/app/sanguis}"
lmp="${LMP:-lmp}"
python=/usr/bin/python3
[[ -x $python ]] || python=python3

particles=32000
steps=2000
repeat=1
seed=4928459
processes=1
logdir=""
keep=""

usage() { sed -n '2,16p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
die() { echo "dem_spheres_vs_lammps: $*" >&2; exit 2; }

while [[ $# -gt 0 ]]; do
  case "$1" in
    --particles) particles="${2:?--particles needs a value}"; shift 2 ;;
    --steps) steps="${2:?--steps needs a value}"; shift 2 ;;
    --repeat) repeat="${2:?--repeat needs a value}"; shift 2 ;;
    --seed) seed="${2:?--seed needs a value}"; shift 2 ;;
    --processes) processes="${2:?--processes needs a value}"; shift 2 ;;
    --logdir) logdir="${2:?--logdir needs a value}"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) usage >&2; die "unknown argument: $1" ;;
  esac
done
for v in particles steps repeat seed processes; do
  [[ ${!v} =~ ^[1-9][0-9]*$ ]] || die "--$v must be a positive integer (got '${!v}')"
done

# ---- prerequisites -----------------------------------------------------------
if [[ ! -x $sanguis ]]; then
  die "sanguis executable not found at '$sanguis' (build it with 'make build', or set SANGUIS=/path/to/sanguis)"
fi
command -v "$lmp" >/dev/null 2>&1 ||
  die "LAMMPS executable '$lmp' not found (install it with 'make bench-deps' or 'scripts/install-deps.sh --bench', or set LMP=...)"
launch=()
if ((processes > 1)); then
  command -v mpirun >/dev/null 2>&1 || die "--processes $processes needs mpirun (openmpi-bin)"
  launch=(mpirun -np "$processes" --allow-run-as-root --oversubscribe)
fi
lmp_help="$("$lmp" -h 2>/dev/null || true)"
grep -qw GRANULAR <<<"$lmp_help" || die "'$lmp' was built without the GRANULAR package"
[[ -f $input ]] || die "missing LAMMPS input $input"

if [[ -n $logdir ]]; then
  mkdir -p "$logdir"
  workdir="$(cd "$logdir" && pwd)"
else
  workdir="$(mktemp -d "${TMPDIR:-/tmp}/dem-spheres-bench.XXXXXX")"
  trap 'rm -rf "$workdir"' EXIT
  keep=" (rerun with --logdir DIR to keep the logs)"
fi
results="$workdir/results.jsonl"
: >"$results"

# ---- parsing helpers (plain python3, no extra packages) ------------------------
# lammps_json LOG N S: JSON line from "Loop time of X on P procs for S steps with N atoms"
lammps_json() {
  "$python" - "$@" <<'PY'
import json, re, sys
log, n, s, p = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
pat = re.compile(r"^Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms")
hits = []
with open(log) as f:
    for line in f:
        m = pat.match(line)
        if m and int(m.group(3)) == s:
            hits.append((float(m.group(1)), int(m.group(2)), int(m.group(4))))
if not hits:
    sys.exit(f"no 'Loop time of ... for {s} steps' line in {log}")
seconds, procs, atoms = hits[0]  # the timed run comes first; the diagnostics run has 0 steps
if atoms != n:
    sys.exit(f"LAMMPS ran with {atoms} atoms, expected {n} (atoms lost?)")
if procs != p:
    sys.exit(f"LAMMPS ran on {procs} procs, expected {p}")
print(json.dumps({"benchmark": "dem-spheres", "code": "lammps", "particles": atoms,
                  "steps": s, "threads": 1, "processes": procs, "seconds": seconds,
                  "particle_steps_per_s": atoms * s / seconds}, separators=(",", ":")))
PY
}

# sanguis_json OUT N S: the last JSON line of `sanguis bench` output, checked
sanguis_json() {
  "$python" - "$@" <<'PY'
import json, sys
out, n, s = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rec = None
with open(out) as f:
    for line in f:
        line = line.strip()
        if not line.startswith("{"):
            continue
        try:
            d = json.loads(line)
        except ValueError:
            continue
        if isinstance(d, dict) and d.get("benchmark") == "dem-spheres":
            rec = d
if rec is None:
    sys.exit(f"no dem-spheres JSON line in the sanguis output ({out})")
for key, want in (("particles", n), ("steps", s)):
    if int(rec.get(key, -1)) != want:
        sys.exit(f"sanguis reported {key}={rec.get(key)}, expected {want}")
if "particle_steps_per_s" not in rec:
    rec["particle_steps_per_s"] = rec["particles"] * rec["steps"] / float(rec["seconds"])
rec.setdefault("code", "sanguis")
print(json.dumps(rec, separators=(",", ":")))
PY
}

# summary RESULTS N S K: medians per code and the ratio
summary() {
  "$python" - "$@" <<'PY'
import json, statistics, sys
path, n, s, k, p = (sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]),
                    int(sys.argv[5]))
rates, secs = {}, {}
with open(path) as f:
    for line in f:
        d = json.loads(line)
        rates.setdefault(d["code"], []).append(float(d["particle_steps_per_s"]))
        secs.setdefault(d["code"], []).append(float(d["seconds"]))
med = {c: statistics.median(v) for c, v in rates.items()}
out = {"benchmark": "dem-spheres", "summary": True, "particles": n, "steps": s,
       "threads": 1, "processes": p, "repeat": k}
for c in ("lammps", "sanguis"):
    out[f"{c}_median_seconds"] = statistics.median(secs[c])
    out[f"{c}_median_particle_steps_per_s"] = med[c]
out["ratio_sanguis_over_lammps"] = med["sanguis"] / med["lammps"]
print(json.dumps(out, separators=(",", ":")))
PY
}

# ---- runs --------------------------------------------------------------------
export OMP_NUM_THREADS=1
echo "dem-spheres: N=$particles steps=$steps repeat=$repeat processes=$processes; lammps: $lmp, sanguis: $sanguis; logs in $workdir" >&2
for ((r = 1; r <= repeat; r++)); do
  log="$workdir/lammps.$r.log"
  echo "dem-spheres: [$r/$repeat] lammps ..." >&2
  if ! (cd "$workdir" && "${launch[@]}" "$lmp" -nocite -screen none -log "$log" -in "$input" \
        -var particles "$particles" -var steps "$steps" -var seed "$seed"); then
    tail -n 20 "$log" >&2 || true
    die "LAMMPS failed (log: $log)$keep"
  fi
  line="$(lammps_json "$log" "$particles" "$steps" "$processes")" || die "could not parse the LAMMPS log $log$keep"
  echo "$line" | tee -a "$results"

  out="$workdir/sanguis.$r.out"
  echo "dem-spheres: [$r/$repeat] sanguis ..." >&2
  if ! "${launch[@]}" "$sanguis" bench dem-spheres --particles "$particles" --steps "$steps" --threads 1 >"$out"; then
    tail -n 20 "$out" >&2 || true
    die "sanguis bench dem-spheres failed (output: $out)$keep"
  fi
  line="$(sanguis_json "$out" "$particles" "$steps")" || die "could not parse the sanguis output $out$keep"
  echo "$line" | tee -a "$results"
done

summary "$results" "$particles" "$steps" "$repeat" "$processes"
