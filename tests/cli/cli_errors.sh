#!/usr/bin/env bash
# Each class of input error stops both ranks with exit code 2 and a message naming the
# parameter's full path; none hangs (each run has a time limit) or crashes.
source "$(dirname "$0")/common.sh"
source "$(dirname "$0")/error_cases.sh"

base '<Parameter name="Spacingg" type="double" value="1"/>' '' >unknown.xml
expect unknown 2 'Spacingg' 'mupm->Discretization' 'valid parameters'
base '' '<Parameter name="Time Step" type="string" value="fast"/>' >wrong_type.xml
expect wrong_type 2 'Time Step' 'mupm->Solver' 'double'
base '' '<Parameter name="Time Step" type="double" value="-1"/>' >out_of_range.xml
expect out_of_range 2 'Time Step' 'mupm->Solver'
base '' '' | sed '/Spacing/d' >missing.xml
expect missing 2 'mupm->Discretization->Spacing' 'missing'
base '<Parameter name="Origin" type="Array(double)" value="{0, 0, 0}"/>' '' >bad_length.xml
expect bad_length 2 'mupm->Discretization->Origin' '2 values'
echo '<ParameterList name="mupm"><Parameter name=' >malformed.xml
expect malformed 2 'not a valid Teuchos XML'
set +e
run 2 1 no_such_file.xml >missing_file.out 2>&1
got=$?
set -e
[[ $got == 2 ]] && grep -qF "cannot read the input file" missing_file.out || fail "missing file: exit $got"
echo "ok: missing_file (exit $got)"
# Fluid inputs: a permeability must be given exactly once; fluid conditions need a fluid physics.
base '' '<Parameter name="Physics" type="string" value="Pore Fluid"/>' >no_permeability.xml
expect no_permeability 2 'mupm->Fluid->Intrinsic Permeability' 'Hydraulic Conductivity' 'neither is set'
base '' '<Parameter name="Physics" type="string" value="Hydro-Mechanical"/>' | sed '$d' >both_permeabilities.xml
cat >>both_permeabilities.xml <<'XML'
  <ParameterList name="Fluid">
    <Parameter name="Intrinsic Permeability" type="double" value="1e-12"/>
    <Parameter name="Hydraulic Conductivity" type="double" value="1e-5"/>
  </ParameterList>
</ParameterList>
XML
expect both_permeabilities 2 'mupm->Fluid->Intrinsic Permeability' 'both are set'
base '' '' | sed '$d' >fluid_bc_on_solid.xml
cat >>fluid_bc_on_solid.xml <<'XML'
  <ParameterList name="Boundary Conditions"><ParameterList name="drain">
    <Parameter name="Type" type="string" value="Pore Pressure"/>
  </ParameterList></ParameterList>
</ParameterList>
XML
expect fluid_bc_on_solid 2 'mupm->Boundary Conditions->drain->Type' 'Pore Fluid or Hydro-Mechanical'
# A state that overflows stops both ranks at the step it appears, naming the point (exit 3).
base '' '<Parameter name="Time Step" type="double" value="1e10"/>' | sed '$d' >inf.xml
cat >>inf.xml <<'XML'
  <ParameterList name="Initial Conditions"><ParameterList name="fast">
    <Parameter name="Field" type="string" value="Velocity"/>
    <Parameter name="Value" type="Array(double)" value="{1e300, 0}"/>
  </ParameterList></ParameterList>
</ParameterList>
XML
expect inf 3 'NaN or Inf at step 1' 'global id' 'reference position'
# A fluid too stiff for automatic substeps (~4e9 of them: the count once overflowed to 1 and the
# run ended with p ~ 1e173 Pa and exit 0) is refused before the first step, naming the
# parameters.
sed -e 's|name="Hydraulic Conductivity" type="double" value="5.11e-5"|name="Hydraulic Conductivity" type="double" value="5.11e3"|' \
    -e 's|name="Number of Steps" type="int" value="3740"|name="Number of Steps" type="int" value="5"|' \
    -e 's|name="Folder" type="string" value="[^"]*"|name="Folder" type="string" value="stiff"|' \
    "$SRC/inputs/consolidation.xml" >stiff_fluid.xml
grep -q 'value="5.11e3"' stiff_fluid.xml || fail "inputs/consolidation.xml changed: stiff_fluid.xml not derived"
expect stiff_fluid 2 'substeps' 'mupm->Fluid->Hydraulic Conductivity' 'mupm->Fluid->Fluid Bulk Modulus'
[[ -e stiff/fields_000000005.h5 ]] && fail "stiff_fluid: the run stepped"
# A time step twice the stable one blows up (energy x100 a step): stopped at the step the stored
# energy passes 1000 x what was supplied, naming the point (it once ran on to 1e116 m, exit 0).
base '<ParameterList name="Regions"><ParameterList name="left">
      <Parameter name="Min" type="Array(double)" value="{0, 0}"/>
      <Parameter name="Max" type="Array(double)" value="{0.05, 0.1}"/></ParameterList></ParameterList>' \
  '<Parameter name="Time Step" type="double" value="2e-5"/>
   <Parameter name="Number of Steps" type="int" value="40"/>' | sed '$d' >diverging.xml
cat >>diverging.xml <<'XML'
  <ParameterList name="Initial Conditions"><ParameterList name="push">
    <Parameter name="Field" type="string" value="Velocity"/>
    <Parameter name="Region" type="string" value="left"/>
    <Parameter name="Value" type="Array(double)" value="{0.1, 0}"/>
  </ParameterList></ParameterList>
</ParameterList>
XML
sed -i '/name="Number of Steps" type="int" value="2"/d' diverging.xml
expect diverging 3 'solid diverged at step' 'global id' 'Automatic Time Step'
# Energy warnings beyond the fifth are announced as suppressed and counted at the end.
sed -e 's|value="2e-5"|value="1e-6"|' diverging.xml |
  sed 's|<Parameter name="Time Step" type="double" value="1e-6"/>|&<Parameter name="Energy Tolerance" type="double" value="0"/><Parameter name="Energy Check Start" type="int" value="0"/>|' >warnings.xml
expect warnings 0 'further solid energy-balance warnings are suppressed' 'solid energy-balance warnings in all'
# A missing checkpoint is an input error naming the parameter; both ranks stop cleanly (no abort).
base '' '<Parameter name="Restart From" type="string" value="nowhere/checkpoint.h5"/>' >no_checkpoint.xml
expect no_checkpoint 2 "mupm->Solver->Restart From = 'nowhere/checkpoint.h5'"
grep -q "MPI_ABORT" no_checkpoint.out && fail "no_checkpoint: aborted instead of stopping cleanly"
# Files the input names are checked before any work, in one line each, by the run and by
# --validate: a directory as the input or as the restart file, a file that is not HDF5.
mkdir -p adir
expect_dir input_dir "cannot read the input file 'adir'" adir
base '' '<Parameter name="Restart From" type="string" value="adir"/>' >restart_dir.xml
expect_dir restart_dir "mupm->Solver->Restart From = 'adir' is a directory" restart_dir.xml
expect_dir restart_dir_validate "mupm->Solver->Restart From = 'adir' is a directory" --validate restart_dir.xml
base '' '<Parameter name="Restart From" type="string" value="valid.xml"/>' >restart_xml.xml
base '' '' >valid.xml
expect_dir restart_not_hdf5 "is not an HDF5 file" --validate restart_xml.xml
# Silent no-ops are refused: a parameter given twice (Teuchos keeps the last), a root list not
# named mupm, a condition on a region without points, a restart with no step left to take.
base '' '<Parameter name="Time Step" type="double" value="1e-6"/><Parameter name="Time Step" type="double" value="2e-6"/>' >twice.xml
expect twice 2 'mupm->Solver->Time Step is given twice'
base '' '' | sed 's|<ParameterList name="mupm">|<ParameterList name="input">|' >root_name.xml
expect root_name 2 "root list is named 'input'"
base '<ParameterList name="Regions"><ParameterList name="outside">
      <Parameter name="Min" type="Array(double)" value="{1, 1}"/>
      <Parameter name="Max" type="Array(double)" value="{2, 2}"/></ParameterList></ParameterList>' '' |
  sed '$d' >empty_region.xml
cat >>empty_region.xml <<'XML'
  <ParameterList name="Boundary Conditions"><ParameterList name="pull">
    <Parameter name="Type" type="string" value="Body Force"/>
    <Parameter name="Region" type="string" value="outside"/>
    <Parameter name="Value" type="double" value="1"/>
  </ParameterList></ParameterList>
</ParameterList>
XML
expect empty_region 2 "mupm->Boundary Conditions->pull->Region = 'outside' holds no point"
# Mirrored boundary-layer values are for Pore Pressure and the kinematic conditions only.
base '<Parameter name="Boundary Layers" type="Array(string)" value="{-x}"/>' '' | sed '$d' >mirrored_kinematic.xml
cat >>mirrored_kinematic.xml <<'XML'
  <ParameterList name="Boundary Conditions"><ParameterList name="hold">
    <Parameter name="Type" type="string" value="Traction"/>
    <Parameter name="Region" type="string" value="Layer -x"/>
    <Parameter name="Boundary Layer Values" type="string" value="Mirrored"/>
  </ParameterList></ParameterList>
</ParameterList>
XML
expect mirrored_kinematic 2 'mupm->Boundary Conditions->hold->Boundary Layer Values = Mirrored' 'only Pore Pressure, Fracture Pressure, Displacement, Velocity'
# A mirrored tangential Displacement slaves its layer (energy-free points), so no condition may
# hold constant values on the same points.
sed -e 's|value="Traction"|value="Displacement"|' \
  -e 's|<Parameter name="Region" type="string" value="Layer -x"/>|&<Parameter name="Component" type="string" value="y"/>|' \
  -e 's|</ParameterList></ParameterList>|</ParameterList><ParameterList name="hold2"><Parameter name="Type" type="string" value="Displacement"/><Parameter name="Region" type="string" value="Layer -x"/></ParameterList></ParameterList>|' \
  mirrored_kinematic.xml >mirrored_tangential.xml
expect mirrored_tangential 2 'mupm->Boundary Conditions->hold->Boundary Layer Values = Mirrored slaves the points of its layer' 'mupm->Boundary Conditions->hold2 also prescribes some of them with constant values'
# ... and slaved layers are for the elastic solid without bond breakage.
sed -e 's|<ParameterList name="hold2">.*</ParameterList></ParameterList>|</ParameterList>|' \
  -e 's|<ParameterList name="Materials">|<ParameterList name="Fracture"><Parameter name="Bond Breakage" type="string" value="Energy"/><Parameter name="Critical Energy Release Rate" type="double" value="100"/></ParameterList>&|' \
  mirrored_tangential.xml >mirrored_breakage.xml
expect mirrored_breakage 2 'mupm->Boundary Conditions->hold->Boundary Layer Values = Mirrored on a Displacement of component y' 'Fracture->Bond Breakage = None'
# ... and for a law whose state is defined on energy-free points (its registration says so:
# the elastic law's, not Drucker-Prager's).
sed -e 's|<ParameterList name="hold2">.*</ParameterList></ParameterList>|</ParameterList>|' \
  -e 's|<ParameterList name="Materials">|&<Parameter name="Model" type="string" value="Micropolar Drucker-Prager"/><Parameter name="Cohesion" type="double" value="1e5"/>|' \
  mirrored_tangential.xml >mirrored_plastic.xml
expect mirrored_plastic 2 'mupm->Boundary Conditions->hold->Boundary Layer Values = Mirrored on a Displacement of component y' 'implemented for mupm->Materials->Model = Micropolar Elastic with'
# ... and mirrored Displacement for a solid without pore water only (measured unstable with it).
base '<Parameter name="Boundary Layers" type="Array(string)" value="{-x}"/>' \
  '<Parameter name="Physics" type="string" value="Hydro-Mechanical"/>' |
  sed -e '$d' -e 's|<Parameter name="Length Scale" type="double" value="1e-3"/>|&<Parameter name="Porosity" type="double" value="0.2"/>|' -e 's|<ParameterList name="Solver">|<ParameterList name="Fluid"><Parameter name="Hydraulic Conductivity" type="double" value="1e-6"/></ParameterList>&|' >mirrored_fluid.xml
sed -n '/<ParameterList name="Boundary Conditions">/,$p' mirrored_kinematic.xml |
  sed 's|value="Traction"|value="Displacement"|' >>mirrored_fluid.xml
expect mirrored_fluid 2 'mupm->Boundary Conditions->hold->Boundary Layer Values = Mirrored' 'mupm->Solver->Physics = Micropolar Solid'
# Fluid Flux sets its layer by the flux only, and needs a region outside one face.
sed 's|value="Displacement"|value="Fluid Flux"|' mirrored_fluid.xml >flux_layer_values.xml
expect flux_layer_values 2 'mupm->Boundary Conditions->hold->Boundary Layer Values = Mirrored' 'leave it Default'
sed -e 's|value="Layer -x"|value="All"|' -e '/name="Boundary Layer Values" type="string" value="Mirrored"/d' \
  flux_layer_values.xml >flux_region.xml
expect flux_region 2 'mupm->Boundary Conditions->hold->Region' 'outside exactly one face'
# Traction Distribution = Consistent: Traction only, on a box holding one face's outer row; a
# valid one runs (20 x 10 body of spacing 0.01: the +x face's outer row at x = 0.195).
base '<ParameterList name="Regions"><ParameterList name="end">
      <Parameter name="Min" type="Array(double)" value="{0.19, -1}"/>
      <Parameter name="Max" type="Array(double)" value="{0.2, 1}"/></ParameterList></ParameterList>' '' |
  sed '$d' >consistent_traction.xml
cat >>consistent_traction.xml <<'XML'
  <ParameterList name="Boundary Conditions"><ParameterList name="pull">
    <Parameter name="Type" type="string" value="Traction"/>
    <Parameter name="Region" type="string" value="end"/>
    <Parameter name="Value" type="double" value="1e5"/>
    <Parameter name="Traction Distribution" type="string" value="Consistent"/>
  </ParameterList></ParameterList>
</ParameterList>
XML
run 2 1 consistent_traction.xml >consistent_traction.out 2>&1 ||
  { cat consistent_traction.out; fail "consistent_traction.xml did not run"; }
echo "ok: consistent_traction runs"
sed 's|value="Traction"|value="Body Force"|' consistent_traction.xml >consistent_body_force.xml
expect consistent_body_force 2 'mupm->Boundary Conditions->pull->Traction Distribution = Consistent' 'only a Traction is distributed'
sed 's|value="{0.19, -1}"|value="{0.17, -1}"|' consistent_traction.xml >consistent_two_rows.xml
expect consistent_two_rows 2 'mupm->Boundary Conditions->pull->Region' 'outermost real row of exactly one face' 'holds none'
sed 's|value="end"|value="All"|' consistent_traction.xml >consistent_all.xml
expect consistent_all 2 'mupm->Boundary Conditions->pull->Region' 'not All or a layer'
# The +y face of the 0.1 m high body: 4 delta + dx = 0.13 m, so the strip would reach -y.
sed -e 's|value="{0.19, -1}"|value="{-1, 0.095}"|' -e 's|value="{0.2, 1}"|value="{1, 0.1}"|' \
  consistent_traction.xml >consistent_thin.xml
expect consistent_thin 2 'mupm->Boundary Conditions->pull->Traction Distribution = Consistent: the body is 0.1' '4 delta + dx'
base '' '' | sed 's|value="out"|value="done"|' >done.xml
run 2 1 done.xml >done.out 2>&1 || { cat done.out; fail "done.xml did not run"; }
base '' '<Parameter name="Restart From" type="string" value="done/checkpoint.h5"/>' |
  sed -e 's|value="out"|value="again"|' -e 's|name="Number of Steps" type="int" value="2"|name="Number of Steps" type="int" value="1"|' >no_steps_left.xml
expect no_steps_left 2 'the checkpoint is at step 2' 'mupm->Solver->Number of Steps = 1'
# End Time (Time Step 1e-6 s): the run ends on the first step whose time reaches it; a restart
# with no time left is refused and leaves the folder's time series whole.
rm -rf kept && cp -r done kept
base '' '<Parameter name="Restart From" type="string" value="done/checkpoint.h5"/><Parameter name="End Time" type="double" value="1.5e-6"/>' |
  sed 's|value="out"|value="kept"|' >no_time_left.xml
expect no_time_left 2 'the checkpoint is at step 2' 'mupm->Solver->End Time = 1.5e-06 s is not beyond its time 2e-06 s'
cmp -s done/time_series.csv kept/time_series.csv || fail "a refused restart changed the time series"
# ceil(End Time / dt) steps: 3.5e-6 s -> 4; an End Time of a whole number of steps (5e-6 s, 5 steps
# whose accumulated time is 5.000000000000001e-06 s) -> 5, no extra step.
for end in 3.5e-6:4 5e-6:5; do
  base '' "<Parameter name=\"End Time\" type=\"double\" value=\"${end%:*}\"/>" |
    sed "s|value=\"out\"|value=\"end${end#*:}\"|" >end_time.xml
  run 2 1 end_time.xml >end_time.out 2>&1 || { cat end_time.out; fail "end_time.xml (${end%:*}) failed"; }
  last=$(tail -n 1 "end${end#*:}/time_series.csv" | cut -d, -f1)
  [[ $last == "${end#*:}" ]] || fail "End Time = ${end%:*} s with dt = 1e-6 s: last step $last, expected ${end#*:}"
  grep -qF "the last step is ${end#*:} (${end#*:} steps of 1e-06 s)" end_time.out || { cat end_time.out; fail "no End Time line"; }
done
# A restart to End Time continues the folder's rows; with another Time Step (5e-7 s from the
# checkpoint's t = 2e-6 s) it still ends at End Time: 5 more steps, last step 7 at t = 4.5e-6 s.
rm -rf endr endh && cp -r done endr && cp -r done endh
base '' '<Parameter name="Restart From" type="string" value="done/checkpoint.h5"/><Parameter name="End Time" type="double" value="4.5e-6"/>' |
  sed 's|value="out"|value="endr"|' >end_restart.xml
run 2 1 end_restart.xml >end_restart.out 2>&1 || { cat end_restart.out; fail "end_restart.xml failed"; }
steps=$(tail -n +2 endr/time_series.csv | cut -d, -f1 | tr '\n' ' ')
[[ $steps == "0 1 2 3 4 5 " ]] || fail "restart to End Time: time_series.csv steps are '$steps', expected 0 to 5"
base '' '<Parameter name="Restart From" type="string" value="done/checkpoint.h5"/><Parameter name="End Time" type="double" value="4.5e-6"/><Parameter name="Time Step" type="double" value="5e-7"/>' |
  sed 's|value="out"|value="endh"|' >end_half.xml
run 2 1 end_half.xml >end_half.out 2>&1 || { cat end_half.out; fail "end_half.xml failed"; }
"$PYTHON" - <<'PY'
import csv
rows = list(csv.DictReader(open("endh/time_series.csv")))
steps = [int(float(r["step"])) for r in rows]
assert steps == list(range(8)), steps
t = float(rows[-1]["time"])
assert abs(t - 4.5e-6) < 1e-12, t
PY
echo "ok: End Time (ceil(End Time / dt), whole numbers of steps, restart, restart with another dt)"
# --validate finds a checkpoint of another grid, as the run would.
base '' '<Parameter name="Restart From" type="string" value="done/checkpoint.h5"/>' |
  sed 's|value="{20, 10}"|value="{20, 11}"|' >other_grid.xml
expect_dir other_grid_validate "does not match this input: the number of points is 200 there and 220 here" --validate other_grid.xml
# Restarting into the folder of a run that went past the checkpoint (a restart from an earlier
# checkpoint, or a stop between a checkpoint and the next row) keeps one row per step.
cp done/checkpoint.h5 step2.h5
base '' '<Parameter name="Restart From" type="string" value="step2.h5"/>' |
  sed -e 's|value="out"|value="done"|' -e 's|name="Number of Steps" type="int" value="2"|name="Number of Steps" type="int" value="5"|' >again.xml
run 2 1 again.xml >again1.out 2>&1 || { cat again1.out; fail "again.xml (first restart) failed"; }
run 2 1 again.xml >again2.out 2>&1 || { cat again2.out; fail "again.xml (second restart) failed"; }
steps=$(tail -n +2 done/time_series.csv | cut -d, -f1 | tr '\n' ' ')
[[ $steps == "0 1 2 3 4 5 " ]] || fail "restart into the same folder: time_series.csv steps are '$steps', expected 0 to 5 once each"
echo "ok: restart rows (steps $steps)"
# SIGTERM to the ranks (a batch system's time limit): they finish the step, write a checkpoint
# and exit with 4; a stale checkpoint.h5.tmp of a killed run is removed; the run continues from
# the checkpoint.
base '' '' | sed -e 's|value="out"|value="long"|' -e 's|name="Number of Steps" type="int" value="2"|name="Number of Steps" type="int" value="100000000"|' >sigterm.xml
mkdir -p long && touch long/checkpoint.h5.tmp
set +e
OMPI_MCA_odls_base_sigkill_timeout=1 run 2 1 sigterm.xml >sigterm.out 2>&1 &
pid=$!
for _ in $(seq 600); do
  [[ -f long/time_series.csv && $(wc -l <long/time_series.csv) -ge 5 ]] && break
  sleep 0.1
done
pkill -TERM -f "^$MUPM sigterm.xml"
wait $pid
got=$?
set -e
[[ $got == 4 ]] || { cat sigterm.out; fail "sigterm: exit code $got, expected 4"; }
grep -qF "stopped by a signal after step" sigterm.out || { cat sigterm.out; fail "sigterm: no message"; }
[[ -f long/checkpoint.h5 && ! -e long/checkpoint.h5.tmp ]] || fail "sigterm: no checkpoint, or a stale .tmp left"
stopped=$("$PYTHON" -c "import h5py; print(h5py.File('long/checkpoint.h5').attrs['step'])")
sed -e "s|value=\"100000000\"|value=\"$((stopped + 2))\"|" \
    -e 's|<Parameter name="Number of Steps"|<Parameter name="Restart From" type="string" value="long/checkpoint.h5"/>&|' sigterm.xml >resume.xml
run 2 1 resume.xml >resume.out 2>&1 || { cat resume.out; fail "sigterm: the restart from its checkpoint failed"; }
rows=$(tail -n +2 long/time_series.csv | cut -d, -f1 | sort -n | uniq -d | wc -l)
[[ $rows == 0 ]] || fail "sigterm: time_series.csv repeats $rows step(s)"
echo "ok: sigterm (exit 4 at step $stopped, resumed)"
# A valid input validates, and --print-defaults is XML that documents every parameter.
base '' '' >valid.xml
# Threads pinned (OMP_PROC_BIND=spread) while the ranks' masks overlap (--bind-to none): warned.
OMP_PROC_BIND=spread run 2 1 valid.xml >pinned.out 2>&1 || { cat pinned.out; fail "pinned: run failed"; }
grep -qF "WARNING: ranks on one node share cores while OMP_PROC_BIND = spread" pinned.out ||
  { cat pinned.out; fail "pinned: no placement warning"; }
echo "ok: placement warning"
run 2 1 --validate valid.xml | grep -q "is valid" || fail "--validate of a valid input"
# Every shipped input validates (the paper-resolution runs are not run by the tests; a change of
# the input reference must not leave one of them refused).
shipped=0
for f in "$SRC"/inputs/*.xml; do
  run 1 1 --validate "$f" >shipped.out 2>&1 && grep -qF "$f is valid" shipped.out ||
    { cat shipped.out; fail "shipped input $f does not validate"; }
  shipped=$((shipped + 1))
done
((shipped >= 10)) || fail "only $shipped shipped inputs found in $SRC/inputs"
echo "ok: the $shipped shipped inputs validate"
# stdout of --print-defaults, --help and --validate holds their output alone, whatever the OpenMP
# environment (Kokkos warned about OMP_PROC_BIND into stdout, making defaults.xml invalid XML).
env -u OMP_PROC_BIND -u OMP_PLACES "$MUPM" --print-defaults >defaults.xml
env -u OMP_PROC_BIND "$MUPM" --help >help.out
head -n 1 help.out | grep -q "^usage: mupm" || { cat help.out; fail "--help: stdout does not start with the usage"; }
env -u OMP_PROC_BIND "$MUPM" --validate valid.xml >validate.out
[[ $(wc -l <validate.out) == 1 ]] && grep -q "^mupm: valid.xml is valid; it needs about .* MiB per rank" validate.out ||
  { cat validate.out; fail "--validate: stdout is not the verdict alone"; }
# J-Integral: contours without a pre-crack, the J criterion without contours, mismatched sizes.
jlist() {  # jlist J-INTEGRAL-PARAMETERS: a list placed before Solver
  sed "s|  <ParameterList name=\"Solver\">|  <ParameterList name=\"J-Integral\">$1</ParameterList>\n&|"
}
crack='<ParameterList name="Pre-Cracks"><ParameterList name="c"><Parameter name="Start" type="Array(double)" value="{-0.01, 0.05}"/><Parameter name="End" type="Array(double)" value="{0.1, 0.05}"/></ParameterList></ParameterList>'
base '' '' | jlist '<Parameter name="Half Widths" type="Array(double)" value="{3}"/>' >j_no_crack.xml
expect j_no_crack 2 'mupm->J-Integral->Half Widths' 'Pre-Cracks'
base "$crack" '' | jlist '' |
  sed 's|  <ParameterList name="Solver">|  <ParameterList name="Fracture"><Parameter name="Bond Breakage" type="string" value="J-Integral"/><Parameter name="Critical Energy Release Rate" type="double" value="10"/></ParameterList>\n&|' >j_no_contour.xml
expect j_no_contour 2 'mupm->Fracture->Bond Breakage' 'mupm->J-Integral->Half Widths'
base "$crack" '' | jlist '<Parameter name="Half Widths" type="Array(double)" value="{3, 4}"/><Parameter name="Half Heights" type="Array(double)" value="{3}"/>' >j_sizes.xml
expect j_sizes 2 'mupm->J-Integral->Half Heights' 'one per contour'
# ... a crack with no end inside the body, a contour that holds the other tip, an increment
# above one spacing, a crack speed without the J criterion.
through='<ParameterList name="Pre-Cracks"><ParameterList name="c"><Parameter name="Start" type="Array(double)" value="{-0.01, 0.05}"/><Parameter name="End" type="Array(double)" value="{0.21, 0.05}"/></ParameterList></ParameterList>'
base "$through" '' | jlist '<Parameter name="Half Widths" type="Array(double)" value="{3}"/>' >j_no_tip.xml
expect j_no_tip 2 'mupm->J-Integral->Half Widths' 'no end inside'
centre='<ParameterList name="Pre-Cracks"><ParameterList name="c"><Parameter name="Start" type="Array(double)" value="{0.08, 0.05}"/><Parameter name="End" type="Array(double)" value="{0.12, 0.05}"/></ParameterList></ParameterList>'
base "$centre" '' | jlist '<Parameter name="Half Widths" type="Array(double)" value="{3, 4}"/>' >j_other_tip.xml
expect j_other_tip 2 'mupm->J-Integral->Half Widths' 'contour 2 around tip 1' 'holds tip 2'
base "$crack" '' | jlist '<Parameter name="Half Widths" type="Array(double)" value="{3}"/><Parameter name="Crack Increment" type="double" value="0.015"/>' |
  sed 's|  <ParameterList name="Solver">|  <ParameterList name="Fracture"><Parameter name="Bond Breakage" type="string" value="J-Integral"/><Parameter name="Critical Energy Release Rate" type="double" value="10"/></ParameterList>\n&|' >j_increment.xml
expect j_increment 2 'mupm->J-Integral->Crack Increment' 'exceeds one Spacing'
base "$crack" '' | jlist '<Parameter name="Half Widths" type="Array(double)" value="{3}"/><Parameter name="Maximum Crack Speed" type="double" value="10"/>' >j_speed.xml
expect j_speed 2 'mupm->J-Integral->Maximum Crack Speed' 'Bond Breakage = J-Integral'
# ... a release time without the J criterion, and one longer than the speed cap's wait
# (Crack Increment 0.005 m / 10 m/s = 0.5 ms).
base "$crack" '' | jlist '<Parameter name="Half Widths" type="Array(double)" value="{3}"/><Parameter name="Release Time" type="double" value="1e-4"/>' >j_release.xml
expect j_release 2 'mupm->J-Integral->Release Time' 'Bond Breakage = J-Integral'
base "$crack" '' | jlist '<Parameter name="Half Widths" type="Array(double)" value="{3}"/><Parameter name="Crack Increment" type="double" value="0.005"/><Parameter name="Maximum Crack Speed" type="double" value="10"/><Parameter name="Release Time" type="double" value="6e-4"/>' |
  sed 's|  <ParameterList name="Solver">|  <ParameterList name="Fracture"><Parameter name="Bond Breakage" type="string" value="J-Integral"/><Parameter name="Critical Energy Release Rate" type="double" value="10"/></ParameterList>\n&|' >j_release_wait.xml
expect j_release_wait 2 'mupm->J-Integral->Release Time' 'exceeds the speed cap' 'wait'
# Drucker-Prager: no cohesion, a residual cohesion above the initial one.
base '' '' | sed 's|<Parameter name="Bulk Modulus"|<Parameter name="Model" type="string" value="Micropolar Drucker-Prager"/>&|' >dp_no_cohesion.xml
expect dp_no_cohesion 2 'mupm->Materials->Cohesion' 'must be > 0'
base '' '' | sed 's|<Parameter name="Bulk Modulus"|<Parameter name="Model" type="string" value="Micropolar Drucker-Prager"/><Parameter name="Cohesion" type="double" value="1e5"/><Parameter name="Residual Cohesion" type="double" value="2e5"/>&|' >dp_residual.xml
expect dp_residual 2 'mupm->Materials->Residual Cohesion' 'exceeds'
# A grid beyond the machine's memory is refused before anything is allocated, by the run and by
# --validate (it once grew until the kernel killed it, or ended in std::bad_alloc).
base '' '' | sed 's|value="{20, 10}"|value="{20000, 20000}"|' >huge.xml
expect huge 2 'GiB per rank' 'GiB available per rank' 'mupm->Discretization->Counts'
set +e
run 2 1 --validate huge.xml >huge_validate.out 2>&1
got=$?
set -e
[[ $got == 2 ]] && grep -q "GiB available per rank" huge_validate.out || { cat huge_validate.out; fail "huge: --validate exit $got"; }
echo "ok: huge (refused by the run and by --validate)"
"$PYTHON" - defaults.xml <<'PY'
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
params = root.iter("Parameter")
n = 0
for p in params:
    n += 1
    assert p.get("docString"), "parameter %s has no doc string" % p.get("name")
assert n > 20, n
print("defaults: %d parameters, all documented" % n)
PY
echo "cli_errors: all passed"
