"""Meshes for other viewers: scalar colours against the published viridis
values (matplotlib's _viridis_data: #440154, #21918c, #fde725) and numpy's
percentiles, a coloured PLY read back by a parser written here (numpy's
structured dtype over the binary body), and a .vtp read back with
xml.etree (not the writer's code)."""
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import edgespace as es


def test_scalar_colors(ctx):
    c = es.scalar_colors([0.0, 0.5, 1.0, np.nan])
    assert [bytes(x).hex() for x in c[:3]] == ["440154", "21918c", "fde725"]
    assert list(c[3]) == [153, 153, 153]                  # ES_NAN_GREY
    v = np.random.default_rng(1).lognormal(sigma=2, size=200)
    lo, hi = np.percentile(v, [5, 95])
    c = es.scalar_colors(v, percentiles=(5, 95))
    assert np.array_equal(c[v <= lo][0], c[np.argmin(v)])  # clamped to the ends
    assert np.array_equal(c[np.argmax(v)], es.scalar_colors([1.0], vmin=0, vmax=1)[0])
    # rdbu: symmetric about 0 without a range
    assert np.array_equal(es.scalar_colors([-1.0, 0.5], cmap="rdbu")[1],
                          es.scalar_colors([0.5], cmap="rdbu", vmin=-1, vmax=1)[0])
    with pytest.raises(ValueError, match="colour map"):
        es.scalar_colors([1.0], cmap="jet")


def read_ply(path):
    data = open(path, "rb").read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    assert "format binary_little_endian 1.0" in lines
    nv = int(next(ln for ln in lines if ln.startswith("element vertex")).split()[-1])
    props = [ln.split()[1:] for ln in lines if ln.startswith("property") and "list" not in ln]
    dt = np.dtype([(name, {"double": "<f8", "uchar": "u1", "float": "<f4"}[t])
                   for t, name in props])
    return np.frombuffer(body, dtype=dt, count=nv)


def test_coloured_ply_and_vtp(tmp_path, ctx):
    syn = es.synth("face", n=1, ctx=ctx)
    X, F = syn["vertices"][0], syn["faces"]
    m = es.Mesh(F, X, ctx=ctx)
    z = X[:, 2]
    rgb = es.scalar_colors(z, percentiles=(2, 98))
    m.write(tmp_path / "c.ply", colors=rgb)
    v = read_ply(tmp_path / "c.ply")
    assert np.array_equal(np.c_[v["x"], v["y"], v["z"]], X)
    assert np.array_equal(np.c_[v["red"], v["green"], v["blue"]], rgb)
    m.write(tmp_path / "f.ply", colors=np.ones((m.nverts, 3)) * 0.5)   # floats in [0, 1]
    assert set(read_ply(tmp_path / "f.ply")["red"]) == {128}
    with pytest.raises(ValueError, match="colors"):
        m.write(tmp_path / "x.ply", colors=rgb[:-1])

    es.write_vtp(tmp_path / "c.vtp", X, F, point_data={"z": z, "xyz": X},
                 cell_data={"face": np.arange(len(F))})
    piece = ET.parse(tmp_path / "c.vtp").getroot().find("PolyData/Piece")
    assert int(piece.get("NumberOfPoints")) == len(X)
    assert int(piece.get("NumberOfPolys")) == len(F)

    def arr(path, name):
        e = next(a for a in piece.iterfind(path + "/DataArray") if a.get("Name") == name)
        return np.array(e.text.split(), dtype=float), int(e.get("NumberOfComponents"))
    pts, k = arr("Points", "Points")
    assert k == 3 and np.array_equal(pts.reshape(-1, 3), X)
    assert np.array_equal(arr("PointData", "z")[0], z)
    assert np.array_equal(arr("PointData", "xyz")[0].reshape(-1, 3), X)
    assert np.array_equal(arr("CellData", "face")[0], np.arange(len(F)))
    conn, _ = arr("Polys", "connectivity")
    offs, _ = arr("Polys", "offsets")
    assert np.array_equal(conn.reshape(-1, 3), F) and offs[-1] == 3 * len(F)
    with pytest.raises(ValueError, match="has 3 values"):
        es.write_vtp(tmp_path / "x.vtp", X, F, point_data={"bad": [1, 2, 3]})


def test_render_writes_coloured_ply_glb_and_vtp(tmp_path, cli, ctx):
    """render MESH --scalars CSV -o OUT.ply|.glb|.vtp: the colours are
    scalar_colors' (numpy's percentiles for the range) of the chosen column;
    face values reach the vertices as numpy's mean over each vertex's faces;
    the PLY (parser above), VTP (xml.etree) and GLB (struct, json) read back."""
    import json
    import struct
    syn = es.synth("face", n=1, ctx=ctx)
    X, F = syn["vertices"][0], syn["faces"]
    es.Mesh(F, X, ctx=ctx).write(tmp_path / "f.obj")
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=len(X)), rng.lognormal(sigma=2, size=len(X))
    b[7] = np.nan
    with open(tmp_path / "v.csv", "w") as f:
        f.write("a,b\n" + "".join(f"{x!r},{y!r}\n" for x, y in zip(a, b)))
    want = es.scalar_colors(b, percentiles=(5, 95))
    r = cli("render", tmp_path / "f.obj", "--scalars", tmp_path / "v.csv", "--column", "b",
            "--percentiles", "5,95", "-o", tmp_path / "c.ply")
    assert "coloured mesh" in r.stdout
    v = read_ply(tmp_path / "c.ply")
    assert np.array_equal(np.c_[v["x"], v["y"], v["z"]], X)
    assert np.array_equal(np.c_[v["red"], v["green"], v["blue"]], want)

    cli("render", tmp_path / "f.obj", "--scalars", tmp_path / "v.csv", "--column", "b",
        "--percentiles", "5,95", "-o", tmp_path / "c.glb")
    data = (tmp_path / "c.glb").read_bytes()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    acc = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"]]
    view = doc["bufferViews"][acc["bufferView"]]
    col = np.frombuffer(data, "u1", 4 * len(X), 28 + jlen + view["byteOffset"]).reshape(-1, 4)
    assert np.array_equal(col[:, :3], want)

    # per-face values into a VTP: cell data as given, point data the vertex means
    fv = rng.normal(size=len(F))
    np.savetxt(tmp_path / "f.csv", fv, header="d", comments="", fmt="%.17g")
    cli("render", tmp_path / "f.obj", "--scalars", tmp_path / "f.csv", "-o", tmp_path / "c.vtp")
    piece = ET.parse(tmp_path / "c.vtp").getroot().find("PolyData/Piece")

    def arr(where, name):
        e = next(d for d in piece.find(where) if d.get("Name") == name)
        return np.array(e.text.split(), float)
    assert np.array_equal(np.array(piece.find("Points/DataArray").text.split(), float)
                          .reshape(-1, 3), X)
    assert np.array_equal(arr("Polys", "connectivity").reshape(-1, 3), F)
    assert np.array_equal(arr("CellData", "d"), fv)
    s, n = np.zeros(len(X)), np.zeros(len(X))
    for k in range(3):
        np.add.at(s, F[:, k], fv)
        np.add.at(n, F[:, k], 1)
    assert np.allclose(arr("PointData", "d"), s / n, rtol=1e-12, atol=1e-15)
    # the colour range is the given values' (the picture's colour bar), not the means'
    assert np.array_equal(arr("PointData", "colors").reshape(-1, 3).astype(np.uint8),
                          es.scalar_colors(s / n, vmin=fv.min(), vmax=fv.max()))
    r = cli("render", tmp_path / "f.obj", tmp_path / "f.obj", "--scalars", tmp_path / "f.csv",
            "-o", tmp_path / "x.ply", check=False)
    assert r.returncode == 2 and "one mesh and one --scalars" in r.stderr
