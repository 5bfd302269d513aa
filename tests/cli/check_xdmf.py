#!/usr/bin/python3
"""Checks that an XDMF file only references HDF5 datasets that exist with the declared shape.

Usage: /usr/bin/python3 check_xdmf.py FILE.xmf
(Debian's /usr/bin/python3 has h5py.) Paths in the .xmf are taken relative to its folder.
Prints "xdmf ok: N steps, M fields" (N = uniform grids, M = distinct attribute names) and exits 0,
or prints every problem found and exits 1.
"""

import os
import sys
import xml.etree.ElementTree as ET

import h5py

# XDMF NumberType -> numpy dtype kinds it may describe.
KINDS = {"float": "f", "int": "i", "uint": "u", "char": "i", "uchar": "u"}


def check_item(item, where, base, problems):
    fmt = item.get("Format", "XML")
    if fmt != "HDF":
        return
    dims_attr = item.get("Dimensions")
    ref = (item.text or "").strip()
    if dims_attr is None or ":" not in ref:
        problems.append(f"{where}: DataItem needs Dimensions and 'file.h5:/path', got {ref!r}")
        return
    h5_file, h5_path = ref.split(":", 1)
    full = os.path.join(base, h5_file)
    try:
        dims = tuple(int(d) for d in dims_attr.split())
    except ValueError:
        problems.append(f"{where}: bad Dimensions {dims_attr!r}")
        return
    if not os.path.isfile(full):
        problems.append(f"{where}: HDF5 file {full} not found")
        return
    try:
        with h5py.File(full, "r") as f:
            obj = f.get(h5_path)
            if not isinstance(obj, h5py.Dataset):
                problems.append(f"{where}: dataset {h5_path} not found in {full}")
                return
            if tuple(obj.shape) != dims:
                problems.append(
                    f"{where}: {full}:{h5_path} has shape {tuple(obj.shape)}, "
                    f"Dimensions says {dims}")
            number_type = item.get("NumberType", item.get("DataType", "Float")).lower()
            precision = int(item.get("Precision", "4"))
            kind = KINDS.get(number_type)
            if kind is not None and (obj.dtype.kind != kind or obj.dtype.itemsize != precision):
                problems.append(
                    f"{where}: {full}:{h5_path} has dtype {obj.dtype}, "
                    f"XDMF says {number_type} {precision}")
    except OSError as e:
        problems.append(f"{where}: cannot read {full}: {e}")


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    xmf = argv[1]
    base = os.path.dirname(os.path.abspath(xmf))
    try:
        root = ET.parse(xmf).getroot()
    except (OSError, ET.ParseError) as e:
        print(f"{xmf}: cannot parse: {e}", file=sys.stderr)
        return 1

    problems = []
    steps = [g for g in root.iter("Grid") if g.get("GridType", "Uniform") == "Uniform"]
    fields = set()
    for i, grid in enumerate(steps):
        where = f"{xmf}: grid {grid.get('Name', i)}"
        topo = grid.find("Topology")
        geo = grid.find("Geometry")
        if topo is None or geo is None:
            problems.append(f"{where}: missing Topology or Geometry")
            continue
        n = topo.get("NumberOfElements")
        for item in grid.iter("DataItem"):
            dims = item.get("Dimensions", "").split()
            if n is not None and dims and dims[0] != n:
                problems.append(f"{where}: DataItem rows {dims[0]} != NumberOfElements {n}")
            check_item(item, where, base, problems)
        for attr in grid.findall("Attribute"):
            fields.add(attr.get("Name"))
        time = grid.find("Time")
        if time is not None:
            try:
                float(time.get("Value"))
            except (TypeError, ValueError):
                problems.append(f"{where}: bad Time Value {time.get('Value')!r}")

    if not steps:
        problems.append(f"{xmf}: no Uniform grid")
    if problems:
        for p in problems:
            print(p, file=sys.stderr)
        return 1
    print(f"xdmf ok: {len(steps)} steps, {len(fields)} fields")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
