"""Checks shared by the reduced Example 3 runs (tests/cli/example3_reduced.sh)."""
import numpy as np


def mirror_asymmetry(x, e, width=0.1):
    """max |e - e(mirror)| / max e, the mirror of a point about the vertical axis x = width / 2
    (the points of x, in the field's order, on a lattice symmetric about it)."""
    key = {(round(a * 1e7), round(b * 1e7)): i for i, (a, b) in enumerate(x)}
    mirror = np.array([key[(round((width - a) * 1e7), round(b * 1e7))] for a, b in x])
    return np.abs(e - e[mirror]).max() / e.max()
