#!/usr/bin/env bash
# The paper's Example 3 (biaxial compression of an unsaturated Drucker-Prager soil) at reduced
# size: inputs/example3_biaxial.xml on a 24 x 48 grid (dx = 4.17 mm, delta = 3.05 dx, l = 5 mm
# kept), dt = 2e-5 s (the stable step is 3.5e-5 s), to t = 0.08 s (u_y = 8 mm), for
# psi = 35 deg (the base) and psi = 15 deg, on 2 ranks. Checked (the paper's claims, section
# 4.3):
#   - the load peaks and drops as the bands form (softening);
#   - two conjugate bands (both branches of the band measurement), symmetric about the vertical
#     axis (the equivalent plastic strain mirrored about x = W/2 to 1e-8 of its largest value),
#     crossing on that axis with no weak element;
#   - negative second-order work (eq 42, over windows of 200 steps) inside the bands as they
#     form: at the field output that ends the load's largest drop, at least 80 % of the
#     localized points (eps-hat >= half its largest value) have d2E < 0 (once a band has
#     softened to the residual cohesion its d2E turns positive again: the dilatancy against
#     the confinement hardens it; see tests/kernels/test_plasticity.cpp);
#   - the band angle is larger for psi = 35 than for psi = 15.
# Not asserted, printed: the angles against Roscoe's 45 + psi/2 and Coulomb's 45 + phi/2 (the
# paper's angle lies between them; ours, measured, is below Roscoe's: inputs/README.md).
#
# With a 6th argument "stress" (example3_reduced_plane_stress): psi = 35 in plane stress
# (Discretization->Plane = Stress) with the unsaturated pore water, the return to
# sigma'_zz = S_r p and the plastic thickness change in the water's balance
# (include/mupm/laws/micropolar_drucker_prager.hpp). Checked: the load peaks and softens; the
# field is symmetric about the vertical axis; the plastic zone crosses the whole width at
# mid-height (sigma_zz = 0 is the largest principal stress under the lateral confinement, so the
# band's plane contains the x axis and cuts through the thickness: in the plane it is a
# horizontal zone, not the conjugate pair of plane strain; at the full 60 x 120 the zones form
# along the platens instead, inputs/README.md); the solid's energy balance closes to
# 2e-3 of the external work (it does only with the plastic thickness change booked on both
# sides: leaving it out of the dissipation's in-plane share or of the water's volumetric strain
# left 3.4 J of 420 J), the water's to 1e-10 and its mass to round-off.
source "$(dirname "$0")/common.sh"
plane=${6:-strain}
# reduced PSI: the reduced input psiPSI.xml writing into outPSI.
reduced() {
  local psi=$1
  sed -E -e 's|<Parameter name="Folder" type="string" value="[^"]*"/>|<Parameter name="Folder" type="string" value="out'$psi'"/>|' \
      -e 's|value="0.00166666666666667"/>|value="0.00416666666666667"/>|; s|value="\{60, 120\}"|value="{24, 48}"|' \
      -e 's|value="\{0.00166666666666667, 0.2\}"|value="{0.00416666666666667, 0.2}"|; s|value="\{0.0983333333333333, 0\}"|value="{0.0958333333333333, 0}"|' \
      -e 's|<Parameter name="Time Step" type="double" value="2.5e-6"/>|<Parameter name="Time Step" type="double" value="2e-5"/>|' \
      -e 's|<Parameter name="Number of Steps" type="int" value="40000"/>|<Parameter name="Number of Steps" type="int" value="4000"/>|' \
      -e 's|<Parameter name="Field Interval" type="int" value="[0-9]+"/>|<Parameter name="Field Interval" type="int" value="200"/>|' \
      -e 's|<Parameter name="Time Series Interval" type="int" value="[0-9]+"/>|<Parameter name="Time Series Interval" type="int" value="50"/>|' \
      -e 's|<Parameter name="Second-Order Work Window" type="int" value="[0-9]+"/>||' \
      -e 's|<ParameterList name="Output">|<ParameterList name="Output"><Parameter name="Second-Order Work Window" type="int" value="200"/>|' \
      -e 's|name="Dilation Angle" type="double" value="35"|name="Dilation Angle" type="double" value="'$psi'"|' \
      "$SRC/inputs/example3_biaxial.xml" >psi$psi.xml
  for k in 'value="{24, 48}"' 'value="2e-5"' 'value="4000"' 'value="{0.0958333333333333, 0}"' 'Dilation Angle" type="double" value="'$psi'"' second_order_work; do
    grep -qF "$k" psi$psi.xml || fail "inputs/example3_biaxial.xml changed: psi$psi.xml lacks $k"
  done
}
if [[ $plane == stress ]]; then
  reduced 35
  sed -i 's|<Parameter name="Dimension" type="int" value="2"/>|&<Parameter name="Plane" type="string" value="Stress"/>|' psi35.xml
  grep -qF 'value="Stress"' psi35.xml || fail "psi35.xml: no Dimension to add Plane = Stress to"
  run 2 1 psi35.xml >psi35.out
  PYTHONPATH="$SRC/tests/cli" "$PYTHON" - <<'PY'
import csv, h5py, numpy as np
from example3_checks import mirror_asymmetry
rows = list(csv.DictReader(open("out35/time_series.csv")))
R = np.array([-float(r["reaction_top"]) for r in rows])
peak = R.argmax()
assert 0 < peak < len(R) - 1 and R[-1] < 0.8 * R[peak], ("no softening", R[peak], R[-1])
x = h5py.File("out35/mesh.h5")["coordinates"][...]
f = h5py.File("out35/fields_%09d.h5" % 4000)
e = f["equivalent_plastic_strain"][...]
body = (x[:, 1] > 0) & (x[:, 1] < 0.2)
asym = mirror_asymmetry(x, e)
assert asym < 1e-8, ("not symmetric about the vertical axis", asym)
loc = body & (e >= 0.5 * e.max())
dx = 0.1 / 24
xs, ys = x[loc, 0], x[loc, 1]
assert xs.min() < 2 * dx and xs.max() > 0.1 - 2 * dx, ("the zone does not cross the width", xs.min(), xs.max())
assert np.abs(ys - 0.1).max() < 0.2 / 4, ("the zone is not at mid-height", ys.min(), ys.max())
last = rows[-1]
work = float(last["external_work"])
err = max(abs(float(r["energy_error"])) for r in rows)
assert err < 2e-3 * work, ("solid energy", err, work)
scale = max(abs(float(r[k])) for r in rows for k in ("fluid_stored_energy", "fluid_coupling_work", "fluid_dissipation"))
ferr = max(abs(float(r["fluid_energy_error"])) for r in rows)
assert ferr < 1e-10 * scale, ("fluid energy", ferr, scale)
merr = max(abs(float(r["fluid_mass_error"])) for r in rows)
assert merr < 1e-12 * float(last["fluid_mass"]), ("water", merr)
print("example3 reduced, plane stress, psi = 35: peak load %.1f kN/m at u_y = %.2f mm, %.1f kN/m "
      "at 8 mm; plastic zone y = %.4f..%.4f m across the width; mirror asymmetry %.1e; solid "
      "energy error %.3g J of %.1f J external work (plastic dissipation %.1f J); fluid energy "
      "error %.1e J of %.3g; water error %.1e kg; plastic volume change in the zone %.4f (mean), "
      "pore pressure there %.1f kPa"
      % (R[peak] / 1e3, float(rows[peak]["time"]) * 100, R[-1] / 1e3, ys.min(), ys.max(), asym,
         err, work, float(last["plastic_dissipation"]), ferr, scale, merr,
         f["plastic_volumetric_strain"][...][loc].mean(), f["pore_pressure"][...][loc].mean() / 1e3))
PY
  echo "example3_reduced_plane_stress: OK"
  exit 0
fi
for psi in 35 15; do
  reduced $psi
  run 2 1 psi$psi.xml >psi$psi.out
done
PYTHONPATH="$SRC/tests/cli" "$PYTHON" - <<'PY'
import csv, math, h5py, numpy as np
from example3_checks import mirror_asymmetry
angle = {}
for psi in (35, 15):
    rows = list(csv.DictReader(open("out%d/time_series.csv" % psi)))
    R = np.array([-float(r["reaction_top"]) for r in rows])
    peak = R.argmax()
    assert 0 < peak < len(R) - 1 and R[-1] < 0.8 * R[peak], ("no softening", R[peak], R[-1])
    last = rows[-1]
    angle[psi] = float(last["band_angle"])
    assert angle[psi] > 0, "no band at the end"
    mesh = h5py.File("out%d/mesh.h5" % psi)
    x = mesh["coordinates"][...]
    f = h5py.File("out%d/fields_%09d.h5" % (psi, 4000))
    e = f["equivalent_plastic_strain"][...]
    d2 = f["second_order_work"][...]
    body = (x[:, 1] > 0) & (x[:, 1] < 0.2)
    asym = mirror_asymmetry(x, e)
    assert asym < 1e-8, ("not symmetric about the vertical axis", asym)
    xc = x[body][np.argmax(e[body])]
    dx = 0.1 / 24
    assert abs(xc[0] - 0.05) < 2 * dx, ("the bands cross off the axis", xc)
    # The field output that ends the largest load drop between two outputs (every 200 steps).
    by_step = {int(float(r["step"])): -float(r["reaction_top"]) for r in rows}
    outs = list(range(200, 4001, 200))
    s = max(outs[1:], key=lambda k: by_step[k - 200] - by_step[k])
    g = h5py.File("out%d/fields_%09d.h5" % (psi, s))
    eg, dg = g["equivalent_plastic_strain"][...], g["second_order_work"][...]
    loc = body & (eg >= 0.5 * eg.max())
    negloc = (dg[loc] < 0).mean()
    assert negloc > 0.8, ("d2E >= 0 in the forming bands", s, negloc)
    print("example3 reduced, psi = %d: peak load %.1f kN/m at u_y = %.2f mm, %.1f kN/m at 8 mm; "
          "band angle %.1f deg (Roscoe %.1f, Coulomb %.1f), width %.1f mm; bands cross at "
          "(%.4f, %.4f) m; mirror asymmetry %.1e; as the bands form (step %d) d2E < 0 on %.0f %% of "
          "the localized points; plastic volume change in the band %.4f (mean), pore "
          "pressure in the band %.1f kPa (mean), elsewhere %.1f kPa"
          % (psi, R[peak] / 1e3, float(rows[peak]["time"]) * 100, R[-1] / 1e3, angle[psi],
             45 + psi / 2, 45 + 35 / 2, float(last["band_width"]) * 1e3, xc[0], xc[1], asym,
             s, 100 * negloc,
             f["plastic_volumetric_strain"][...][body & (e >= 0.5 * e.max())].mean(),
             f["pore_pressure"][...][body & (e >= 0.5 * e.max())].mean() / 1e3,
             f["pore_pressure"][...][body & (e < 0.5 * e.max())].mean() / 1e3))
assert angle[35] > angle[15], angle
PY
echo "example3_reduced: OK"
