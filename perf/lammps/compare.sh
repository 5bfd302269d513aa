#!/usr/bin/env bash
# Side-by-side of LAMMPS pair_style peri/lps and mupm's whole solid force evaluation
# (bench_solid BM_SolidForces<3>: pass 1 + ghost refresh + pass 2) on the same 50^3 simple-cubic
# grid, free surfaces, same horizon: time per bond-update and the ratio LAMMPS / mupm.
#
# A bond-update is one bond of one point in one force evaluation, counted from both ends (the
# full neighbour list: 122 per interior point at 3.015 dx, 256 at 4.015 dx), the same count for
# both programs (checked below).
#
# Usage, from the repository root with the project built in ./build:
#   perf/lammps/compare.sh
# Environment: FACTORS ("3.015 4.015"), STEPS (100, LAMMPS steps), REPS (3, runs of each program;
# medians are quoted), PARALLEL ("1 2": LAMMPS MPI ranks = mupm OpenMP threads), BUILD (build).
# Run it on an otherwise idle machine: the two programs are timed one after the other.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
build=${BUILD:-build}
factors=${FACTORS:-"3.015 4.015"}
steps=${STEPS:-100}
reps=${REPS:-3}
parallel=${PARALLEL:-"1 2"}
n=50  # bench_solid registers its 3D benchmarks on 50^3 only

if ! command -v lmp > /dev/null; then
  echo "LAMMPS (lmp) not found. On Debian/Ubuntu: apt-get install lammps" >&2
  exit 1
fi
bench=$build/perf/bench_solid
if [[ ! -x $bench ]]; then
  echo "$bench not found: build the project first (cmake --build $build -j2)" >&2
  exit 1
fi
mpirun_flags=(--bind-to core --map-by core)
[[ $(id -u) == 0 ]] && mpirun_flags+=(--allow-run-as-root)

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"

median() { sort -g | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }

results=()
for f in $factors; do
  f1000=$(awk -v f="$f" 'BEGIN {printf "%d", f * 1000 + 0.5}')
  for p in $parallel; do
    # LAMMPS: p MPI ranks of 1 thread (this Debian build has no OPENMP package).
    : > "$work/lmp_loop"
    : > "$work/lmp_pair"
    for ((r = 0; r < reps; r++)); do
      log=$work/lmp_${f}_${p}_$r.log
      launch=(lmp)
      ((p > 1)) && launch=(mpirun -np "$p" "${mpirun_flags[@]}" lmp)
      OMP_NUM_THREADS=1 "${launch[@]}" -in "$here/in.lps_cube" -var n $n -var factor "$f" \
        -var steps "$steps" -log "$log" -screen none
      bonds=$(awk '/^BONDS/ {printf "%.0f", $2}' "$log")
      awk '/^Loop time of/ {t = $4} END {print t}' "$log" >> "$work/lmp_loop"
      # Pair row: min avg max; the max is the rank on the critical path.
      awk '/^Pair +\|/ {t = $7} END {print t}' "$log" >> "$work/lmp_pair"
    done
    lmp_loop=$(median < "$work/lmp_loop")
    lmp_pair=$(median < "$work/lmp_pair")

    # mupm: one rank, p OpenMP threads, medians of reps repetitions.
    json=$work/mupm_${f}_$p.json
    OMP_NUM_THREADS=$p OMP_PROC_BIND=spread OMP_PLACES=threads "$bench" \
      --benchmark_filter="^BM_SolidForces<3>/$n/$f1000/" --benchmark_repetitions="$reps" \
      --benchmark_report_aggregates_only=true --benchmark_min_time=2 \
      --benchmark_format=json > "$json" 2> /dev/null
    # The median aggregate (REPS > 1) or the single run (REPS = 1, no aggregates).
    read -r mupm_ms mupm_bonds < <(python3 -c '
import json, sys
runs = json.load(open(sys.argv[1]))["benchmarks"]
pick = [b for b in runs if b.get("aggregate_name") == "median"] or runs
b = pick[0]
scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
print(b["real_time"] * scale, int(b["bonds"]))
' "$json")
    if [[ $mupm_bonds != "$bonds" ]]; then
      echo "warning: bond counts differ (LAMMPS $bonds, mupm $mupm_bonds)" >&2
    fi
    results+=("$f $p $bonds $lmp_loop $lmp_pair $mupm_ms")
  done
done
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"

echo
echo "50^3 simple cubic, $steps LAMMPS steps, medians of $reps runs; ns per bond-update"
printf '%-6s %-12s %12s %12s %12s %12s %10s %10s\n' delta/dx "ranks|thr" bonds \
  "lmp loop" "lmp pair" "mupm forces" "loop/mupm" "pair/mupm"
for row in "${results[@]}"; do
  read -r f p bonds loop pair ms <<< "$row"
  awk -v f="$f" -v p="$p" -v b="$bonds" -v loop="$loop" -v pair="$pair" -v ms="$ms" \
    -v s="$steps" 'BEGIN {
      l = loop / (s * b) * 1e9; q = pair / (s * b) * 1e9; m = ms * 1e-3 / b * 1e9
      printf "%-6s %-12s %12d %12.2f %12.2f %12.2f %10.2f %10.2f\n", f, p, b, l, q, m, l / m, q / m
    }'
done
echo
echo "lmp loop: LAMMPS loop time / (steps x bonds) (pair + neighbour check + integration + comm);"
echo "lmp pair: its Pair row (max over ranks); mupm forces: bench_solid BM_SolidForces<3> median."
echo "ratio > 1: LAMMPS takes longer per bond-update than mupm."
