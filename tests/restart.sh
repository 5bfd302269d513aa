#!/usr/bin/env bash
# Checkpoint -> restart on another number of ranks and threads continues bit for bit: a run of
# 40 steps on 1 rank equals 20 steps on 2 ranks followed by 20 more on 1 rank x 2 threads.
source "$(dirname "$0")/common.sh"
make_input() {  # make_input FOLDER STEPS RESTART
  sed -e "s|<Parameter name=\"Folder\" type=\"string\" value=\"output\"/>|<Parameter name=\"Folder\" type=\"string\" value=\"$1\"/>|" \
      -e "s|<Parameter name=\"Number of Steps\" type=\"int\" value=\"2000\"/>|<Parameter name=\"Number of Steps\" type=\"int\" value=\"$2\"/><Parameter name=\"Restart From\" type=\"string\" value=\"$3\"/>|" \
      -e "s|<Parameter name=\"Field Interval\" type=\"int\" value=\"200\"/>|<Parameter name=\"Field Interval\" type=\"int\" value=\"20\"/>|" \
      -e "s|value=\"{displacement, velocity, damage, fracture, regions}\"|value=\"{displacement, velocity, acceleration, micro_rotation, damage, fracture}\"|" \
      "$SRC/inputs/quickstart.xml"
}
make_input straight 40 "" >straight.xml
make_input first 20 "" >first.xml
make_input second 40 "first/checkpoint.h5" >second.xml
run 1 1 straight.xml >straight.out
run 2 1 first.xml >first.out
run 1 2 second.xml >second.out
grep -q "restarted from first/checkpoint.h5 at step 20" second.out || fail "no restart line"
"$PYTHON" - <<'PY'
import h5py, numpy as np
with h5py.File("straight/fields_000000040.h5") as a, h5py.File("second/fields_000000040.h5") as b:
    for name in a:
        x, y = a[name][...], b[name][...]
        assert x.shape == y.shape and x.tobytes() == y.tobytes(), name
    print("restart: %d fields equal bit for bit" % len(a))
with h5py.File("straight/checkpoint.h5") as a, h5py.File("second/checkpoint.h5") as b:
    for grp in ("points", "bonds"):
        for name in a[grp]:
            assert a[grp][name][...].tobytes() == b[grp][name][...].tobytes(), name
    print("restart: checkpoints equal bit for bit")
PY
echo "restart: passed"
