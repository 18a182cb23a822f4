#!/usr/bin/env python3
"""Regenerate the binary PLY files of this corpus (the text ones are edited by hand)."""
import struct


def hdr(fmt, vprops, fprops, nv, nf, extra=""):
    h = "ply\nformat %s 1.0\ncomment malformed test file\nelement vertex %d\n" % (fmt, nv)
    h += "".join("property %s\n" % p for p in vprops)
    h += "element face %d\n" % nf + "".join("property %s\n" % p for p in fprops) + extra
    return (h + "end_header\n").encode()


V = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
F3 = ["float x", "float y", "float z"]
LI = ["list uchar int vertex_indices"]
files = {
    # vertex count says 3, only 2 present
    "ply_bin_truncated.ply": hdr("binary_little_endian", F3, LI, 3, 1)
    + b"".join(struct.pack("<3f", *v) for v in V[:2]),
    # index out of range, with an extra normal property to skip
    "ply_bin_index_range.ply": hdr("binary_little_endian", F3 + ["float nx"], LI, 3, 1)
    + b"".join(struct.pack("<4f", *v, 0.5) for v in V) + struct.pack("<B3i", 3, 0, 1, 3),
    # negative list count (signed char)
    "ply_bin_neg_count.ply": hdr("binary_little_endian", ["double x", "double y", "double z"],
                                 ["list char int vertex_indices"], 3, 1)
    + b"".join(struct.pack("<3d", *v) for v in V) + struct.pack("<b3i", -1, 0, 1, 2),
    # NaN coordinate
    "ply_bin_nan.ply": hdr("binary_little_endian", F3, LI, 3, 1)
    + struct.pack("<3f", 0, 0, 0) + struct.pack("<3f", 1, float("nan"), 0)
    + struct.pack("<3f", 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2),
    # big endian, face list cut short
    "ply_be_truncated_face.ply": hdr("binary_big_endian", F3, ["list uchar uint vertex_indices"], 3, 1)
    + b"".join(struct.pack(">3f", *v) for v in V) + struct.pack(">B2I", 3, 0, 1),
    # big endian, face with 2 corners, index type ushort
    "ply_be_face_2.ply": hdr("binary_big_endian", F3, ["list uchar ushort vertex_indices"], 3, 1)
    + b"".join(struct.pack(">3f", *v) for v in V) + struct.pack(">B2H", 2, 0, 1),
    # an extra element with a list whose count runs past the end
    "ply_bin_extra_truncated.ply": hdr("binary_little_endian", F3, LI, 3, 1,
                                       "element material 1\nproperty list uint uchar name\n")
    + b"".join(struct.pack("<3f", *v) for v in V) + struct.pack("<B3i", 3, 0, 1, 2)
    + struct.pack("<I", 1000) + b"abc",
    # header claims a billion vertices: must fail as truncated, not allocate
    "ply_bin_huge_count.ply": hdr("binary_little_endian", F3, LI, 1000000000, 1)
    + b"".join(struct.pack("<3f", *v) for v in V),
}
for name, data in files.items():
    with open(name, "wb") as f:
        f.write(data)
