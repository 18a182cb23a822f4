"""Stores from Python: ingest files or arrays, read lengths, positions and labels.

Oracles: the command's CSV export (%.17g, so every double reads back to the
same bits) for the lengths and scales, numpy for the edge lengths of
appended arrays (an independent computation), the synthetic positions for
what the store gives back."""
import csv

import numpy as np
import pytest

import edgespace as es


def read_lengths_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head, body = rows[0], rows[1:]
    assert head[:2] == ["id", "scale"]
    ids = [r[0] for r in body]
    scales = np.array([float(r[1]) for r in body])
    L = np.array([[float(x) for x in r[2:]] for r in body])
    return head[2:], ids, scales, L


def test_lengths_and_scales_match_the_cli_csv_bit_for_bit(store_path, tmp_path, cli, ctx):
    out = tmp_path / "lengths.csv"
    cli("export", store_path, "--lengths", out)
    names, ids, scales, L = read_lengths_csv(out)
    with es.Store(store_path, ctx=ctx) as s:
        assert list(s.ids) == ids
        assert np.array_equal(s.lengths(), L)          # bit for bit
        assert np.array_equal(s.scales(), scales)
        assert names == [f"{a}-{b}" for a, b in s.edges]
        # subsets: a range, a list, one row, a strided slice
        assert np.array_equal(s.lengths(slice(3, 7)), L[3:7])
        assert np.array_equal(s.lengths([5, 0, 2]), L[[5, 0, 2]])
        assert np.array_equal(s.lengths(4), L[4:5])
        assert np.array_equal(s.lengths(slice(0, None, 3)), L[::3])


def test_lengths_are_written_into_the_callers_array(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        buf = np.full((s.nrows, s.nedges), np.nan)
        got = s.lengths(out=buf)
        assert got is buf and np.allclose(buf.sum(axis=1), 1, rtol=0, atol=1e-13)
        with pytest.raises(ValueError):
            s.lengths(out=np.empty((s.nedges, s.nrows)))   # the transposed layout


def test_positions_are_what_was_ingested(store_path, faces_dir, ctx):
    syn = es.synth("face", n=6, ctx=es.Context(progress=None))   # same seed, same set
    with es.Store(store_path, ctx=ctx) as s:
        order = [list(s.ids).index(n) for n in syn["names"]]
        P = s.positions()
        assert P.shape == (s.nrows, s.nverts, 3)
        # OBJ with %.17g reads back exactly
        assert np.array_equal(P[order], syn["vertices"])
        assert np.array_equal(s.positions(order[2]), syn["vertices"][2])
        assert np.array_equal(s.faces, syn["faces"])
        m = s.mesh
        assert (m.nverts, m.nfaces, m.nedges) == (s.nverts, s.nfaces, s.nedges)
        assert np.array_equal(m.edges, s.edges)


def test_labels_and_the_table(store_path, faces_dir, ctx):
    with open(faces_dir / "manifest.csv", newline="") as f:
        man = list(csv.DictReader(f))
    with es.Store(store_path, ctx=ctx) as s:
        assert s.columns == ["file", "subject", "expression"]
        t = s.labels()
        assert list(t) == ["id", "file", "subject", "expression"]
        assert list(t["expression"]) == [r["expression"] for r in man]
        assert list(t["subject"]) == [r["subject"] for r in man]
        with pytest.raises(es.NotFoundError):
            s.label("nope")
        rows = s.select("expression=happy")
        assert list(rows) == [i for i, r in enumerate(man) if r["expression"] == "happy"]
        assert s.find_row(t["id"][4]) == 4 and s.find_row("nobody") == -1
        tab = s.table()
        try:
            import pandas as pd
        except ImportError:
            assert isinstance(tab, dict)
        else:
            assert isinstance(tab, pd.DataFrame) and list(tab["subject"]) == list(t["subject"])


def test_a_store_from_arrays(tmp_path, ctx):
    syn = es.synth("face", n=3, ctx=ctx)
    V, F = syn["vertices"], syn["faces"]
    path = tmp_path / "arrays.h5"
    with es.Store.create(path, faces=F, vertices=V[0], ctx=ctx) as s:
        s.append(syn["names"], V, labels=syn["labels"])
    with es.Store(path, ctx=ctx) as s:
        assert s.nrows == len(V) and list(s.ids) == syn["names"]
        for c, vals in syn["labels"].items():
            assert list(s.label(c)) == list(vals)
        # numpy oracle: edge lengths straight from the positions
        E = s.edges
        raw = np.linalg.norm(V[:, E[:, 0]] - V[:, E[:, 1]], axis=2)
        assert np.allclose(s.scales(), raw.sum(axis=1), rtol=1e-14, atol=0)
        assert np.allclose(s.lengths(), raw / raw.sum(axis=1, keepdims=True), rtol=1e-13,
                           atol=0)
        assert np.array_equal(s.positions(), V)


def test_append_is_all_or_nothing(tmp_path, ctx):
    syn = es.synth("face", n=2, ctx=ctx)
    path = tmp_path / "s.h5"
    with es.Store.create(path, faces=syn["faces"], vertices=syn["vertices"][0], ctx=ctx) as s:
        s.append(syn["names"][:2], syn["vertices"][:2])
    with es.Store(path, write=True, ctx=ctx) as s:
        with pytest.raises(es.ExistsError):   # an id that is stored already
            s.append(["new", syn["names"][0]], syn["vertices"][:2])
        assert s.nrows == 2


def test_abort_discards_and_close_publishes(tmp_path, ctx):
    syn = es.synth("face", n=2, ctx=ctx)
    path = tmp_path / "s.h5"
    s = es.Store.create(path, faces=syn["faces"], vertices=syn["vertices"][0], ctx=ctx)
    s.append(syn["names"], syn["vertices"])
    s.abort()
    assert not path.exists()
    s = es.Store.create(path, faces=syn["faces"], vertices=syn["vertices"][0], ctx=ctx)
    s.append(syn["names"], syn["vertices"])
    s.close()
    s.close()   # idempotent
    assert es.Store(path, ctx=ctx).nrows == len(syn["names"])
    with pytest.raises(ValueError, match="closed"):
        s.nrows


def test_a_landmark_store_without_faces(tmp_path, ctx):
    rng = np.random.default_rng(1)
    X = rng.normal(size=(4, 5, 3))
    path = tmp_path / "lm.h5"
    with es.Store.create(path, nverts=5, edges=[[0, 1], [1, 2], [2, 3]], ctx=ctx) as s:
        s.append(["a", "b", "c", "d"], X)
    with es.Store(path, ctx=ctx) as s:
        assert s.topology_kind == "truss" and s.nedges == 3 and s.nfaces == 0
        raw = np.linalg.norm(X[:, [0, 1, 2]] - X[:, [1, 2, 3]], axis=2)
        assert np.allclose(s.lengths(), raw / raw.sum(1, keepdims=True), rtol=1e-13, atol=0)


def test_ingest_files_and_the_report(tmp_path, faces_dir, ctx):
    files = sorted(faces_dir.glob("*.obj"))[:4]
    rep = es.ingest(tmp_path / "f.h5", files=files, ctx=ctx)
    assert rep["rows_added"] == 4 and rep["created"] == 1 and rep["rows_total"] == 4
    assert rep["bytes_read"] == sum(f.stat().st_size for f in files)
    rep = es.ingest(tmp_path / "f.h5", files=files, ctx=ctx)   # a no-op
    assert rep["rows_added"] == 0 and rep["rows_skipped"] == 4
    with es.Store(tmp_path / "f.h5", ctx=ctx) as s:
        assert s.source_path(0).endswith(files[0].name)
        assert s.content_hash(0).startswith("fnv1a64:")


def test_stored_results_read_back(store_path, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as s:
        p = s.pca("faces", components=3)
        assert s.results() == ["pca"] and s.results("pca") == ["faces"]
        assert s.has("pca/faces/components")
        assert np.array_equal(s.get_matrix("pca/faces/components"), p.components)
        assert np.array_equal(s.get_vector("pca/faces/eigenvalues"), p.eigenvalues)
        assert np.array_equal(s.get_ints("pca/faces/rows"), np.arange(s.nrows))
        assert s.get_attr("pca/faces", "ncomp") == "3"
        assert not s.get_matrix("pca/faces/components").flags.writeable
