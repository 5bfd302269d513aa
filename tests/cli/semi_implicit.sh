#!/usr/bin/env bash
# Solver->Pressure Integration = Semi-Implicit from the command line (include/mupm/solvers/
# pressure_projection.hpp), on the consolidation input with incompressible water, and on
# Example 1 case 1 at 66 x 66 (fracture flow: the crack water's pressure in the same solve):
#  - a restart on the same rank count continues bit for bit (fields and checkpoint);
#  - 1 rank x 2 threads and 2 ranks x 1 thread agree to the pressure solve's tolerance (the
#    Krylov iterates depend on the reductions' order and the preconditioner's subdomains);
#  - the water mass and the energy balances close (time_series.csv; the crack water's too);
#  - what it does not take is refused by name, by the run and by --validate.
source "$(dirname "$0")/common.sh"
source "$(dirname "$0")/error_cases.sh"

# si_input FOLDER STEPS RESTART: inputs/consolidation.xml, Semi-Implicit, incompressible water.
si_input() {
  sed -E -e "s|<Parameter name=\"Fluid Substeps\" type=\"int\" value=\"0\"/>|<Parameter name=\"Pressure Integration\" type=\"string\" value=\"Semi-Implicit\"/>|" \
    -e "s|(<Parameter name=\"Fluid Bulk Modulus\"[^>]*>)|\1<Parameter name=\"Incompressible\" type=\"bool\" value=\"true\"/>|" \
    -e "s|<Parameter name=\"Folder\" type=\"string\" value=\"[^\"]*\"/>|<Parameter name=\"Folder\" type=\"string\" value=\"$1\"/>|" \
    -e "s|<Parameter name=\"Number of Steps\" type=\"int\" value=\"[0-9]+\"/>|<Parameter name=\"Number of Steps\" type=\"int\" value=\"$2\"/><Parameter name=\"Restart From\" type=\"string\" value=\"$3\"/>|" \
    -e "s|<Parameter name=\"Field Interval\" type=\"int\" value=\"[0-9]+\"/>|<Parameter name=\"Field Interval\" type=\"int\" value=\"40\"/>|" \
    -e "s|<Parameter name=\"Checkpoint Interval\" type=\"int\" value=\"[0-9]+\"/>|<Parameter name=\"Checkpoint Interval\" type=\"int\" value=\"0\"/>|" \
    "$SRC/inputs/consolidation.xml"
}
si_input straight 160 "" >straight.xml
si_input first 80 "" >first.xml
si_input second 160 first/checkpoint.h5 >second.xml
si_input threads 160 "" >threads.xml
grep -q 'value="Semi-Implicit"' straight.xml && grep -q '"Incompressible"' straight.xml &&
  grep -q '"Restart From"' straight.xml || fail "inputs/consolidation.xml changed: straight.xml not derived"
run 2 1 straight.xml >straight.out 2>&1 || { cat straight.out; fail "straight.xml did not run"; }
grep -q "semi-implicit pressure" straight.out || { cat straight.out; fail "no semi-implicit line"; }
run 2 1 first.xml >first.out 2>&1 || { cat first.out; fail "first.xml did not run"; }
run 2 1 second.xml >second.out 2>&1 || { cat second.out; fail "second.xml did not run"; }
grep -q "restarted from first/checkpoint.h5 at step 80" second.out || fail "no restart line"
run 1 2 threads.xml >threads.out 2>&1 || { cat threads.out; fail "threads.xml did not run"; }
"$PYTHON" - <<'PY'
import csv, h5py, numpy as np
f = "fields_%09d.h5" % 160
with h5py.File("straight/" + f) as a, h5py.File("second/" + f) as b:
    for field in a:
        assert a[field][...].tobytes() == b[field][...].tobytes(), "restart: " + field
    print("restart on 2 ranks: %d fields equal bit for bit" % len(a))
with h5py.File("straight/checkpoint.h5") as a, h5py.File("second/checkpoint.h5") as b:
    for field in a["points"]:
        assert a["points"][field][...].tobytes() == b["points"][field][...].tobytes(), field
# 2 ranks x 1 thread against 1 rank x 2 threads (the files hold the points in global-id order).
with h5py.File("straight/" + f) as a, h5py.File("threads/" + f) as b:
    for field in ("pore_pressure", "displacement"):
        x, y = a[field][...], b[field][...]
        scale = np.abs(x).max()
        diff = np.abs(x - y).max() / scale
        print("2 ranks x 1 thread vs 1 rank x 2 threads: %s differs by %.2e of its largest value"
              % (field, diff))
        assert scale > 0 and diff < 1e-10, field
rows = list(csv.DictReader(open("straight/time_series.csv")))
last = rows[-1]
mass, error = float(last["fluid_mass"]), float(last["fluid_mass_error"])
assert abs(error) < 1e-10 * mass, ("water mass", error, mass)
work = max(abs(float(r["external_work"])) for r in rows)
assert abs(float(last["energy_error"])) < 1e-3 * work, ("solid energy", last["energy_error"], work)
coupling = max(abs(float(r["fluid_coupling_work"])) for r in rows)
assert abs(float(last["fluid_energy_error"])) < 1e-8 * coupling, ("fluid energy", last["fluid_energy_error"])
assert max(float(r["pressure_solve_iterations"]) for r in rows[1:]) > 0
print("water mass error %.2e of %.4g kg; solid energy error %.2e J of %.3g J; fluid %.2e J"
      % (error, mass, float(last["energy_error"]), work, float(last["fluid_energy_error"])))
PY

# With fracture flow (the crack water's pressure in the same solve): Example 1 case 1 at 66 x 66
# with incompressible water, 40 steps at the drained automatic step; the same checks, and the
# crack water's balance. A film of 1 um (not the input's 0.1 mm), so that the crack opens
# beyond it within the run and the cubic law's conductances change. The preconditioner (the
# default, AMG) is kept for 7 steps (Preconditioner Refresh Interval), so the straight run's
# hierarchy at step 21 is of its step 15 unless the checkpoint it writes at step 20 renews it:
# the restart, which builds it at step 21, continues it bit for bit only because it does
# (LinearSolve::renew; without it the accelerations differ). The recycling CG's space, which the
# checkpoint drops likewise, is tested in tests/solvers/test_pressure_projection.cpp (with AMG
# these solves are shorter than its 25-iteration cycle, so it would gather none here).
ff_input() {  # FOLDER STEPS RESTART [CHECKPOINT_INTERVAL]
  sed -E -e "s|<Parameter name=\"Physics\" type=\"string\" value=\"Hydro-Mechanical\"/>|&<Parameter name=\"Pressure Integration\" type=\"string\" value=\"Semi-Implicit\"/><ParameterList name=\"Pressure Solve\"><Parameter name=\"Preconditioner Refresh Interval\" type=\"int\" value=\"7\"/></ParameterList>|" \
    -e "s|(<Parameter name=\"Fluid Bulk Modulus\"[^>]*>)|\1<Parameter name=\"Incompressible\" type=\"bool\" value=\"true\"/>|" \
    -e "s|<Parameter name=\"End Time\" type=\"double\" value=\"0.5\"/>|<Parameter name=\"Number of Steps\" type=\"int\" value=\"$2\"/><Parameter name=\"Restart From\" type=\"string\" value=\"$3\"/>|" \
    -e "s|<Parameter name=\"Folder\" type=\"string\" value=\"[^\"]*\"/>|<Parameter name=\"Folder\" type=\"string\" value=\"$1\"/>|" \
    -e "s|<Parameter name=\"(Field\|Checkpoint) Interval\" type=\"int\" value=\"[0-9]+\"/>|<Parameter name=\"\1 Interval\" type=\"int\" value=\"0\"/>|" \
    -e "s|<Parameter name=\"Checkpoint Interval\" type=\"int\" value=\"0\"/>|<Parameter name=\"Checkpoint Interval\" type=\"int\" value=\"${4:-0}\"/>|" \
    -e "s|<Parameter name=\"Time Series Interval\" type=\"int\" value=\"[0-9]+\"/>|<Parameter name=\"Time Series Interval\" type=\"int\" value=\"1\"/>|" \
    -e "s|<Parameter name=\"Minimum Aperture\" type=\"double\" value=\"1e-4\"/>|<Parameter name=\"Minimum Aperture\" type=\"double\" value=\"1e-6\"/>|" \
    "$SRC/inputs/example1_fluid_driven_66_explicit.xml"
}
ff_input ff_straight 40 "" 20 >ff_straight.xml
ff_input ff_first 20 "" >ff_first.xml
ff_input ff_second 40 ff_first/checkpoint.h5 >ff_second.xml
ff_input ff_threads 40 "" >ff_threads.xml
for k in 'value="Semi-Implicit"' '"Incompressible"' '"Restart From"' 'Checkpoint Interval" type="int" value="20"' 'Refresh Interval" type="int" value="7"' 'Minimum Aperture" type="double" value="1e-6"'; do
  grep -q "$k" ff_straight.xml || fail "inputs/example1_fluid_driven_66_explicit.xml changed: ff_straight.xml lacks $k"
done
for c in ff_straight ff_first ff_second; do
  run 2 1 $c.xml >$c.out 2>&1 || { cat $c.out; fail "$c.xml did not run"; }
done
run 1 2 ff_threads.xml >ff_threads.out 2>&1 || { cat ff_threads.out; fail "ff_threads.xml did not run"; }
grep -q "drained: the pore pressure is semi-implicit" ff_straight.out || { cat ff_straight.out; fail "not the drained step"; }
grep -q "one solve per step (CG, AMG (hypre BoomerAMG" ff_straight.out || { cat ff_straight.out; fail "not CG with AMG"; }
"$PYTHON" - <<'PY'
import csv, h5py, numpy as np
with h5py.File("ff_straight/checkpoint.h5") as a, h5py.File("ff_second/checkpoint.h5") as b:
    for field in a["points"]:
        assert a["points"][field][...].tobytes() == b["points"][field][...].tobytes(), "restart: " + field
    print("fracture flow, restart on 2 ranks: %d checkpoint fields equal bit for bit" % len(a["points"]))
with h5py.File("ff_straight/checkpoint.h5") as a, h5py.File("ff_threads/checkpoint.h5") as b:
    for field in ("pore_pressure", "fracture_pressure", "displacement"):  # in global-id order
        x, y = a["points"][field][...], b["points"][field][...]
        scale = np.abs(x).max()
        diff = np.abs(x - y).max() / scale
        print("fracture flow, 2 ranks x 1 thread vs 1 rank x 2 threads: %s differs by %.2e of its largest value" % (field, diff))
        assert scale > 0 and diff < 1e-10, field
rows = list(csv.DictReader(open("ff_straight/time_series.csv")))
last = rows[-1]
water = float(last["fluid_mass"]) + float(last["fracture_fluid_mass"])
injected = float(last["fluid_inflow_injection"])
assert injected > 0 and float(last["fracture_fluid_mass"]) > 0.5 * injected
assert abs(float(last["fluid_mass_error"])) < 1e-10 * water, ("water mass", last["fluid_mass_error"])
scale = max(abs(float(r["fracture_fluid_skeleton_work"])) for r in rows)
assert abs(float(last["fracture_fluid_energy_error"])) < 1e-10 * scale, ("crack water", last["fracture_fluid_energy_error"])
fluid = max(abs(float(r["fluid_coupling_work"])) for r in rows)
assert abs(float(last["fluid_energy_error"])) < 1e-8 * max(fluid, scale), ("fluid energy", last["fluid_energy_error"])
print("fracture flow: water error %.2e of %.4g kg, injected %.3g kg; crack water balance %.2e J of %.3g J"
      % (float(last["fluid_mass_error"]), water, injected, float(last["fracture_fluid_energy_error"]), scale))
PY

# Refused by name: incompressible water without the semi-implicit scheme, and what the scheme
# does not have (eq 17's crack water force) or does not use (staggering, sub-cycling), and its physics.
hm='<Parameter name="Physics" type="string" value="Hydro-Mechanical"/>'
si='<Parameter name="Pressure Integration" type="string" value="Semi-Implicit"/>'
pores='<Parameter name="Porosity" type="double" value="0.3"/>'
fluid='<ParameterList name="Fluid"><Parameter name="Hydraulic Conductivity" type="double" value="1e-6"/><Parameter name="Incompressible" type="bool" value="true"/></ParameterList>'
base '' "$hm" | sed -e "s|<ParameterList name=\"Solver\">|$fluid&|" -e "s|<Parameter name=\"Bulk Modulus\"|$pores&|" >incompressible_explicit.xml
expect incompressible_explicit 2 'mupm->Fluid->Incompressible = true needs mupm->Solver->Pressure Integration = Semi-Implicit'
expect_dir incompressible_explicit_validate 'mupm->Fluid->Incompressible' --validate incompressible_explicit.xml
base '' "$hm$si<Parameter name=\"Fluid Substeps\" type=\"int\" value=\"0\"/>" | sed -e "s|<ParameterList name=\"Solver\">|$fluid&|" -e "s|<Parameter name=\"Bulk Modulus\"|$pores&|" >si_substeps.xml
expect si_substeps 2 'mupm->Solver->Pressure Integration = Semi-Implicit' 'Fluid Substeps are for Explicit'
base '' "$si" >si_solid.xml
expect si_solid 2 'mupm->Solver->Pressure Integration = Semi-Implicit' 'Physics = Hydro-Mechanical'
base '' "$hm$si" | sed -e "s|<ParameterList name=\"Solver\">|<ParameterList name=\"Fracture\"><Parameter name=\"Fracture Flow\" type=\"bool\" value=\"true\"/><Parameter name=\"Crack Water Force\" type=\"string\" value=\"Eq 17\"/></ParameterList>$fluid&|" -e "s|<Parameter name=\"Bulk Modulus\"|$pores&|" >si_eq17.xml
expect si_eq17 2 'mupm->Solver->Pressure Integration = Semi-Implicit' 'Fracture->Crack Water Force must be Face Pressure'
sed -e 's|<Parameter name="Type" type="string" value="Pore Pressure"/>|<Parameter name="Type" type="string" value="Fluid Flux"/>|' straight.xml >si_flux.xml
grep -q 'value="Fluid Flux"' si_flux.xml || fail "si_flux.xml not derived"
expect si_flux 2 'mupm->Solver->Pressure Integration = Semi-Implicit does not take mupm->Boundary Conditions->' '->Type = Fluid Flux yet'
expect_dir si_flux_validate 'Type = Fluid Flux yet' --validate si_flux.xml
# Pressure Solve's limits at input (exit 2, by name and range) and a solve that does not converge
# stopping the run (exit 3) with the parameters to change: one CG iteration is not enough for
# the consolidation column's first step.
ps() {  # ps NAME PARAMETERS: straight.xml with these Pressure Solve parameters
  sed -e "s|$si|$si<ParameterList name=\"Pressure Solve\">$2</ParameterList>|" straight.xml >"$1.xml"
  grep -q 'name="Pressure Solve"' "$1.xml" || fail "$1.xml not derived"
}
ps si_recycle '<Parameter name="Recycled Vectors" type="int" value="1000000"/>'
expect si_recycle 2 'mupm->Solver->Pressure Solve->Recycled Vectors = 1000000 is not valid' 'Max: 24'
ps si_threshold '<Parameter name="AMG Strong Threshold" type="double" value="1.5"/>'
expect si_threshold 2 'mupm->Solver->Pressure Solve->AMG Strong Threshold = 1.5 is not valid'
ps si_diverge '<Parameter name="Maximum Iterations" type="int" value="1"/>'
expect si_diverge 3 'the pressure solve did not converge at t = ' 'after 1 iterations' 'mupm->Solver->Pressure Solve: Tolerance, Maximum Iterations, Preconditioner'
echo "semi_implicit: all checks passed"
