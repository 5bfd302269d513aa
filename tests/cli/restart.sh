#!/usr/bin/env bash
# Checkpoint -> restart on another number of ranks and threads continues bit for bit, for the
# quick-start solid (40 steps), the coupled consolidation input (60 steps) and a notched plate
# whose crack grows by bond breakage from step ~200 of 440 (restarted at 220, in the middle of
# the growth): a straight run on 1 rank equals half the steps on 2 ranks followed by the rest on
# 1 rank x 2 threads (fields and checkpoints compared byte for byte; for the crack, the broken
# bonds too); the crack also by the J criterion (J and the broken bonds the same bits on 1 and 2
# ranks), in a saturated, hydro-mechanical plate, and with water in the crack (fracture flow, both
# crack-water force models, and a mirrored Fracture Pressure on a layer the crack runs into:
# restarted bit for bit on 2 ranks, and 1e-10 across rank and thread counts, the network's
# distributed solve), whose water balance is checked too; and a Drucker-Prager soil
# restarted as its shear bands soften (in plane strain, and in plane stress with its water,
# also with the semi-implicit pressure, saturated and unsaturated).
#   restart.sh MUPM SRC WORK PYTHON MPIEXEC [CASE...]: only the cases named (all when none), so
#   that ctest runs them as several entries (tests/CMakeLists.txt).
source "$(dirname "$0")/common.sh"
ran=""
shift 5
cases=" $* "
selected() {  # selected CASE: whether CASE is to run
  [[ $cases == "  " || $cases == *" $1 "* ]]
}
# make_input XML FOLDER STEPS RESTART [SED_EXPR]: the input (a path in the source tree) with
# its folder, step count and restart file replaced, a field output every 20 steps, and SED_EXPR.
make_input() {
  sed -E -e "${5:-}" -e "s|<Parameter name=\"Folder\" type=\"string\" value=\"[^\"]*\"/>|<Parameter name=\"Folder\" type=\"string\" value=\"$2\"/>|" \
      -e "s|<Parameter name=\"Number of Steps\" type=\"int\" value=\"[0-9]+\"/>|<Parameter name=\"Number of Steps\" type=\"int\" value=\"$3\"/><Parameter name=\"Restart From\" type=\"string\" value=\"$4\"/>|" \
      -e "s|<Parameter name=\"Field Interval\" type=\"int\" value=\"[0-9]+\"/>|<Parameter name=\"Field Interval\" type=\"int\" value=\"20\"/>|" \
      -e "s|<Parameter name=\"Checkpoint Interval\" type=\"int\" value=\"[0-9]+\"/>|<Parameter name=\"Checkpoint Interval\" type=\"int\" value=\"0\"/>|" \
      "$SRC/$1"
}
# solve=1: the case solves a distributed linear system (the fracture network's,
# solvers/fracture_flow.hpp), whose results agree across rank and thread counts to the solve's
# tolerance, not to the bit: the three runs are on 2 ranks x 1 thread (bit for bit), and a
# straight run on 1 rank x 2 threads is compared with tolerance.
solve=0
check() {  # check NAME XML STEPS GLOBALS [SED_EXPR]
  local name=$1 xml=$2 steps=$3 globals=$4 half=$(($3 / 2)) edit=${5:-}
  selected "$name" || return 0
  ran+=" $name"
  make_input "$xml" "$name-straight" "$steps" "" "$edit" >"$name-straight.xml"
  make_input "$xml" "$name-first" "$half" "" "$edit" >"$name-first.xml"
  make_input "$xml" "$name-second" "$steps" "$name-first/checkpoint.h5" "$edit" >"$name-second.xml"
  for f in straight first second; do
    grep -q '"Restart From"' "$name-$f.xml" && grep -q 'Field Interval" type="int" value="20"' "$name-$f.xml" ||
      fail "$xml changed: $name-$f.xml was not derived from it"
  done
  if ((solve)); then
    make_input "$xml" "$name-other" "$steps" "" "$edit" >"$name-other.xml"
    run 2 1 "$name-straight.xml" >"$name-straight.out"
    run 2 1 "$name-first.xml" >"$name-first.out"
    run 2 1 "$name-second.xml" >"$name-second.out"
    run 1 2 "$name-other.xml" >"$name-other.out"
  else
    run 1 1 "$name-straight.xml" >"$name-straight.out"
    run 2 1 "$name-first.xml" >"$name-first.out"
    run 1 2 "$name-second.xml" >"$name-second.out"
  fi
  grep -q "restarted from $name-first/checkpoint.h5 at step $half" "$name-second.out" || fail "$name: no restart line"
  "$PYTHON" - "$name" "$steps" "$globals" "$solve" "${agree:-$steps}" <<'PY'
import sys, h5py, numpy as np
name, steps, globals_, solve = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4] == "1"
f = "fields_%09d.h5" % steps
if solve:  # 2 ranks x 1 thread against 1 rank x 2 threads: the solve's tolerance (at `agree`)
    g = "fields_%09d.h5" % int(sys.argv[5])
    with h5py.File(f"{name}-straight/{g}") as a, h5py.File(f"{name}-other/{g}") as b:
        worst = (0.0, "")
        for field in a:
            x, y = a[field][...].astype(float), b[field][...].astype(float)
            scale = np.abs(x).max()
            diff = np.abs(x - y).max() / scale if scale > 0 else np.abs(y).max()
            worst = max(worst, (diff, field))
            assert diff < 1e-10, (field, diff)
        print("restart %s: 2 ranks x 1 thread and 1 rank x 2 threads agree to %.1e (%s) at step %s"
              % (name, *worst, sys.argv[5]))
with h5py.File(f"{name}-straight/{f}") as a, h5py.File(f"{name}-second/{f}") as b:
    assert len(a) >= 3, list(a)
    for field in a:
        x, y = a[field][...], b[field][...]
        assert x.shape == y.shape and x.tobytes() == y.tobytes(), field
    moved = "pore_pressure" if "pore_pressure" in a else "displacement"
    assert np.abs(a[moved][...]).max() > 0, "nothing happened"
    print("restart %s: %d fields equal bit for bit" % (name, len(a)))
with h5py.File(f"{name}-straight/checkpoint.h5") as a, h5py.File(f"{name}-second/checkpoint.h5") as b:
    for grp in ("points", "bonds"):
        for field in a[grp]:
            assert a[grp][field][...].tobytes() == b[grp][field][...].tobytes(), field
    print("restart %s: checkpoints equal bit for bit" % name)
    import csv
    rows = {int(float(r["step"])): r for r in csv.DictReader(open(f"{name}-straight/time_series.csv"))}
    if "pair_force" in a["bonds"] or "j_integral" in rows[0]:  # the crack grew in both halves
        broken = [float(rows[s]["broken_bonds"]) for s in (0, steps // 2, steps)]
        assert broken[0] < broken[1] < broken[2], broken
        print("restart %s: broken bonds %g -> %g (restart) -> %g" % (name, *broken))
    if "plastic_dissipation" in rows[0]:  # plastic flow in both halves
        dp = [float(rows[s]["plastic_dissipation"]) for s in (0, steps // 2, steps)]
        assert dp[0] == 0 < dp[1] < dp[2], dp
        print("restart %s: plastic dissipation %g -> %g (restart) -> %g J" % (name, *dp))
    if "j_integral" in rows[0]:  # J, an exact sum over ranks (core/exact_sum.hpp): the same bits
        for part in ("first", "second"):  # 2 ranks, then 1 rank x 2 threads
            for r in csv.DictReader(open(f"{name}-{part}/time_series.csv")):
                s = int(float(r["step"]))
                for col in ("j_integral", "j_rotational", "broken_bonds", "crack_length"):
                    assert rows[s][col] == r[col], (part, s, col, rows[s][col], r[col])
        print("restart %s: J and the broken bonds equal bit for bit on 1 and 2 ranks" % name)
    # The energy and inflow bookkeeping is a sum over ranks: equal to round-off, not bit for
    # bit, across rank counts.
    def named(f):  # globals/<module>/<name> -> value
        out = {}
        f["globals"].visititems(lambda k, d: out.__setitem__(k, d[0]) if isinstance(d, h5py.Dataset) else None)
        return out
    ga, gb = named(a), named(b)
    if "release_force" in a["points"]:  # the J criterion's release: under way at the restart
        with h5py.File(f"{name}-first/checkpoint.h5") as c:
            gc = named(c)
            held = np.abs(c["points"]["release_force"][...]).max()
        t_b = [v for k, v in gc.items() if k.endswith("release_start_time")]
        t_half = [float(r["time"]) for r in csv.DictReader(open(f"{name}-first/time_series.csv"))][-1]
        print("restart %s: the release started at %.4g s, restarted at %.4g s, |F| up to %.3g" %
              (name, t_b[0], t_half, held))
        assert len(t_b) == 1 and held > 0 and 0 <= t_half - t_b[0] < 1.25e-4, (t_b, t_half, held)
    assert sorted(ga) == sorted(gb) and len(ga) == globals_, (sorted(ga), sorted(gb))
    for k in ga:
        assert np.allclose(ga[k], gb[k], rtol=1e-11, atol=1e-300), (k, ga[k], gb[k])
PY
}
check solid inputs/quickstart.xml 40 8
check coupled inputs/consolidation.xml 60 15
# Mirrored drained layers: their mirrors' pressures travel with the ghosts.
check coupled-mirrored inputs/consolidation.xml 60 15 's|<Parameter name="Boundary Layers"|<Parameter name="Boundary Layer Values" type="string" value="Mirrored"/>&|'
# Water let in through the base by a Fluid Flux layer (after the drained base: it wins there).
check coupled-flux inputs/consolidation.xml 60 16 's|<ParameterList name="drain top">|<ParameterList name="inflow base"><Parameter name="Type" type="string" value="Fluid Flux"/><Parameter name="Region" type="string" value="Layer -y"/><Parameter name="Value" type="double" value="1e-7"/></ParameterList>\n&|'
# Mirrored displacement layers (the quick start's plate pulled through mirrored top and bottom
# layers): the layers follow their mirrors, which travel with the ghosts.
check solid-mirrored inputs/quickstart.xml 40 8 's|(<Parameter name="Component" type="string" value="y"/>)|\1<Parameter name="Boundary Layer Values" type="string" value="Mirrored"/>|'
# Slaved clamps (the quick start's plate pulled through top and bottom layers that hold x, y and
# the micro-rotation, each Mirrored; the top one also sheared at 0.05 m/s by a Velocity, whose
# displacement so far is a restart global): energy-free layers that follow their mirrors, whose
# forces are folded back onto the mirrors across ranks (Distribution::add_to_owners).
cond() {  # cond NAME LAYER TYPE COMPONENT [VALUE]
  printf '<ParameterList name="%s"><Parameter name="Type" type="string" value="%s"/><Parameter name="Region" type="string" value="%s"/><Parameter name="Component" type="string" value="%s"/><Parameter name="Value" type="double" value="%s"/><Parameter name="Boundary Layer Values" type="string" value="Mirrored"/></ParameterList>' "$1" "$3" "$2" "$4" "${5:-0}"
}
clamps="$(cond "top x" "Layer +y" Velocity x 0.05)$(cond "top rotation" "Layer +y" Micro-Rotation z)$(cond "bottom x" "Layer -y" Displacement x)$(cond "bottom rotation" "Layer -y" Micro-Rotation z)"
check solid-clamped inputs/quickstart.xml 40 9 "s|(<Parameter name=\"Component\" type=\"string\" value=\"y\"/>)|\\1<Parameter name=\"Boundary Layer Values\" type=\"string\" value=\"Mirrored\"/>|; s|(<ParameterList name=\"Boundary Conditions\">)|\\1$clamps|"
# The quick start with a shear traction on its free +x face, Traction Distribution = Consistent
# (its load from the operator's own passes at start, kernels/boundary_conditions.hpp): the same
# bits on 1 rank and on 2 ranks followed by 1 rank x 2 threads.
shear='<ParameterList name="shear"><Parameter name="Type" type="string" value="Traction"/><Parameter name="Region" type="string" value="right face"/><Parameter name="Component" type="string" value="y"/><Parameter name="Value" type="double" value="1e6"/><Parameter name="Traction Distribution" type="string" value="Consistent"/></ParameterList>'
check solid-traction inputs/quickstart.xml 40 8 "s|(<Parameter name=\"Boundary Layers\" type=\"Array\\(string\\)\" value=\"\\{-y, \\+y\\}\"/>)|\\1<ParameterList name=\"Regions\"><ParameterList name=\"right face\"><Parameter name=\"Min\" type=\"Array(double)\" value=\"{0.2475, -1}\"/><Parameter name=\"Max\" type=\"Array(double)\" value=\"{0.25, 1}\"/></ParameterList></ParameterList>|; s|(<ParameterList name=\"Boundary Conditions\">)|\\1$shear|"
check fracture tests/cli/fracture_small.xml 440 11
# The J criterion (Algorithm 3): the crack advances by increments from step ~200.
check fracture-j tests/cli/fracture_small.xml 440 13 's|value="Energy"/>|value="J-Integral"/>|; s|  <ParameterList name="Boundary Conditions">|  <ParameterList name="J-Integral"><Parameter name="Half Widths" type="Array(double)" value="{4, 5}"/></ParameterList>\n&|'
# The J criterion at a centre crack's two tips, each with its own advances (two more globals).
check fracture-j-centre tests/cli/fracture_small.xml 440 15 's|value="Energy"/>|value="J-Integral"/>|; s|value="\{-0.01, 0.05\}"|value="{0.03, 0.05}"|; s|value="\{0.02, 0.05\}"|value="{0.07, 0.05}"|; s|  <ParameterList name="Boundary Conditions">|  <ParameterList name="J-Integral"><Parameter name="Half Widths" type="Array(double)" value="{4, 5}"/></ParameterList>\n&|'
# The same plate saturated, hydro-mechanical (soft water so that dt stays stable): breakage
# with pore water (effective force state, strain-reference shift, fluid re-evaluation).
check fracture-hm tests/cli/fracture_small.xml 440 16 's|value="Micropolar Solid"|value="Hydro-Mechanical"|; s|<ParameterList name="Fracture">|<ParameterList name="Fluid"><Parameter name="Hydraulic Conductivity" type="double" value="1e-6"/><Parameter name="Fluid Bulk Modulus" type="double" value="2.2e7"/></ParameterList><ParameterList name="Fracture">|' 
# The same with water in the crack: p_f, injection at the notch's mouth, exchange, crack
# pressure on the faces (the network's distributed solve: solve=1 above).
# A film of 0.1 mm keeps the crack water's stiffness K_w / a_min within the fixed 2 us step;
# the injection is strong enough for the crack to grow before the restart.
flow_edit='s|value="Micropolar Solid"|value="Hydro-Mechanical"|; s|<ParameterList name="Fracture">|<ParameterList name="Fluid"><Parameter name="Hydraulic Conductivity" type="double" value="1e-6"/><Parameter name="Fluid Bulk Modulus" type="double" value="2.2e7"/></ParameterList><ParameterList name="Fracture">|; s|<Parameter name="Bond Breakage"|<Parameter name="Fracture Flow" type="bool" value="true"/><Parameter name="Minimum Aperture" type="double" value="1e-4"/><Parameter name="Bond Breakage"|; s|<ParameterList name="Pre-Cracks">|<ParameterList name="Regions"><ParameterList name="mouth"><Parameter name="Min" type="Array(double)" value="{0, 0.045}"/><Parameter name="Max" type="Array(double)" value="{0.005, 0.055}"/></ParameterList></ParameterList><ParameterList name="Pre-Cracks">|; s|<ParameterList name="Boundary Conditions">|<ParameterList name="Boundary Conditions"><ParameterList name="mouth"><Parameter name="Type" type="string" value="Fracture Source"/><Parameter name="Region" type="string" value="mouth"/><Parameter name="Value" type="double" value="1e-2"/></ParameterList>|'
solve=1
check fracture-flow tests/cli/fracture_small.xml 440 24 "$flow_edit"
# The same grown by the J criterion in increments of dx/2: the points next to its increments are
# fracture points before their damage reaches D_cr (kFlagCut), set again from the advances at
# the restart.
check fracture-flow-j tests/cli/fracture_small.xml 440 26 "$flow_edit; s|value=\"Energy\"/>|value=\"J-Integral\"/>|; s|  <ParameterList name=\"Boundary Conditions\">|  <ParameterList name=\"J-Integral\"><Parameter name=\"Half Widths\" type=\"Array(double)\" value=\"{4, 5}\"/><Parameter name=\"Crack Increment\" type=\"double\" value=\"0.00125\"/></ParameterList>\n&|"
# The same with the increments' bond forces released over the speed cap's wait (J-Integral->
# Release Time; the release field and its start are restored), restarted during a release.
check fracture-flow-j-release tests/cli/fracture_small.xml 440 27 "$flow_edit; s|value=\"Energy\"/>|value=\"J-Integral\"/>|; s|  <ParameterList name=\"Boundary Conditions\">|  <ParameterList name=\"J-Integral\"><Parameter name=\"Half Widths\" type=\"Array(double)\" value=\"{4, 5}\"/><Parameter name=\"Crack Increment\" type=\"double\" value=\"0.00125\"/><Parameter name=\"Maximum Crack Speed\" type=\"double\" value=\"10\"/><Parameter name=\"Release Time\" type=\"double\" value=\"1.25e-4\"/></ParameterList>\n&|"
# The same with a drained boundary layer at the notch's face (-x) that the crack runs into, its
# fracture points held by a mirrored Fracture Pressure (2 g - q, q relaxed from the step's start
# and rebuilt from the checkpointed p_f: src/solvers/fracture_flow.cpp, assemble).
check fracture-flow-mirrored tests/cli/fracture_small.xml 440 26 "s|value=\"\{-y, \+y\}\"|value=\"{-x, -y, +y}\"|; $flow_edit; s|<ParameterList name=\"Boundary Conditions\">|<ParameterList name=\"Boundary Conditions\"><ParameterList name=\"drained\"><Parameter name=\"Type\" type=\"string\" value=\"Pore Pressure\"/><Parameter name=\"Region\" type=\"string\" value=\"Layer -x\"/></ParameterList><ParameterList name=\"mouth pressure\"><Parameter name=\"Type\" type=\"string\" value=\"Fracture Pressure\"/><Parameter name=\"Region\" type=\"string\" value=\"Layer -x\"/><Parameter name=\"Value\" type=\"double\" value=\"1e6\"/><Parameter name=\"Boundary Layer Values\" type=\"string\" value=\"Mirrored\"/></ParameterList>|"
# Drucker-Prager plasticity (Example 3 at 16 x 32, dt = 1.75e-5 s): restarted at step 3700
# (t = 0.065 s), as the bands soften, with the plastic state, the step's start state and the
# second-order work's window in the checkpoint.
solve=0
check plastic inputs/example3_biaxial.xml 7400 16 's|value="0.00166666666666667"/>|value="0.00625"/>|; s|value="\{60, 120\}"|value="{16, 32}"|; s|value="\{0.00166666666666667, 0.2\}"|value="{0.00625, 0.2}"|; s|value="\{0.0983333333333333, 0\}"|value="{0.09375, 0}"|; s|<Parameter name="Time Step" type="double" value="2.5e-6"/>|<Parameter name="Time Step" type="double" value="1.75e-5"/>|; s|<ParameterList name="Output">|<ParameterList name="Output"><Parameter name="Second-Order Work Window" type="int" value="100"/>|'
# The same in plane stress with the pore water (the return to sigma'_zz = S_r p*, the plastic
# thickness change in the water's volumetric strain: laws/micropolar_drucker_prager.hpp).
check plastic-stress inputs/example3_biaxial.xml 7400 16 's|value="0.00166666666666667"/>|value="0.00625"/>|; s|value="\{60, 120\}"|value="{16, 32}"|; s|value="\{0.00166666666666667, 0.2\}"|value="{0.00625, 0.2}"|; s|value="\{0.0983333333333333, 0\}"|value="{0.09375, 0}"|; s|<Parameter name="Time Step" type="double" value="2.5e-6"/>|<Parameter name="Time Step" type="double" value="1.75e-5"/>|; s|<ParameterList name="Output">|<ParameterList name="Output"><Parameter name="Second-Order Work Window" type="int" value="100"/>|; s|<Parameter name="Dimension" type="int" value="2"/>|&<Parameter name="Plane" type="string" value="Stress"/>|'
# The same saturated with the semi-implicit pressure (the plastic thickness change a step late,
# solvers/fluid_solver.hpp lagged_plastic_source; the pressure solve: solve=1), restarted at
# step 2000 (t = 0.035 s) as the soil yields. Bit for bit on the same ranks; across rank and
# thread counts only while elastic (agree=1000: 4e-14): the yield amplifies the solve's
# differences (measured: 3e-7 at step 1600, 1 % at 2000 in the second-order work, as the bands
# form), so plasticity with a pressure solve is not rank-count independent (the explicit
# pressure is, bit for bit).
solve=1 agree=1000
check plastic-stress-si inputs/example3_biaxial.xml 4000 18 's|value="0.00166666666666667"/>|value="0.00625"/>|; s|value="\{60, 120\}"|value="{16, 32}"|; s|value="\{0.00166666666666667, 0.2\}"|value="{0.00625, 0.2}"|; s|value="\{0.0983333333333333, 0\}"|value="{0.09375, 0}"|; s|<Parameter name="Time Step" type="double" value="2.5e-6"/>|<Parameter name="Time Step" type="double" value="1.75e-5"/>|; s|<ParameterList name="Output">|<ParameterList name="Output"><Parameter name="Second-Order Work Window" type="int" value="100"/>|; s|<Parameter name="Dimension" type="int" value="2"/>|&<Parameter name="Plane" type="string" value="Stress"/>|; s|<Parameter name="Physics" type="string" value="Hydro-Mechanical"/>|&<Parameter name="Pressure Integration" type="string" value="Semi-Implicit"/>|; s|value="Van Genuchten"|value="Saturated"|; s|value="\{-25e3\}"|value="{0}"|'
# The same unsaturated: S_r, k_r and the storage change every step, so the system's values are
# written again on its kept graphs every step (include/mupm/solvers/kept_matrix.hpp) and the
# preconditioner kept for 20 steps (Preconditioner Refresh Interval = 20, Refresh Iteration
# Growth = 0, LinearSolve::refresh): the straight run writes no checkpoint at the restart's
# step, so it computes the preconditioner at step 2701 only because the refreshes, one a step
# from step 2, count 20 there; the restart computes it at step 2701 too, builds the graphs
# anew and continues bit for bit. (With the default interval, 100, or the growth rule, whose
# set-ups restart the count, the straight run would keep an older one there.) Restarted at step
# 2700 (t = 0.047 s), as the soil yields (from step ~2450); across rank counts at step 1000, as
# the saturated case.
check plastic-stress-si-unsaturated inputs/example3_biaxial.xml 5400 18 's|value="0.00166666666666667"/>|value="0.00625"/>|; s|value="\{60, 120\}"|value="{16, 32}"|; s|value="\{0.00166666666666667, 0.2\}"|value="{0.00625, 0.2}"|; s|value="\{0.0983333333333333, 0\}"|value="{0.09375, 0}"|; s|<Parameter name="Time Step" type="double" value="2.5e-6"/>|<Parameter name="Time Step" type="double" value="1.75e-5"/>|; s|<ParameterList name="Output">|<ParameterList name="Output"><Parameter name="Second-Order Work Window" type="int" value="100"/>|; s|<Parameter name="Dimension" type="int" value="2"/>|&<Parameter name="Plane" type="string" value="Stress"/>|; s|<Parameter name="Physics" type="string" value="Hydro-Mechanical"/>|&<Parameter name="Pressure Integration" type="string" value="Semi-Implicit"/>|; s|<Parameter name="Physics" type="string" value="Hydro-Mechanical"/>|&<ParameterList name="Pressure Solve"><Parameter name="Preconditioner Refresh Interval" type="int" value="20"/><Parameter name="Refresh Iteration Growth" type="double" value="0"/></ParameterList>|'
agree=
# The same with Automatic Time Step: the restart continues with the run's step (kept in the
# checkpoint), not with an estimate of the restarted state, whose crack water is stiffer.
solve=1
check fracture-flow-auto tests/cli/fracture_small.xml 440 24 "s|<Parameter name=\"Time Step\" type=\"double\" value=\"2e-6\"/>|<Parameter name=\"Automatic Time Step\" type=\"bool\" value=\"true\"/>|; $flow_edit"
# Breakage with the semi-implicit pressure and incompressible water, from zero pore pressure:
# the projection's matrix refilled at each breaking step, the bond energy of the effective
# force state. The ILU is computed at each refill (Preconditioner Refresh Interval = 1): the
# straight run writes no checkpoint at the restart's step, so factors kept from earlier values
# would differ from the ones the restart computes (tests/cli/semi_implicit.sh restarts at a
# checkpoint of the straight run, with kept factors).
check fracture-hm-si tests/cli/fracture_small.xml 440 18 's|value="Micropolar Solid"/>|value="Hydro-Mechanical"/><Parameter name="Pressure Integration" type="string" value="Semi-Implicit"/><ParameterList name="Pressure Solve"><Parameter name="Preconditioner Refresh Interval" type="int" value="1"/></ParameterList>|; s|<ParameterList name="Fracture">|<ParameterList name="Fluid"><Parameter name="Hydraulic Conductivity" type="double" value="1e-6"/><Parameter name="Incompressible" type="bool" value="true"/></ParameterList><ParameterList name="Fracture">|'
# Water (bulk + fracture + injected) over the straight run, whose crack and network grow.
selected fracture-flow && "$PYTHON" - <<'PY'
import csv
rows = list(csv.DictReader(open("fracture-flow-straight/time_series.csv")))
worst = max(abs(float(r["fluid_mass_error"])) / float(r["fluid_mass"]) for r in rows)
first, last = float(rows[1]["fracture_points"]), float(rows[-1]["fracture_points"])
assert last > first and float(rows[-1]["fluid_inflow_mouth"]) > 0, (first, last)
assert worst < 1e-12, worst
print(f"restart fracture-flow: water conserved to {worst:.1e} of the body's while the network "
      f"grew from {first:.0f} to {last:.0f} points")
PY
selected fracture-flow-mirrored && "$PYTHON" - <<'PY'
import csv
rows = list(csv.DictReader(open("fracture-flow-mirrored-straight/time_series.csv")))
worst = max(abs(float(r["fluid_mass_error"])) / float(r["fluid_mass"]) for r in rows)
assert worst < 1e-12 and float(rows[-1]["fluid_inflow_mouth pressure"]) != 0, worst
# The layer's fracture points (lattice columns 0-5 of 46, x fastest in the global id) take
# 2 g - q, not g = 1 MPa: the reflection ran.
import h5py, numpy as np
with h5py.File("fracture-flow-mirrored-straight/checkpoint.h5") as f:
    pf = f["points/fracture_pressure"][...].ravel()
    on = f["points/fracture_saturation"][...].ravel() > 0
layer = (np.arange(pf.size) % 46) < 6
reflected = int(np.count_nonzero(on & layer & (np.abs(pf - 1e6) > 1.0)))
assert pf.size == 46 * 52 and reflected > 0, (pf.size, reflected)
print(f"restart fracture-flow-mirrored: water conserved to {worst:.1e} of the body's; "
      f"{reflected} layer fracture points reflected")
PY
# And with the paper's eq 17 for the crack water's force.
check fracture-eq17 tests/cli/fracture_small.xml 440 23 's|value="Micropolar Solid"|value="Hydro-Mechanical"|; s|<ParameterList name="Fracture">|<ParameterList name="Fluid"><Parameter name="Hydraulic Conductivity" type="double" value="1e-6"/><Parameter name="Fluid Bulk Modulus" type="double" value="2.2e7"/></ParameterList><ParameterList name="Fracture">|; s|<Parameter name="Bond Breakage"|<Parameter name="Fracture Flow" type="bool" value="true"/><Parameter name="Crack Water Force" type="string" value="Eq 17"/><Parameter name="Bond Breakage"|; s|<ParameterList name="Pre-Cracks">|<ParameterList name="Regions"><ParameterList name="mouth"><Parameter name="Min" type="Array(double)" value="{0, 0.045}"/><Parameter name="Max" type="Array(double)" value="{0.005, 0.055}"/></ParameterList></ParameterList><ParameterList name="Pre-Cracks">|; s|<ParameterList name="Boundary Conditions">|<ParameterList name="Boundary Conditions"><ParameterList name="mouth"><Parameter name="Type" type="string" value="Fracture Source"/><Parameter name="Region" type="string" value="mouth"/><Parameter name="Value" type="double" value="5e-5"/></ParameterList>|'
# A case name that matches none is an error, not an empty pass.
for c in $cases; do
  [[ " $ran " == *" $c "* ]] || fail "no restart case named $c"
done
[[ -n ${ran:-} ]] || fail "no case ran"
echo "restart:$ran passed"
