#!/usr/bin/env python3
"""Regenerate the binary PLY files here: the tetrahedron of tetra.ply in both
endians, with extra properties and an extra element to skip."""
import struct

V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
F = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]
for fmt, e in (("binary_little_endian", "<"), ("binary_big_endian", ">")):
    h = ("ply\nformat %s 1.0\nelement vertex 4\nproperty double x\nproperty short extra\n"
         "property float y\nproperty float z\nproperty list uchar ushort junk\n"
         "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
         "element face 4\nproperty uchar flags\nproperty list uint uint vertex_indices\n"
         "end_header\n" % fmt).encode()
    b = h
    for x, y, z in V:
        b += struct.pack(e + "dhff", x, -7, y, z) + struct.pack(e + "B2H", 2, 1, 2)
    b += struct.pack(e + "2i", 0, 1)
    for f in F:
        b += struct.pack(e + "BI3I", 0, 3, *f)
    with open("tetra_%s.ply" % ("le" if e == "<" else "be"), "wb") as out:
        out.write(b)
