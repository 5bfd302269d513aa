#!/usr/bin/env bash
# Scaling on one node and rank independence (perf/README.md, "Scaling"): the quick start and a
# 3D elastic cube of N^3 points (default 100^3 = 1e6, delta = 3.015 dx, fixed step, a few steps)
# on 1 rank x 1 thread, 1 rank x 2 threads and 2 ranks x 1 thread, the speed-ups of the steps'
# wall time (the region mupm::Solver::step, max over ranks: set-up, stable-step estimate and
# output left out), then the quick start on 3 and 4 ranks (oversubscribed) with
# its final fields compared bit for bit with the 1-rank run's.
#
# Usage, from the repository root with mupm built in ./build:
#   perf/scaling.sh [MUPM]        environment: N (100), STEPS (5), WORK (a temporary folder),
#                                 CASES ("quickstart cube")
# Run it on an otherwise idle machine.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
mupm=$(realpath "${1:-$root/build/mupm}")
n=${N:-100}
steps=${STEPS:-5}
work=${WORK:-$(mktemp -d)}
mkdir -p "$work" && cd "$work"
flags=(--allow-run-as-root)
[[ $(id -u) == 0 ]] || flags=()
python=/usr/bin/python3

source "$root/perf/cube_input.sh"
cube() {  # cube FOLDER: an elastic cube, base held, top pulled at 1 cm/s
  cube_input "$1" "$n" 0.001 3.015 "$steps" "Micropolar Solid" \
    '<ParameterList name="base"><Parameter name="Type" type="string" value="Displacement"/><Parameter name="Region" type="string" value="Layer -z"/><Parameter name="Component" type="string" value="z"/></ParameterList><ParameterList name="pull"><Parameter name="Type" type="string" value="Velocity"/><Parameter name="Region" type="string" value="Layer +z"/><Parameter name="Component" type="string" value="z"/><Parameter name="Value" type="double" value="0.01"/></ParameterList>'
}

run() {  # run NAME RANKS THREADS XML: prints the seconds of the steps
  local name=$1 np=$2 t=$3 xml=$4 bind=core
  # a rank of T threads gets the node (one rank of this machine's 2 cores); oversubscribed runs
  # are not pinned
  ((np > 2 || t > 1)) && bind=none
  OMP_NUM_THREADS=$t OMP_PROC_BIND=$( ((np > 2)) && echo false || echo spread) \
    OMP_PLACES=threads mpirun "${flags[@]}" --oversubscribe --bind-to "$bind" -np "$np" \
    -x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES "$mupm" "$xml" >"$name.out" 2>&1 ||
    { tail -5 "$name.out" >&2; exit 1; }
  awk '$1 == "region" && $2 == "mupm::Solver::step" {print $5}' "$name.out"
}

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-12s %10s %10s %10s %8s %8s\n' case "1x1 s" "1x2 s" "2x1 s" threads ranks
for c in ${CASES:-quickstart cube}; do
  for cfg in "1 1" "1 2" "2 1"; do
    set -- $cfg
    name=$c-$1x$2
    if [[ $c == quickstart ]]; then
      sed "s|<Parameter name=\"Folder\" type=\"string\" value=\"[^\"]*\"/>|<Parameter name=\"Folder\" type=\"string\" value=\"$name\"/>|" \
        "$root/inputs/quickstart.xml" >"$name.xml"
    else
      cube "$name" >"$name.xml"
    fi
    eval "t_$1x$2=$(run "$name" "$1" "$2" "$name.xml")"
  done
  printf '%-12s %10s %10s %10s %8.2f %8.2f\n' "$c" "$t_1x1" "$t_1x2" "$t_2x1" \
    "$(echo "$t_1x1 / $t_1x2" | bc -l)" "$(echo "$t_1x1 / $t_2x1" | bc -l)"
done
[[ " ${CASES:-quickstart} " == *" quickstart "* ]] || exit 0
for np in 3 4; do
  name=quickstart-${np}x1
  sed "s|<Parameter name=\"Folder\" type=\"string\" value=\"[^\"]*\"/>|<Parameter name=\"Folder\" type=\"string\" value=\"$name\"/>|" \
    "$root/inputs/quickstart.xml" >"$name.xml"
  run "$name" "$np" 1 "$name.xml" >/dev/null
done
"$python" - <<'PY'
import h5py
ref = h5py.File("quickstart-1x1/fields_000003000.h5")
for run in ("1x2", "2x1", "3x1", "4x1"):
    with h5py.File(f"quickstart-{run}/fields_000003000.h5") as f:
        same = sorted(f) == sorted(ref) and all(f[k][...].tobytes() == ref[k][...].tobytes() for k in ref)
    print(f"quick start {run}: final fields {'bit-identical to' if same else 'DIFFER from'} 1x1's ({len(ref)} fields)")
    assert same, run
PY
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
