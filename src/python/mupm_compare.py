#!/usr/bin/env python3
"""Compare two mupm output folders dataset by dataset, bit for bit.

    /usr/bin/python3 src/python/mupm_compare.py FOLDER_A FOLDER_B

Every HDF5 file of FOLDER_A (mesh.h5, fields_*.h5, checkpoint.h5) must exist in FOLDER_B; every
dataset the two files share must have the same shape and bytes. Datasets only one side has are
listed (a newer mupm may add fields) but do not fail the comparison. Prints one line per file and
exits 1 on any difference, 0 otherwise. Used to check that a change keeps results bit for bit,
or that runs on different rank and thread counts agree.
"""
import glob
import os
import sys

try:
    import h5py
except ImportError:
    sys.exit("mupm_compare.py needs h5py: apt-get install python3-h5py (or pip install h5py), "
             "or run it with /usr/bin/python3")


def datasets(f):
    out = {}
    f.visititems(lambda k, d: out.__setitem__(k, d) if isinstance(d, h5py.Dataset) else None)
    return out


def main(a, b):
    bad = 0
    files = sorted(os.path.basename(p) for p in glob.glob(os.path.join(a, "*.h5")))
    if not files:
        sys.exit(f"no .h5 files in {a}")
    for name in files:
        pb = os.path.join(b, name)
        if not os.path.exists(pb):
            print(f"{name}: missing in {b}")
            bad += 1
            continue
        with h5py.File(os.path.join(a, name)) as fa, h5py.File(pb) as fb:
            da, db = datasets(fa), datasets(fb)
            common = sorted(set(da) & set(db))
            diff = [k for k in common
                    if da[k].shape != db[k].shape or da[k][...].tobytes() != db[k][...].tobytes()]
            only = sorted(set(da) ^ set(db))
            print(f"{name}: {len(common) - len(diff)}/{len(common)} datasets equal"
                  + (f"; differ: {', '.join(diff)}" if diff else "")
                  + (f"; in one only: {', '.join(only)}" if only else ""))
            bad += len(diff)
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
