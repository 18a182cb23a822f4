"""The embedding session from Python (Store.embedder(), es_study_embedder_*):
a point expression, and the same point given as lengths and row weights,
embed to the same bits; the cold session's output is `edgespace embed`'s
(the command's mesh file, %.17g); a row's prior is that row's mesh moved
rigidly (numpy: its edge lengths are the row's)."""
import numpy as np

import edgespace as es

EXPR = "mean + 1.5*pc:1 - 0.5*pc:2"


def test_lengths_and_weights_embed_as_their_expression(store_path, tmp_path, cli, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as s:
        s.pca("p", components=4)
    cli("embed", store_path, "--point", EXPR, "--pca", "p", "-o", tmp_path / "cli.ply",
        "--fast", "--no-store")
    with es.Store(store_path, ctx=ctx) as s:
        se = s.embedder()
        a = se.embed(EXPR, pca="p", warm=False, fast=True)
        pt = s.point_weights(EXPR, pca="p")
        b = se.solve(pt.lengths, pt.scale, pt.weights, warm=False, fast=True)
        assert np.array_equal(a.V, b.V) and a.report["rms_ratio"] == b.report["rms_ratio"]
        assert np.array_equal(a.V, s.mesh.read_positions(tmp_path / "cli.ply"))
        dev = se.vertex_deviation()
        assert dev.shape == (s.nverts,) and np.all(dev >= 0) and dev.max() < 0.05
        # warm: from the last output's correction, to the same accuracy
        c = se.solve(pt.lengths, pt.scale, pt.weights, warm=True, fast=True)
        assert "last output" in c.report["init"] and c.report["rms_ratio"] < 2e-3
        se.forget()
        d = se.solve(pt.lengths, pt.scale, pt.weights, warm=True, fast=True)
        assert np.array_equal(d.V, a.V)


def test_a_rows_prior_is_the_row_moved_rigidly(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        se = s.embedder()
        w = np.zeros(s.nrows)
        w[4] = 1.0
        X = se.prior_positions(w)
        E = s.edges
        got = np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1)
        want = s.lengths(4)[0] * s.scales()[4]
        assert np.allclose(got, want, rtol=1e-9)
