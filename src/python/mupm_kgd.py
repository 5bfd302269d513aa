#!/usr/bin/env python3
"""Compare a KGD run (inputs/kgd_hydraulic_fracture.xml or a variant) with the closed form.

    /usr/bin/python3 src/python/mupm_kgd.py INPUT.xml [OUTPUT_DIR] [-o figure.png]

The closed form (plane strain, toughness-dominated, impermeable matrix, infinite plate, LEFM)
takes the undrained moduli (K_u = K + K_w / phi, E' = E_u / (1 - nu_u^2); E' = E_u with
Discretization->Plane = Stress), K_Ic = sqrt(G_cr E') and a0 the network's half-length at the
start: before growth (t < t0 = 2 sqrt(pi) a0^1.5 K_Ic / (E' Q0)) p = E' Q0 t / (2 pi a0^2); from
t0 on l = [E' Q0 t / (2 sqrt(pi) K_Ic)]^(2/3), p = K_Ic / sqrt(pi l); the mouth opening is
4 p l / E' throughout. Per field output: p_f at the mouth (the network's points in the column
of the source's centre), the opening there (the rows next to the crack), the network's
half-length (its farthest point from the centre along the crack) and, with the J criterion, the
tips' half-lengths (j_crack_length_tip1/2), each with its ratio to the closed form. With -o a
figure of the three against time.
"""
import argparse
import csv
import glob
import math
import os
import re
import sys

try:
    import h5py
    import numpy as np
except ImportError:
    sys.exit("mupm_kgd.py needs h5py and numpy: run it with /usr/bin/python3")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("input")
    ap.add_argument("output", nargs="?", help="the run's folder (default: the input's Folder)")
    ap.add_argument("-o", dest="figure", help="a figure of p_f, opening and half-length")
    args = ap.parse_args()
    xml = open(args.input).read()

    def num(name):
        m = re.search(r'name="%s" type="double" value="([^"]+)"' % re.escape(name), xml)
        if not m:
            sys.exit("mupm_kgd.py: %s has no double parameter '%s'" % (args.input, name))
        return float(m.group(1))

    def vec(name):
        m = re.search(r'name="%s" type="Array\(double\)" value="\{([^}]+)\}"' % re.escape(name), xml)
        return [float(v) for v in m.group(1).split(",")]

    folder = args.output or re.search(r'name="Folder" type="string" value="([^"]+)"', xml).group(1)
    K, mu, Kw, phi = (num(n) for n in ("Bulk Modulus", "Shear Modulus", "Fluid Bulk Modulus",
                                        "Porosity"))
    Q0, G = num("Value"), num("Critical Energy Release Rate")
    stress = re.search(r'name="Plane" type="string" value="Stress"', xml) is not None
    Ku = K + Kw / phi
    lam = Ku - 2 * mu / 3
    Ep = 9 * Ku * mu / (3 * Ku + mu) if stress else 4 * mu * (lam + mu) / (lam + 2 * mu)
    KIc = math.sqrt(G * Ep)
    start, end = vec("Start"), vec("End")
    yc = start[1]
    xc = 0.5 * (vec("Min")[0] + vec("Max")[0])
    rows = {int(r["step"]): r for r in csv.DictReader(open(os.path.join(folder, "time_series.csv")))}
    with h5py.File(os.path.join(folder, "mesh.h5")) as m:
        x = m["coordinates"][...]
    dx = num("Spacing")
    col = np.abs(x[:, 0] - xc) < np.abs(x[:, 0] - xc).min() + 1e-9
    up = col & (x[:, 1] > yc) & (x[:, 1] < yc + dx)
    down = col & (x[:, 1] < yc) & (x[:, 1] > yc - dx)
    files = sorted(glob.glob(os.path.join(folder, "fields_*.h5")))
    a0 = None
    out = []
    for f in files:
        step = int(f[-12:-3])
        t = float(rows[step]["time"])
        with h5py.File(f) as h:
            u, pf, net = h["displacement"][...], h["fracture_pressure"][...], h["fracture"][...] > 0
        a = np.abs(x[net, 0] - xc).max()
        if a0 is None:
            a0 = a
            t0 = 2 * math.sqrt(math.pi) * a0**1.5 * KIc / (Ep * Q0)
        if t <= 0:
            continue
        if t < t0:
            lc, pc = a0, Ep * Q0 * t / (2 * math.pi * a0 * a0)
        else:
            lc = (Ep * Q0 * t / (2 * math.sqrt(math.pi) * KIc)) ** (2.0 / 3.0)
            pc = KIc / math.sqrt(math.pi * lc)
        wc = 4 * pc * lc / Ep
        p = pf[net & col].mean()
        w = u[up, 1].mean() - u[down, 1].mean()
        r = rows[step]
        tips = None
        if "j_crack_length_tip1" in r and "j_crack_length_tip2" in r:
            tips = (float(r["j_crack_length_tip1"]), float(r["j_crack_length_tip2"]))
        out.append((t, p, pc, w, wc, a, lc, tips))
    print("KGD: E' = %.4g Pa, K_Ic = %.4g Pa m^0.5, a0 = %.4g m (network), t0 = %.4g s, onset "
          "p = %.4g Pa" % (Ep, KIc, a0, t0, KIc / math.sqrt(math.pi * a0)))
    print("t [ms] | p_f mouth [MPa] (closed, ratio) | opening [um] (closed, ratio) | network "
          "half-length [mm] (closed, ratio) | J tips' half-lengths [mm] (ratio)")
    for t, p, pc, w, wc, a, lc, tips in out:
        s = "%7.3f | %.4f (%.4f, %.3f) | %.2f (%.2f, %.3f) | %.2f (%.2f, %.3f)" % (
            t * 1e3, p * 1e-6, pc * 1e-6, p / pc, w * 1e6, wc * 1e6, w / wc, a * 1e3, lc * 1e3,
            a / lc)
        if tips:
            s += " | %.2f, %.2f (%.3f, %.3f)" % (tips[0] * 1e3, tips[1] * 1e3, tips[0] / lc,
                                                  tips[1] / lc)
        print(s)
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        t = np.array([o[0] for o in out]) * 1e3
        fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
        for k, (i, ic, scale, label) in enumerate([(1, 2, 1e-6, "p_f at the mouth [MPa]"),
                                                   (3, 4, 1e6, "mouth opening [µm]"),
                                                   (5, 6, 1e3, "half-length [mm]")]):
            ax[k].plot(t, [o[i] * scale for o in out], "o-", ms=3, label="mupm")
            ax[k].plot(t, [o[ic] * scale for o in out], "k--", label="closed form (LEFM)")
            if k == 2 and out[0][7]:
                ax[k].plot(t, [o[7][0] * scale for o in out], "s-", ms=2, label="J tip 1")
                ax[k].plot(t, [o[7][1] * scale for o in out], "^-", ms=2, label="J tip 2")
            ax[k].axvline(t0 * 1e3, color="grey", lw=0.5)
            ax[k].set_xlabel("t [ms]")
            ax[k].set_ylabel(label)
            ax[k].legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.figure, dpi=110)
        print("wrote", args.figure)


if __name__ == "__main__":
    main()
