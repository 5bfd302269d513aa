#!/usr/bin/env bash
# The quick start on 2 ranks: the run ends well, and its XDMF/HDF5/CSV outputs open in the
# readers users have (XDMF parsed, every referenced dataset found with its declared shape).
source "$(dirname "$0")/common.sh"
run 2 1 "$SRC/inputs/quickstart.xml" | tee run.out
grep -q "point-steps/s" run.out || fail "no throughput line"
grep -q "ETA" run.out || fail "no progress line"
grep -q "mupm::Fracture::damage" run.out || fail "no kernel time table"
"$PYTHON" "$SRC/tests/check_xdmf.py" output/fields.xmf
"$PYTHON" - <<'PY'
import csv, h5py, numpy as np
rows = list(csv.DictReader(open("output/time_series.csv")))
assert len(rows) == 2000 // 20 + 1, len(rows)
assert float(rows[-1]["step"]) == 2000
with h5py.File("output/mesh.h5") as m, h5py.File("output/fields_000002000.h5") as f:
    x = m["coordinates"][...]
    gid = m["global_id"][...]
    assert x.shape == (100 * 106, 2), x.shape          # 100 x 100 + 2 x 3 layer rows
    assert (gid == np.arange(len(gid))).all()
    u = f["displacement"][...]
    # Kinematics only: a layer point moved by v t = 0.01 m/s * 1e-3 s, the body did not move.
    top = x[:, 1] > 0.25
    assert np.allclose(u[top, 1], 1e-5, rtol=1e-9), u[top, 1][:3]
    assert np.all(u[(x[:, 1] > 0) & (x[:, 1] < 0.25)] == 0)
    d = f["damage"][...]
    # Points next to the notch lost bonds; points far from it did not.
    near = (np.abs(x[:, 1] - 0.125) < 0.002) & (x[:, 0] < 0.045)
    far = np.abs(x[:, 1] - 0.125) > 0.01
    assert d[near].min() > 0.2 and d[far].max() == 0, (d[near].min(), d[far].max())
print("quickstart outputs ok")
PY
echo "run_quickstart: passed"
