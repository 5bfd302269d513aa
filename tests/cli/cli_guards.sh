#!/usr/bin/env bash
# Runs that once ended with exit 0 and wrong, dropped or mixed results, or never ended: refused
# by name (exit 2; exit 3 where only the run can tell), by the run and by --validate.
source "$(dirname "$0")/common.sh"
source "$(dirname "$0")/error_cases.sh"

# Boundary Layer Horizons: floor(value * delta / dx) rows; 0.1 gave no row (conditions on the
# layers did nothing), 1e9 overflowed the row count (0 points, "needs about -nan MiB").
layer_hold() {  # a Displacement on 'Layer +y' appended to the input on stdin
  sed '$d'
  cat <<'XML'
  <ParameterList name="Boundary Conditions"><ParameterList name="hold">
    <Parameter name="Type" type="string" value="Displacement"/>
    <Parameter name="Region" type="string" value="Layer +y"/>
  </ParameterList></ParameterList>
</ParameterList>
XML
}
for v in 0.1:no_row 1e9:thicker; do
  name=layer_${v#*:}
  base "<Parameter name=\"Boundary Layers\" type=\"Array(string)\" value=\"{-y, +y}\"/><Parameter name=\"Boundary Layer Horizons\" type=\"double\" value=\"${v%:*}\"/>" '' |
    layer_hold >"$name.xml"
done
expect layer_no_row 2 'mupm->Discretization->Boundary Layer Horizons = 0.1 gives layers of no row' 'The minimum is dx / delta = 0.331675'
expect_dir layer_no_row_validate 'mupm->Discretization->Boundary Layer Horizons = 0.1' --validate layer_no_row.xml
expect layer_thicker 2 'mupm->Discretization->Boundary Layer Horizons = 1e+09' 'thicker than the body along y (10 rows)'
expect_dir layer_thicker_validate 'mupm->Discretization->Boundary Layer Horizons = 1e+09' --validate layer_thicker.xml
# End Time beyond 1e12 steps (1e13 s of 1e-6 s steps: "the last step is -9223372036854775808" and
# a run without end); with Automatic Time Step the run refuses it once dt is known.
base '' '<Parameter name="End Time" type="double" value="1e13"/>' >end_time_huge.xml
expect end_time_huge 2 'mupm->Solver->End Time = 1e+13 s takes 1e+19 steps' 'mupm->Solver->Time Step'
expect_dir end_time_huge_validate 'mupm->Solver->End Time = 1e+13 s' --validate end_time_huge.xml
base '' '<Parameter name="End Time" type="double" value="1e308"/>' >end_time_max.xml
expect end_time_max 2 'mupm->Solver->End Time = 1e+308 s'
base '' '<Parameter name="End Time" type="double" value="1e13"/><Parameter name="Automatic Time Step" type="bool" value="true"/>' >end_time_auto.xml
expect end_time_auto 2 'mupm->Solver->End Time = 1e+13 s' "Automatic Time Step's estimate"
# Fluid Substeps beyond the automatic choice's limit (2147483647 ran for ever).
base '' '<Parameter name="Fluid Substeps" type="int" value="2147483647"/>' >substeps_huge.xml
expect substeps_huge 2 'mupm->Solver->Fluid Substeps = 2147483647 is not valid' 'At most 1e6'
# A modulus beyond its physical range leaves Automatic Time Step no step: said so (it read
# "the pore fluid's estimated stable step is 1.57e-05 s: a fluid interval of 0 s would need -0
# substeps").
base '' '<Parameter name="Automatic Time Step" type="bool" value="true"/>' |
  sed 's|name="Bulk Modulus" type="double" value="1e8"|name="Bulk Modulus" type="double" value="1e300"|' >modulus_huge.xml
grep -q 'value="1e300"' modulus_huge.xml || fail "modulus_huge.xml not derived"
expect modulus_huge 2 "the solid's estimated stable step is 0 s" 'Bulk Modulus'
# An Output->Folder below a regular file: said so (it was "not writable (Permission denied)").
touch afile
base '' '' | sed 's|value="out"|value="afile/sub"|' >folder_below_file.xml
expect folder_below_file 2 "mupm->Output->Folder = 'afile/sub'" "afile' is a file, not a folder"
expect_dir folder_below_file_validate "afile' is a file, not a folder" --validate folder_below_file.xml
# A restart continues the checkpoint's state: a change of what that state was made under is
# refused by name, by the run and by --validate (each once ran with exit 0: a Drucker-Prager
# checkpoint went on elastic with its internal energy doubled; an added pre-crack only flagged
# points; Fracture Flow switched off lost the crack water; a smaller Minimum Aperture kept the
# checkpoint's stable step and diverged; a switch to plane stress went on from plane strain's
# stresses).
restart_with() {  # restart_with CHECKPOINT_FOLDER: Restart From its checkpoint, folder NAME.again
  sed -e "s|<Parameter name=\"Number of Steps\" type=\"int\" value=\"2\"/>|<Parameter name=\"Number of Steps\" type=\"int\" value=\"4\"/><Parameter name=\"Restart From\" type=\"string\" value=\"$1/checkpoint.h5\"/>|" \
    -e "s|name=\"Folder\" type=\"string\" value=\"$1\"|name=\"Folder\" type=\"string\" value=\"$1.again\"|"
}
dp='<Parameter name="Model" type="string" value="Micropolar Drucker-Prager"/><Parameter name="Cohesion" type="double" value="1e5"/>'
base '' '' | sed -e "s|<Parameter name=\"Bulk Modulus\"|$dp&|" -e 's|value="out"|value="dp"|' >dp.xml
run 2 1 dp.xml >dp.out 2>&1 || { cat dp.out; fail "dp.xml did not run"; }
restart_with dp <dp.xml | sed 's|value="Micropolar Drucker-Prager"|value="Micropolar Elastic"|' >dp_to_elastic.xml
expect dp_to_elastic 2 "mupm->Solver->Restart From = 'dp/checkpoint.h5'" 'was written with mupm->Materials->Model = Micropolar Drucker-Prager, and this input has Micropolar Elastic'
expect_dir dp_to_elastic_validate 'mupm->Materials->Model = Micropolar Drucker-Prager' --validate dp_to_elastic.xml
base '' '' | sed 's|value="out"|value="plain"|' >plain.xml
run 2 1 plain.xml >plain.out 2>&1 || { cat plain.out; fail "plain.xml did not run"; }
restart_with plain <plain.xml | sed "s|<Parameter name=\"Bulk Modulus\"|$dp&|" >elastic_to_dp.xml
expect elastic_to_dp 2 'was written with mupm->Materials->Model = Micropolar Elastic, and this input has Micropolar Drucker-Prager'
restart_with plain <plain.xml |
  sed 's|<Parameter name="Counts" type="Array(int)" value="{20, 10}"/>|&<ParameterList name="Pre-Cracks"><ParameterList name="c"><Parameter name="Start" type="Array(double)" value="{-0.01, 0.05}"/><Parameter name="End" type="Array(double)" value="{0.1, 0.05}"/></ParameterList></ParameterList>|' >added_crack.xml
expect added_crack 2 'was written with mupm->Discretization->Pre-Cracks = none, and this input has c: Start = {-0.01, 0.05} End = {0.1, 0.05}'
restart_with plain <plain.xml |
  sed 's|<Parameter name="Counts" type="Array(int)" value="{20, 10}"/>|&<Parameter name="Plane" type="string" value="Stress"/>|' >to_plane_stress.xml
grep -q 'value="Stress"' to_plane_stress.xml || fail "to_plane_stress.xml not derived"
expect to_plane_stress 2 'was written with mupm->Discretization->Plane = Strain, and this input has Stress'
# A pre-crack that misses the body (it cut nothing and measured no length).
base '<ParameterList name="Pre-Cracks"><ParameterList name="away"><Parameter name="Start" type="Array(double)" value="{0.3, 0.05}"/><Parameter name="End" type="Array(double)" value="{0.4, 0.05}"/></ParameterList></ParameterList>' '' >crack_outside.xml
expect crack_outside 2 'mupm->Discretization->Pre-Cracks->away lies outside the body'
expect_dir crack_outside_validate 'mupm->Discretization->Pre-Cracks->away lies outside the body' --validate crack_outside.xml
# A J contour beyond the body (J came out 0.012 for 0.93): the tip at (0.1, 0.05) m of the
# 0.2 x 0.1 m body, 10 spacings on either side along x fit, 6 along y do not.
base '<ParameterList name="Pre-Cracks"><ParameterList name="c"><Parameter name="Start" type="Array(double)" value="{-0.01, 0.05}"/><Parameter name="End" type="Array(double)" value="{0.1, 0.05}"/></ParameterList></ParameterList>' '' |
  sed 's|  <ParameterList name="Solver">|  <ParameterList name="J-Integral"><Parameter name="Half Widths" type="Array(double)" value="{4, 10}"/><Parameter name="Half Heights" type="Array(double)" value="{4, 6}"/></ParameterList>\n&|' >j_beyond.xml
expect j_beyond 2 'mupm->J-Integral->Half Heights: contour 2 spans y = -0.01 to 0.11 m' 'beyond the body (0 to 0.1 m)'
sed 's|value="{4, 6}"|value="{4, 5}"|' j_beyond.xml >j_inside.xml
run 2 1 j_inside.xml >j_inside.out 2>&1 || { cat j_inside.out; fail "j_inside.xml (contours up to the body's faces) failed"; }
echo "ok: J contours up to the body's faces run"
# A dilation angle above the friction angle runs, with a warning.
sed 's|<Parameter name="Cohesion"|<Parameter name="Friction Angle" type="double" value="20"/><Parameter name="Dilation Angle" type="double" value="30"/>&|' dp.xml |
  sed 's|value="dp"|value="dilation"|' >dilation.xml
expect dilation 0 'WARNING: mupm->Materials->Dilation Angle = 30 exceeds Friction Angle = 20 degrees'
# An allowed change (a material constant) restarts.
restart_with plain <plain.xml | sed 's|value="5e7"|value="6e7"|' >stiffer.xml
run 2 1 stiffer.xml >stiffer.out 2>&1 || { cat stiffer.out; fail "stiffer.xml (a restart with another Shear Modulus) failed"; }
echo "ok: a restart with another Shear Modulus runs"
# Water in the crack (tests/cli/fracture_small.xml with Fracture Flow, injected at the notch's
# mouth): a Minimum Aperture not below Spacing (1e50 m ran with nothing moving, 1e308 m ended in
# a non-finite aperture), and a Fracture Source on a network without any fracture point (no
# pre-crack: the water was dropped with exit 0) errs as one beside the crack does.
sed -e 's|value="Micropolar Solid"|value="Hydro-Mechanical"|' \
  -e 's|<ParameterList name="Fracture">|<ParameterList name="Fluid"><Parameter name="Hydraulic Conductivity" type="double" value="1e-6"/></ParameterList>&<Parameter name="Fracture Flow" type="bool" value="true"/><Parameter name="Minimum Aperture" type="double" value="1e-4"/>|' \
  -e 's|<ParameterList name="Pre-Cracks">|<ParameterList name="Regions"><ParameterList name="mouth"><Parameter name="Min" type="Array(double)" value="{0, 0.045}"/><Parameter name="Max" type="Array(double)" value="{0.005, 0.055}"/></ParameterList></ParameterList>&|' \
  -e 's|<ParameterList name="Boundary Conditions">|&<ParameterList name="mouth"><Parameter name="Type" type="string" value="Fracture Source"/><Parameter name="Region" type="string" value="mouth"/><Parameter name="Value" type="double" value="1e-2"/></ParameterList>|' \
  -e 's|name="Number of Steps" type="int" value="440"|name="Number of Steps" type="int" value="2"|' \
  "$SRC/tests/cli/fracture_small.xml" >crack_water.xml
grep -q 'value="Fracture Source"' crack_water.xml && grep -q 'name="edge notch"' crack_water.xml ||
  fail "tests/cli/fracture_small.xml changed: crack_water.xml not derived"
sed 's|name="Minimum Aperture" type="double" value="1e-4"|name="Minimum Aperture" type="double" value="1e50"|' \
  crack_water.xml >aperture_huge.xml
expect aperture_huge 2 'mupm->Fracture->Minimum Aperture = 1e+50 m is not below the point spacing 0.0025 m'
expect_dir aperture_huge_validate 'mupm->Fracture->Minimum Aperture = 1e+50' --validate aperture_huge.xml
sed '/name="edge notch"/,/<\/ParameterList>/d' crack_water.xml >source_no_network.xml
grep -q 'name="edge notch"' source_no_network.xml && fail "source_no_network.xml keeps the pre-crack"
expect source_no_network 3 'mupm->Boundary Conditions->mouth (Fracture Source) has no fracture point in its region'
sed -e 's|value="{0, 0.045}"|value="{0.08, 0.045}"|' -e 's|value="{0.005, 0.055}"|value="{0.09, 0.055}"|' \
  crack_water.xml >source_off_crack.xml
expect source_off_crack 3 'mupm->Boundary Conditions->mouth (Fracture Source) has no fracture point in its region'
# An initial Fracture Pressure (it was shown at step 0, then ignored) is not a field to set.
sed 's|<ParameterList name="Boundary Conditions">|<ParameterList name="Initial Conditions"><ParameterList name="crack water"><Parameter name="Field" type="string" value="Fracture Pressure"/><Parameter name="Value" type="Array(double)" value="{1e7}"/></ParameterList></ParameterList>&|' \
  crack_water.xml >initial_pf.xml
expect initial_pf 2 'mupm->Initial Conditions->crack water' 'Field' 'Pore Pressure'
# The crack water's run restarted without Fracture Flow, or with another Minimum Aperture.
sed 's|value="out"|value="water"|' crack_water.xml >water.xml
run 2 1 water.xml >water.out 2>&1 || { cat water.out; fail "water.xml did not run"; }
restart_with water <water.xml | sed -e 's|<Parameter name="Fracture Flow" type="bool" value="true"/>||' \
  -e 's|<ParameterList name="mouth"><Parameter name="Type" type="string" value="Fracture Source"/>\(<Parameter [^>]*>\)*</ParameterList>||' >water_off.xml
expect water_off 2 'was written with mupm->Fracture->Fracture Flow = true, and this input has false'
restart_with water <water.xml | sed 's|name="Minimum Aperture" type="double" value="1e-4"|name="Minimum Aperture" type="double" value="1e-6"|' >water_film.xml
expect water_film 2 'was written with mupm->Fracture->Minimum Aperture = 0.0001, and this input has 1e-06'
# The paper's eq 17 for the crack water's force (Example 1 case 1 at 66 x 66 with injection) blew
# up at any step: 4e4 J of kinetic energy in 100 steps of the automatic 1.245 us, with exit 0,
# since each balance's stored energy stayed below its own pore work. The coupled system's check
# stops it (exit 3) and says why.
sed -e 's|value="Face Pressure"|value="Eq 17"|' -e 's|name="End Time" type="double" value="0.5"|name="End Time" type="double" value="1.3e-4"|' \
  -e 's|value="output/example1_fluid_driven_66_explicit"|value="eq17"|' "$SRC/inputs/example1_fluid_driven_66_explicit.xml" >eq17.xml
grep -q 'value="Eq 17"' eq17.xml && grep -q 'value="1.3e-4"' eq17.xml || fail "eq17.xml not derived"
expect eq17 3 'Error, the coupled system diverged at step' 'times the energy supplied from outside' 'Crack Water Force = Eq 17'
# Output->Folder holds one run at a time: a second run into the folder of a running one is
# refused (both ranks, exit 2), and a run killed with SIGKILL leaves no stale lock.
base '' '' | sed -e 's|<Parameter name="Folder" type="string" value="out"/>|<Parameter name="Folder" type="string" value="busy"/><Parameter name="Field Interval" type="int" value="0"/>|' \
  -e 's|name="Number of Steps" type="int" value="2"|name="Number of Steps" type="int" value="100000000"|' >busy.xml
set +e
run 2 1 busy.xml >busy.out 2>&1 &
pid=$!
set -e
for _ in $(seq 600); do
  [[ -f busy/time_series.csv ]] && break
  sleep 0.1
done
base '' '' | sed 's|value="out"|value="busy"|' >second.xml
expect second 2 "mupm->Output->Folder = 'busy': another mupm run is writing it (process" 'Wait for that run to end'
pkill -KILL -f "^$MUPM busy.xml" || true
wait $pid || true
run 2 1 second.xml >second_after.out 2>&1 || { cat second_after.out; fail "second.xml after the first run was killed: refused (a stale lock?)"; }
echo "ok: one run per output folder, no stale lock after SIGKILL"
echo "cli_guards: all passed"
