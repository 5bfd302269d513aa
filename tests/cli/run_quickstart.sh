#!/usr/bin/env bash
# The quick start on 2 ranks: the run ends well, its outputs open in the readers users have
# (XDMF parsed and every referenced dataset found with its declared shape), and its physics
# holds: prescribed layer displacements, balanced reactions, energy conserved.
source "$(dirname "$0")/common.sh"
run 2 1 "$SRC/inputs/quickstart.xml" | tee run.out
grep -q "point-steps/s" run.out || fail "no throughput line"
grep -q "ETA" run.out || fail "no progress line"
grep -q "mupm::Solid::pass2" run.out || fail "no kernel time table"
grep -q "WARNING" run.out && fail "the quick start printed a warning"
# A step allocates no View (each would be a system call and a fill per step; the buffers of the
# ghost refreshes are kept by width: include/mupm/mesh/distribution.hpp).
grep -q "^View allocations in the time loop: 0 " run.out ||
  fail "the time loop allocated Views: $(grep -A5 '^View allocations' run.out)"
"$PYTHON" "$SRC/tests/cli/check_xdmf.py" output/fields.xmf
"$PYTHON" - <<'PY'
import csv, h5py, numpy as np
rows = list(csv.DictReader(open("output/time_series.csv")))
assert len(rows) == 3000 // 30 + 1, len(rows)
last = rows[-1]
assert float(last["step"]) == 3000
w = float(last["external_work"])
assert w > 0
# Energy balance (eqs 137-140): E_int + E_kin + D - W_ext stays at 0 within 1e-4 of the work.
err = max(abs(float(r["energy_error"])) for r in rows)
assert err < 1e-4 * w, (err, w)
# The two layers pull with equal and opposite forces once the plate is loaded.
top, bottom = float(last["reaction_top"]), float(last["reaction_bottom"])
assert top > 0 and abs(top + bottom) < 1e-9 * top, (top, bottom)
with h5py.File("output/mesh.h5") as m, h5py.File("output/fields_000003000.h5") as f:
    x = m["coordinates"][...]
    gid = m["global_id"][...]
    assert x.shape == (100 * 112, 2), x.shape  # 100 x 100 + 2 layers of 2 horizons (6 rows)
    assert (gid == np.arange(len(gid))).all()
    u = f["displacement"][...]
    top_layer = x[:, 1] > 0.25
    assert np.all(u[top_layer, 1] == 1e-4), u[top_layer, 1][:3]  # ramp done: held at 0.1 mm
    assert np.all(u[x[:, 1] < 0, 1] == -1e-4)
    inside = (x[:, 1] > 0) & (x[:, 1] < 0.25)
    assert np.abs(u[inside, 1]).max() < 1.2e-4
    d = f["damage"][...]
    near = (np.abs(x[:, 1] - 0.125) < 0.002) & (x[:, 0] < 0.045)
    far = np.abs(x[:, 1] - 0.125) > 0.01
    assert d[near].min() > 0.2 and d[far].max() == 0, (d[near].min(), d[far].max())
    # The crack tip concentrates the stress: sigma_yy ahead of the tip exceeds the far field.
    s = f["stress"][...]
    tip = (np.abs(x[:, 0] - 0.05125) < 0.002) & (np.abs(x[:, 1] - 0.125) < 0.002)
    remote = (np.abs(x[:, 0] - 0.2) < 0.002) & (np.abs(x[:, 1] - 0.125) < 0.002)
    assert s[tip, 3].mean() > 2 * s[remote, 3].mean() > 0, (s[tip, 3].mean(), s[remote, 3].mean())
print("quickstart outputs ok: W_ext = %.4g J, energy error %.2g J, reaction %.4g N" % (w, err, top))
PY
echo "run_quickstart: passed"
