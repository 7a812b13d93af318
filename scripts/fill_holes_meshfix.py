"""Fills a mesh's holes with MeshFix (an independent mesh repair) and writes a binary STL:
the reference an open scan's sections are compared with (tests/oracle.rs). Needs numpy and
pymeshfix 0.18.1 (`python3 -m venv v && v/bin/pip install numpy pymeshfix==0.18.1`); only
`scripts/make_oracle_fixtures.sh` runs it, never the tests.

Usage: fill_holes_meshfix.py IN.stl OUT.stl
"""

import struct
import sys

import numpy as np
import pymeshfix


def read_stl(path):
    data = open(path, "rb").read()
    n = struct.unpack("<I", data[80:84])[0]
    rec = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    facets = np.frombuffer(data[84 : 84 + n * 50], dtype=rec)
    corners = facets["v"].reshape(-1, 3).astype(np.float64)
    vertices, index = np.unique(corners, axis=0, return_inverse=True)
    return vertices, index.reshape(-1, 3)


def write_stl(path, vertices, faces):
    out = bytearray(80) + struct.pack("<I", len(faces))
    for f in faces:
        out += struct.pack("<3f", 0, 0, 0)
        out += b"".join(struct.pack("<3f", *vertices[i]) for i in f)
        out += b"\0\0"
    open(path, "wb").write(out)


def main():
    vertices, faces = read_stl(sys.argv[1])
    fix = pymeshfix.MeshFix(vertices, faces)
    fix.repair(joincomp=False, remove_smallest_components=False)
    write_stl(sys.argv[2], fix.points, fix.faces)
    print(f"{len(faces)} facets in, {len(fix.faces)} out", file=sys.stderr)


main()
