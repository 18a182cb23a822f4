"""A notebook cell run twice: replace= on the storing calls, delete_result,
embed of an array of lengths, a model's seed.

Oracles: the stored arrays read back by h5py (not through the binding), the
library's own embedding of a file: point (the same mesh written as OBJ:
its ridge-regression weights and prior) against Store.embed of the array, numpy's edge
lengths of the embedded mesh against the target, and a model refitted with
the same seed."""
import os

import h5py
import numpy as np
import pytest

import edgespace as es


def test_a_stored_pca_is_refused_then_replaced(store_path, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as s:
        s.pca("faces", components=3)
        with pytest.raises(es.ExistsError, match=r"replace=True"):
            s.pca("faces", components=2)
        p = s.pca("faces", components=2, replace=True)
        with pytest.raises(es.ExistsError):   # the handle's mode is back
            s.pca("faces", components=4)
        s.mean(by="expression", name="m")
        s.mean(by="expression", where="expression=happy", name="m", replace=True)
    # each result a file beside the store (format 3), laid out as inside one
    with h5py.File(f"{store_path}.results/pca/faces.h5", "r") as f:
        g = f["analysis/pca/faces"]
        assert np.allclose(g["eigenvalues"][:], p.eigenvalues, rtol=0, atol=0)
        assert g["eigenvalues"].shape == (2,)
    with h5py.File(f"{store_path}.results/mean/m.h5", "r") as f:
        assert f["analysis/mean/m/means"].shape[0] == 1   # one group: happy


def test_delete_result_and_what_is_left(store_path, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as s:
        s.pca("a", components=2)
        s.pca("b", components=2)
        s.delete_result("pca/a")
        assert s.results("pca") == ["b"]
        with pytest.raises(es.NotFoundError):
            s.delete_result("pca", "a")
        s.delete_result("pca", "b")
        assert "pca" not in s.results()
    with h5py.File(store_path, "r") as f:
        assert "pca" not in f.get("analysis", {})
    assert not os.path.exists(f"{store_path}.results/pca")   # the kind's folder went too


def test_read_handle_cannot_replace(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        with pytest.raises(es.Error, match="open for reading"):
            s.pca("x", replace=True)


def test_an_array_of_lengths_embeds_as_its_file_would(store_path, tmp_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        # a face that is not a row: halfway between rows 1 and 4
        X = 0.5 * (s.positions(1) + s.positions(4))
        E = s.edges
        raw = np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1)   # numpy, not the library
        obj = tmp_path / "half.obj"
        s.mesh.write(str(obj), X)
        # the library's weights of the same face as a file: point
        pt = s.point_weights(f"file:{obj}")
        assert np.allclose(pt.lengths, raw / raw.sum(), rtol=1e-12)
        ref = es.embed(raw / raw.sum(), s.mesh, scale=raw.sum(), prior=s.prior(pt.weights),
                       ctx=ctx)
        got = s.embed(raw)                      # raw lengths: embedded at their own sum
        size = np.abs(ref.V).max()
        assert np.abs(got.V - ref.V).max() < 1e-11 * size   # numpy's lengths: last bits
        pt_raw = pt.lengths * pt.scale          # the file's own lengths: the same solve
        again = s.embed(pt.lengths, scale=pt.scale)
        assert np.abs(again.V - ref.V).max() < 1e-11 * size   # renormalized: last bits
        assert np.abs(s.embed(pt_raw).V - ref.V).max() < 1e-11 * size
        L = np.linalg.norm(got.V[E[:, 0]] - got.V[E[:, 1]], axis=1)
        assert np.sqrt(np.mean((L - raw) ** 2)) / raw.mean() < 1e-3
        unit = s.embed(raw / raw.sum())         # sum 1: the rows' mean scale
        assert np.isclose(unit.report["scale"], s.scales().mean(), rtol=1e-12)
        bad = raw.copy()
        bad[7] = -1.0
        with pytest.raises(ValueError, match="length 7"):
            s.embed(bad)
        with pytest.raises(ValueError, match="lengths"):
            s.embed(raw[:-1])
        with pytest.raises(ValueError, match="point expression"):
            s.embed(raw, name="x")


def test_a_model_says_its_seed_and_reruns_with_it(store_path, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as s:
        a = s.model("~ expression", permutations=49, seed=7, name="m")
        b = s.model("~ expression", permutations=49, seed=7, name="m", replace=True)
        c = s.model("~ expression", permutations=49)
        assert a.seed == 7 and b.seed == 7 and a.permutations == 49
        assert c.seed == ctx.seed            # the context's, untouched by seed=7
        assert np.array_equal(a.p, b.p) and np.array_equal(a.z, b.z)
        with pytest.raises(ValueError, match="seed"):
            s.model("~ expression", seed=0)
