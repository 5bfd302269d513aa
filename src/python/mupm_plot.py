#!/usr/bin/env python3
"""Plot mupm output with matplotlib + h5py (Debian: python3-matplotlib python3-h5py).

  mupm_plot.py field OUTPUT_DIR FIELD [--step N] [--component C] [--scale S] [-o out.png]
      2D point field (last output step by default) on the deformed points (scale S).
  mupm_plot.py series OUTPUT_DIR COLUMN [COLUMN...] [-o out.png]
      columns of time_series.csv against time.
  mupm_plot.py compare COLUMN OUTPUT_DIR[:LABEL] [OUTPUT_DIR[:LABEL] ...] [--time-scale S]
                       [--x-column X] [--xlabel TEXT] [--reference X Y [X Y ...]]
                       [--reference-label TEXT] [--scale Y] [--ylabel TEXT] [-o out.png]
      one column of several runs (x Y, e.g. --scale=-1e-3 for a compressive reaction in kN) against
      time x S (e.g. the load of a ramp), or against another column x S (--x-column, e.g.
      crack_length with S = 1/W for a/W), with reference points (X, Y) such as a paper's values.
"""
import argparse
import csv
import glob
import os
import shlex
import sys

try:
    import h5py
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
except ImportError as e:
    sys.exit(
        "mupm_plot.py needs h5py and matplotlib (with numpy); this Python (%s) cannot import "
        "%s.\nInstall them: apt-get install python3-h5py python3-matplotlib (Debian's "
        "/usr/bin/python3), or pip install h5py matplotlib (this Python).\nOr run it with "
        "Debian's Python: /usr/bin/python3 %s"
        % (sys.executable, e.name or e, " ".join(map(shlex.quote, sys.argv))))


def plot_field(args):
    files = sorted(glob.glob(os.path.join(args.dir, "fields_*.h5")))
    if not files:
        raise SystemExit("no fields_*.h5 in %s" % args.dir)
    path = files[-1] if args.step is None else os.path.join(args.dir, "fields_%09d.h5" % args.step)
    with h5py.File(os.path.join(args.dir, "mesh.h5")) as m, h5py.File(path) as f:
        x = m["coordinates"][...]
        if x.shape[1] != 2:
            raise SystemExit("field plots are for 2D runs; open fields.xmf in ParaView for 3D")
        if args.field not in f:
            raise SystemExit("%s not in %s (has: %s)" % (args.field, path, ", ".join(f)))
        v = f[args.field][...]
        if v.ndim == 2:
            v = v[:, args.component]
        if "displacement" in f and args.scale:
            x = x + args.scale * f["displacement"][...]
        time = f.attrs["time"]
    fig, ax = plt.subplots(figsize=(6, 5))
    sc = ax.scatter(x[:, 0], x[:, 1], c=v, s=2, marker="s", cmap="viridis")
    fig.colorbar(sc, ax=ax, label=args.field)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("%s at t = %.4g s" % (args.field, time))
    fig.savefig(args.output, dpi=150, bbox_inches="tight")
    print("wrote", args.output)


def plot_series(args):
    rows = list(csv.DictReader(open(os.path.join(args.dir, "time_series.csv"))))
    t = np.array([float(r["time"]) for r in rows])
    fig, ax = plt.subplots(figsize=(6, 4))
    for c in args.columns:
        ax.plot(t, [float(r[c]) for r in rows], label=c)
    ax.set_xlabel("time [s]")
    ax.legend()
    fig.savefig(args.output, dpi=150, bbox_inches="tight")
    print("wrote", args.output)


def plot_compare(args):
    fig, ax = plt.subplots(figsize=(6, 4))
    for run in args.runs:
        d, _, label = run.partition(":")
        rows = list(csv.DictReader(open(os.path.join(d, "time_series.csv"))))
        if args.column not in rows[0]:
            raise SystemExit("%s: no column %s in time_series.csv" % (d, args.column))
        if args.x_column and args.x_column not in rows[0]:
            raise SystemExit("%s: no column %s in time_series.csv" % (d, args.x_column))
        ax.plot([float(r[args.x_column or "time"]) * args.time_scale for r in rows],
                [float(r[args.column]) * args.scale for r in rows], label=label or d)
    if args.reference:
        if len(args.reference) % 2:
            raise SystemExit("--reference takes pairs X Y")
        ax.plot(args.reference[0::2], args.reference[1::2], "ko", label=args.reference_label)
    ax.set_xlabel(args.xlabel)
    ax.set_ylabel(args.ylabel or args.column)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(args.output, dpi=150, bbox_inches="tight")
    print("wrote", args.output)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    f = sub.add_parser("field")
    f.add_argument("dir")
    f.add_argument("field")
    f.add_argument("--step", type=int)
    f.add_argument("--component", type=int, default=0)
    f.add_argument("--scale", type=float, default=0.0)
    f.add_argument("-o", "--output", default="field.png")
    s = sub.add_parser("series")
    s.add_argument("dir")
    s.add_argument("columns", nargs="+")
    s.add_argument("-o", "--output", default="series.png")
    c = sub.add_parser("compare")
    c.add_argument("column")
    c.add_argument("runs", nargs="+", metavar="OUTPUT_DIR[:LABEL]")
    c.add_argument("--time-scale", type=float, default=1.0)
    c.add_argument("--x-column", default="")
    c.add_argument("--xlabel", default="time [s]")
    c.add_argument("--scale", type=float, default=1.0, help="multiplies the column (e.g. -1e-3)")
    c.add_argument("--ylabel", default="")
    c.add_argument("--reference", type=float, nargs="+")
    c.add_argument("--reference-label", default="reference")
    c.add_argument("-o", "--output", default="compare.png")
    args = p.parse_args()
    {"field": plot_field, "series": plot_series, "compare": plot_compare}[args.cmd](args)


if __name__ == "__main__":
    main()
