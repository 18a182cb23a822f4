"""STL and GLB files as other tools read them: parsed here with struct and
json by the formats' specifications (binary STL; Khronos glTF 2.0, "GLB File
Format Specification"), not by the library, and checked against numpy's
float32 positions, face normals and the faces; and every GLB read by
Khronos' own glTF validator (its npm build, pinned in tests/js and installed
by tools/setup.sh), which must find no error or warning and count the
vertices and triangles numpy counts."""
import json
import pathlib
import struct
import subprocess

import numpy as np
import pytest

import edgespace as es


VALIDATOR = pathlib.Path(__file__).resolve().parents[2] / "tests" / "js" / "validate_gltf.js"


def khronos_valid(path, nverts, ntris, attributes):
    """Khronos' validator's report on path: no errors, no warnings, and its
    own counts of vertices, triangles and vertex attributes."""
    assert (VALIDATOR.parent / "node_modules" / "gltf-validator").is_dir(), \
        "Khronos' glTF validator is missing: tools/setup.sh installs it (npm ci in tests/js)"
    r = subprocess.run(["node", str(VALIDATOR), str(path)], capture_output=True, text=True)
    assert r.returncode in (0, 1), r.stderr
    rep = json.loads(r.stdout)
    assert rep["issues"]["numErrors"] == 0 and rep["issues"]["numWarnings"] == 0, rep["issues"]
    info = rep["info"]
    assert (info["totalVertexCount"], info["totalTriangleCount"]) == (nverts, ntris)
    assert info["maxAttributes"] == attributes and info["drawCallCount"] == 1
    return rep


@pytest.fixture
def face(ctx):
    syn = es.synth("face", n=1, ctx=ctx)
    return syn["vertices"][0], syn["faces"]


def test_stl_has_float32_facets_with_unit_normals(face, tmp_path, ctx):
    V, F = face
    es.Mesh(F, V, ctx=ctx).write(tmp_path / "f.stl")
    data = (tmp_path / "f.stl").read_bytes()
    assert not data.startswith(b"solid")      # a binary STL must not look like ASCII
    (n,) = struct.unpack_from("<I", data, 80)
    assert n == len(F) and len(data) == 84 + 50 * n
    rec = np.frombuffer(data, np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                        count=n, offset=84)
    assert np.array_equal(rec["v"], V[F].astype(np.float32))
    want = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    want /= np.linalg.norm(want, axis=1, keepdims=True)
    assert np.allclose(rec["n"], want, atol=1e-6) and (rec["a"] == 0).all()
    with pytest.raises(es.Error, match="not read"):
        es.Mesh(F, ctx=ctx).read_positions(tmp_path / "f.stl")


def test_glb_chunks_accessors_and_colours(face, tmp_path, ctx):
    V, F = face
    rgb = (np.arange(3 * len(V)).reshape(-1, 3) % 256).astype(np.uint8)
    es.Mesh(F, V, ctx=ctx).write(tmp_path / "f.glb", colors=rgb)
    data = (tmp_path / "f.glb").read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    jlen, jtype = struct.unpack_from("<I4s", data, 12)
    assert jtype == b"JSON" and jlen % 4 == 0
    doc = json.loads(data[20:20 + jlen])
    blen, btype = struct.unpack_from("<I4s", data, 20 + jlen)
    assert btype == b"BIN\0" and blen % 4 == 0 and 28 + jlen + blen == len(data)
    bin_ = data[28 + jlen:]
    assert doc["asset"]["version"] == "2.0" and doc["buffers"][0]["byteLength"] == blen
    prim = doc["meshes"][0]["primitives"][0]
    assert prim.get("mode", 4) == 4                      # triangles

    def accessor(i, dtype, width):
        a = doc["accessors"][i]
        v = doc["bufferViews"][a["bufferView"]]
        off = v.get("byteOffset", 0) + a.get("byteOffset", 0)
        assert off % np.dtype(dtype).itemsize == 0       # the specification's alignment
        return a, np.frombuffer(bin_, dtype, a["count"] * width, off).reshape(a["count"], width)

    a, pos = accessor(prim["attributes"]["POSITION"], "<f4", 3)
    assert a["componentType"] == 5126 and a["type"] == "VEC3"
    assert np.array_equal(pos, V.astype(np.float32))
    assert np.allclose(a["min"], pos.min(axis=0), rtol=0) and np.allclose(a["max"], pos.max(axis=0), rtol=0)
    a, idx = accessor(prim["indices"], "<u4", 1)
    assert a["componentType"] == 5125 and np.array_equal(idx.reshape(-1, 3), F)
    a, col = accessor(prim["attributes"]["COLOR_0"], "u1", 4)
    assert a["normalized"] and a["componentType"] == 5121
    assert np.array_equal(col[:, :3], rgb) and (col[:, 3] == 255).all()
    khronos_valid(tmp_path / "f.glb", len(V), len(F), attributes=2)
    # without colours: no COLOR_0, and the BIN chunk holds positions and indices only
    es.Mesh(F, V, ctx=ctx).write(tmp_path / "g.glb")
    data = (tmp_path / "g.glb").read_bytes()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    assert "COLOR_0" not in doc["meshes"][0]["primitives"][0]["attributes"]
    assert doc["buffers"][0]["byteLength"] == 12 * len(V) + 12 * len(F)
    khronos_valid(tmp_path / "g.glb", len(V), len(F), attributes=1)
    # the validator is no rubber stamp: the same file cut short has errors
    (tmp_path / "cut.glb").write_bytes(data[:len(data) - 8])
    r = subprocess.run(["node", str(VALIDATOR), str(tmp_path / "cut.glb")], capture_output=True,
                       text=True)
    assert r.returncode == 1 and json.loads(r.stdout)["issues"]["numErrors"] > 0
