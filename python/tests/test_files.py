"""Files from Python and the smaller helpers: the lengths CSV and the mesh
files the command exports (byte for byte the command's, from the same
library calls), a mesh and a picture written from an embedding, the nearest
stored row, the embedder's per-vertex edge error, and the label table
without pandas.

Oracles: the command's files (`edgespace export`), numpy (nearest row in
Euclidean edge-length distance, per-vertex mean relative edge error), the
bytes the binding returned (written pictures and meshes read back)."""
import sys

import numpy as np
import pytest

import edgespace as es


def test_lengths_csv_is_the_commands(store_path, tmp_path, cli, ctx):
    cli("export", store_path, "--lengths", tmp_path / "cli.csv")
    cli("export", store_path, "--lengths", tmp_path / "cli_raw.csv", "--raw",
        "--where", "expression=happy")
    with es.Store(store_path, ctx=ctx) as s:
        s.export_lengths_csv(tmp_path / "py.csv")
        s.export_lengths_csv(tmp_path / "py_raw.csv", rows=s.select("expression=happy"), raw=True)
        happy = len(s.select("expression=happy"))
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    raw = (tmp_path / "py_raw.csv").read_bytes()
    assert raw == (tmp_path / "cli_raw.csv").read_bytes()
    assert raw.count(b"\n") == 1 + happy == 7


def test_meshes_are_the_commands(store_path, tmp_path, cli, ctx):
    cli("export", store_path, "--meshes", tmp_path / "cli", "--format", "ply",
        "--where", "subject=s02")
    with es.Store(store_path, ctx=ctx) as s:
        rows = s.select("subject=s02")
        s.export_meshes(tmp_path / "py", rows=rows, format="ply")
        ids = [s.ids[r] for r in rows]
        P = s.positions(rows)
        mesh = s.mesh
    got = sorted(p.name for p in (tmp_path / "py").iterdir())
    assert got == sorted(f"{i}.ply" for i in ids) == \
        sorted(p.name for p in (tmp_path / "cli").iterdir())
    for i, p in zip(ids, P):
        f = tmp_path / "py" / f"{i}.ply"
        assert f.read_bytes() == (tmp_path / "cli" / f"{i}.ply").read_bytes()
        assert np.array_equal(mesh.read_positions(f), p)   # binary PLY: the same doubles
    with es.Store(store_path, ctx=ctx) as s, pytest.raises(AttributeError):
        s.export_meshes(tmp_path / "x", format="vtk")         # no such format
    # STL for printers: one binary file per row (test_stl_glb.py reads them)
    with es.Store(store_path, ctx=ctx) as s:
        s.export_meshes(tmp_path / "stl", rows=rows, format="stl")
    assert sorted(p.name for p in (tmp_path / "stl").iterdir()) == sorted(f"{i}.stl" for i in ids)


def test_the_nearest_row_is_numpys(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        L = s.lengths()
        target = 0.7 * L[4] + 0.3 * L[11]
        d = np.linalg.norm(L - target, axis=1)
        row, dist = s.nearest_row(target)
        assert row == int(np.argmin(d)) == 4
        assert np.isclose(dist, d[4], rtol=1e-12, atol=0)
        sub = [15, 11, 0, 9]                               # a row, not a position in sub
        want = sub[int(np.argmin(d[sub]))]
        row, dist = s.nearest_row(target, rows=sub)
        assert row == want != 4 and np.isclose(dist, d[want], rtol=1e-12, atol=0)
        with pytest.raises(ValueError):
            s.nearest_row(target[:-1])                     # the wrong length


def test_an_embedding_writes_its_mesh_and_picture(store_path, tmp_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        emb = s.embed("row:face_s03_angry")
        mesh = s.mesh
    emb.write(tmp_path / "e.ply", ctx=ctx)
    assert np.array_equal(mesh.read_positions(tmp_path / "e.ply"), emb.V)
    back = es.read_mesh(tmp_path / "e.ply", ctx=ctx)
    assert np.array_equal(back.faces, emb.F)
    if not es.has_figures():
        pytest.skip("library built without figures")
    img = emb.render(width=200, height=150)
    img.save(tmp_path / "e.png")
    assert (tmp_path / "e.png").read_bytes() == bytes(img)
    assert bytes(img)[:8] == b"\x89PNG\r\n\x1a\n"


def test_vertex_edge_error_is_the_mean_relative_error_around_each_vertex(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        L, sc, X, E = s.lengths(7)[0], s.scales()[7], s.positions(1), s.edges
        emb = es.Embedder(s.mesh, ctx=ctx)
        assert emb.vertex_edge_error() is None                      # before a solve
        V, _, rep = emb.solve(L, scale=sc, init_vertices=X, refine_max_iter=5)
        got = emb.vertex_edge_error()
    # numpy oracle
    target = L * sc
    rel = np.abs(np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1) - target) / target
    tot = np.bincount(E[:, 0], rel, len(V)) + np.bincount(E[:, 1], rel, len(V))
    deg = np.bincount(E[:, 0], minlength=len(V)) + np.bincount(E[:, 1], minlength=len(V))
    want = tot / np.maximum(deg, 1)
    assert got.shape == (len(V),) and rel.max() > 0
    # |l - L| / L cancels: each side carries ~1e-16 absolute of rounding
    assert np.allclose(got, want, rtol=1e-6, atol=1e-13)
    assert np.isclose(rel.max(), rep["max_rel"], rtol=1e-9)


def test_the_table_is_a_dict_without_pandas(store_path, ctx, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)   # `import pandas` raises ImportError
    with es.Store(store_path, ctx=ctx) as s:
        t = s.table()
        assert isinstance(t, dict) and list(t) == ["id", "file", "subject", "expression"]
        assert list(t["id"]) == list(s.ids)


def test_a_store_without_faces_needs_its_vertex_count(tmp_path, ctx):
    with pytest.raises(ValueError, match="nverts"):
        es.Store.create(tmp_path / "x.h5", ctx=ctx)
    assert not (tmp_path / "x.h5").exists()
