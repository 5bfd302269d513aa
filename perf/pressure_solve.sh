#!/usr/bin/env bash
# The semi-implicit pressure solve's cost (Solver->Pressure Integration = Semi-Implicit,
# include/mupm/solvers/pressure_projection.hpp): GMRES iterations per step, time per step of the
# projection (its solve, its assembly) and its share of the whole step, from the run's kernel
# timers (max over ranks) and time_series.csv, on 1 rank and on 2 ranks (1 thread each).
#   [PS='<Parameter .../>...'] [RANKS='1 2'] perf/pressure_solve.sh MUPM [CASE...]
#   CASE: example1 | cube50 | cube100 | crack | crack-kept | crack-whole (all by default)
#         | square<N> | cube<N> | cube<N>-1.5
#   PS: Pressure Solve parameters added to every case's (e.g. the preconditioner:
#   PS='<Parameter name="Preconditioner" type="string" value="ILU"/>').
# example1: inputs/example1_deformation_driven_explicit.xml (Example 1 case 2, 100 x 100, delta = 3.015 dx)
#   with incompressible water at the automatic (drained) step, 200 steps of the load's ramp.
# cube50: a saturated 3D cube of 50^3 points, delta = 3.015 dx, incompressible, base fixed, top
#   drained and pressed at 1 cm/s, 10 steps. cube100: the same at 100^3 = 1e6 points with
#   delta = 1.5 dx (at 3.015 dx the projection's matrix, two horizons wide, would hold ~920
#   entries a row: 11 GB at 1e6 points, and its ILU as much: beyond this machine's 24 GiB).
# crack: inputs/example1_fluid_driven_explicit.xml (Example 1 case 1, 100 x 100, fracture flow:
#   the crack water's pressure in the same solve, whose network rows change every step) with
#   incompressible water at the automatic step, 150 steps, the default Pressure Solve; crack-kept:
#   the same with Drop Tolerance = 0 (the ILU of the whole matrix); crack-whole: also Preconditioner
#   Refresh Interval = 1 (that ILU computed every step, as before both settings existed).
# square<N>: a saturated 2D square of 1 m, N x N points (spacing 1/N), delta = 3.015 dx,
#   incompressible, base fixed, top drained and pressed at 1 cm/s, 20 steps: the refinement
#   series at fixed delta / dx. cube<N>: the cube above at N^3 points (delta = 3.015 dx; -1.5:
#   1.5 dx), 10 steps.
# Writes into a temporary folder; prints one table row per case and rank count, and the
# projection's parts per step (ms; max over ranks): `compose` the network's rows added to the
# kept matrix, `setup` the preconditioner's set-ups (count in parentheses), `krylov` the
# solve's iterations, `rhs+` the rest of the projection (right-hand side, correction).
set -euo pipefail
MUPM=$(realpath "$1")
shift
SRC=$(cd "$(dirname "$0")/.." && pwd)
PY=/usr/bin/python3
cases=("$@")
((${#cases[@]})) || cases=(example1 cube50 cube100 crack crack-kept crack-whole)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

# The edits both 2D cases make: incompressible water, FOLDER, no field or checkpoint output, a
# time-series row every step.
shared_edits() {  # shared_edits FOLDER: sed arguments
  printf '%s\n' -e 's|(<Parameter name="Fluid Bulk Modulus"[^>]*>)|\1<Parameter name="Incompressible" type="bool" value="true"/>|' \
    -e "s|<Parameter name=\"Folder\" type=\"string\" value=\"[^\"]*\"/>|<Parameter name=\"Folder\" type=\"string\" value=\"$1\"/>|" \
    -e 's#name="(Field|Checkpoint) Interval" type="int" value="[0-9]+"#name="\1 Interval" type="int" value="0"#' \
    -e 's|name="Time Series Interval" type="int" value="[0-9]+"|name="Time Series Interval" type="int" value="1"|'
}
PS=${PS:-}
PSL="<ParameterList name=\"Pressure Solve\">$PS</ParameterList>"
example1() {  # example1 FOLDER
  local shared
  mapfile -t shared < <(shared_edits "$1")
  sed -E -e "s|<Parameter name=\"Time Step\" type=\"double\" value=\"[^\"]*\"/>|<Parameter name=\"Automatic Time Step\" type=\"bool\" value=\"true\"/><Parameter name=\"Pressure Integration\" type=\"string\" value=\"Semi-Implicit\"/>$PSL|" \
    -e 's|<Parameter name="Number of Steps" type="int" value="[0-9]+"/>|<Parameter name="Number of Steps" type="int" value="200"/>|' \
    "${shared[@]}" "$SRC/inputs/example1_deformation_driven_explicit.xml"
}
crack() {  # crack FOLDER DROP_TOLERANCE REFRESH_INTERVAL
  local shared
  mapfile -t shared < <(shared_edits "$1")
  sed -E -e "s|<Parameter name=\"Physics\" type=\"string\" value=\"Hydro-Mechanical\"/>|&<Parameter name=\"Pressure Integration\" type=\"string\" value=\"Semi-Implicit\"/><ParameterList name=\"Pressure Solve\"><Parameter name=\"Drop Tolerance\" type=\"double\" value=\"$2\"/><Parameter name=\"Preconditioner Refresh Interval\" type=\"int\" value=\"$3\"/>$PS</ParameterList>|" \
    -e 's|<Parameter name="End Time" type="double" value="[^"]*"/>|<Parameter name="Number of Steps" type="int" value="150"/>|' \
    "${shared[@]}" "$SRC/inputs/example1_fluid_driven_explicit.xml"
}
source "$SRC/perf/cube_input.sh"
cube() {  # cube FOLDER N HORIZON STEPS
  local bcs="" comp
  for comp in x y z; do
    bcs+="<ParameterList name=\"base $comp\"><Parameter name=\"Type\" type=\"string\" value=\"Displacement\"/><Parameter name=\"Region\" type=\"string\" value=\"Layer -z\"/><Parameter name=\"Component\" type=\"string\" value=\"$comp\"/></ParameterList>"
  done
  bcs+='<ParameterList name="drain"><Parameter name="Type" type="string" value="Pore Pressure"/><Parameter name="Region" type="string" value="Layer +z"/></ParameterList>'
  bcs+='<ParameterList name="press"><Parameter name="Type" type="string" value="Velocity"/><Parameter name="Region" type="string" value="Layer +z"/><Parameter name="Component" type="string" value="z"/><Parameter name="Value" type="double" value="-0.01"/></ParameterList>'
  cube_input "$1" "$2" 0.01 "$3" "$4" Hydro-Mechanical "$bcs" \
    "<Parameter name=\"Automatic Time Step\" type=\"bool\" value=\"true\"/><Parameter name=\"Pressure Integration\" type=\"string\" value=\"Semi-Implicit\"/>$PSL" \
    '<Parameter name="Water Density" type="double" value="1000"/><Parameter name="Fluid Bulk Modulus" type="double" value="2.2e9"/><Parameter name="Incompressible" type="bool" value="true"/><Parameter name="Hydraulic Conductivity" type="double" value="5.11e-5"/>'
}
square() {  # square FOLDER N
  local bcs="" comp
  for comp in x y; do
    bcs+="<ParameterList name=\"base $comp\"><Parameter name=\"Type\" type=\"string\" value=\"Displacement\"/><Parameter name=\"Region\" type=\"string\" value=\"Layer -y\"/><Parameter name=\"Component\" type=\"string\" value=\"$comp\"/></ParameterList>"
  done
  bcs+='<ParameterList name="drain"><Parameter name="Type" type="string" value="Pore Pressure"/><Parameter name="Region" type="string" value="Layer +y"/></ParameterList>'
  bcs+='<ParameterList name="press"><Parameter name="Type" type="string" value="Velocity"/><Parameter name="Region" type="string" value="Layer +y"/><Parameter name="Component" type="string" value="y"/><Parameter name="Value" type="double" value="-0.01"/></ParameterList>'
  local dx
  dx=$("$PY" -c "print(1.0 / $2)")
  cube_input "$1" "$2" "$dx" 3.015 20 Hydro-Mechanical "$bcs" \
    "<Parameter name=\"Automatic Time Step\" type=\"bool\" value=\"true\"/><Parameter name=\"Pressure Integration\" type=\"string\" value=\"Semi-Implicit\"/>$PSL" \
    '<Parameter name="Water Density" type="double" value="1000"/><Parameter name="Fluid Bulk Modulus" type="double" value="2.2e9"/><Parameter name="Incompressible" type="bool" value="true"/><Parameter name="Hydraulic Conductivity" type="double" value="5.11e-5"/>' |
    sed -E -e 's|<Parameter name="Dimension" type="int" value="3"/>|<Parameter name="Dimension" type="int" value="2"/>|' \
      -e "s|value=\"\{$2, $2, $2\}\"|value=\"{$2, $2}\"|" -e 's|value="\{-z, \+z\}"|value="{-y, +y}"|'
}

# it/step: Krylov iterations (CG, or GMRES with mirrored pressure layers); solve ms: the
# projection per step without its assembly (once per run here: no bond breaks); rest ms: the
# rest of the step (solid, fluid, output); share: the projection's part of the step without the
# assembly.
printf '%-11s %5s %8s %5s %7s %9s %9s %10s %6s\n' case ranks points steps "it/step" "solve ms" "rest ms" "assemble s" share
for c in "${cases[@]}"; do
  case $c in
    example1) example1 "$c" >"$c.xml" ;;
    cube50) cube "$c" 50 3.015 10 >"$c.xml" ;;
    cube100) cube "$c" 100 1.5 5 >"$c.xml" ;;
    crack) crack "$c" 0.02 20 >"$c.xml" ;;
    crack-kept) crack "$c" 0 20 >"$c.xml" ;;
    crack-whole) crack "$c" 0 1 >"$c.xml" ;;
    square[0-9]*) square "$c" "${c#square}" >"$c.xml" ;;
    cube[0-9]*-1.5) n=${c#cube}; cube "$c" "${n%-1.5}" 1.5 10 >"$c.xml" ;;
    cube[0-9]*) cube "$c" "${c#cube}" 3.015 10 >"$c.xml" ;;
    *) echo "unknown case $c" >&2; exit 1 ;;
  esac
  for np in ${RANKS:-1 2}; do
    rm -rf "$c"
    OMP_NUM_THREADS=1 OMP_PROC_BIND=false mpirun --allow-run-as-root --bind-to none -np $np \
      -x OMP_NUM_THREADS -x OMP_PROC_BIND "$MUPM" "$c.xml" >"$c-$np.out" 2>&1 ||
      { tail -20 "$c-$np.out"; exit 1; }
    "$PY" - "$c" "$np" "$c-$np.out" <<'PY'
import csv, re, sys
name, np_, out = sys.argv[1], sys.argv[2], open(sys.argv[3]).read()
def region(label):  # max seconds over ranks, calls
    m = re.search(r"^region\s+" + re.escape(label) + r"\s+(\d+)\s+\S+\s+(\S+)", out, re.M)
    return (float(m.group(2)), int(m.group(1))) if m else (0.0, 0)
step, steps = region("mupm::Solver::step")
proj, _ = region("mupm::Pressure::projection")
asm, nasm = region("mupm::Pressure::assemble")
points = re.search(r"(\d+) points", out)
rows = list(csv.DictReader(open(f"{name}/time_series.csv")))[1:]
its = sum(float(r["pressure_solve_iterations"]) for r in rows) / max(1, len(rows))
solve, rest = (proj - asm) / steps, (step - proj) / steps
print("%-11s %5s %8s %5d %7.1f %9.1f %9.1f %10.2f %5.0f%%" % (
    name, np_, points.group(1) if points else "?", steps, its, 1e3 * solve, 1e3 * rest, asm,
    100 * solve / (solve + rest)))
compose, _ = region("mupm::Pressure::compose")
setup, nsetup = region("mupm::LinearSolve::setup")
refresh, _ = region("mupm::LinearSolve::refresh")
amg, namg = region("mupm::AMG::setup")
krylov, _ = region("mupm::LinearSolve::solve")
print("    per step: compose %.2f, setup %.2f (%d AMG set-ups), krylov %.2f, rhs+ %.2f ms" % (
    1e3 * compose / steps, 1e3 * (setup + refresh) / steps, namg, 1e3 * krylov / steps,
    1e3 * (proj - asm - compose - krylov - refresh - setup) / steps))
PY
  done
done
