"""Embedding from Python: store points (es_study_embed), arrays of lengths
(es_embed_solve, es_embed_prior_solve), walks (es_study_interp).

Oracles: the command's output meshes (binary PLY: doubles, bit for bit) and
stored reports; numpy edge lengths of the output against the target; the
array route with the store's prior against the store route (the same
library calls, so the same bits); RSS over 1,000 embeddings for leaks."""
import os
import shutil

import h5py
import numpy as np
import pytest

import edgespace as es

EXPR = "mean[expression=neutral] + 0.5*(row:face_s02_happy - row:face_s02_neutral)"


def test_a_store_point_matches_the_command(store_path, tmp_path, cli, ctx):
    cli_store = tmp_path / "cli.h5"
    shutil.copyfile(store_path, cli_store)
    cli("embed", cli_store, "--point", EXPR, "-o", tmp_path / "cli.ply", "--name", "e")
    with es.Store(store_path, write=True, ctx=ctx) as s:
        V, F, rep = s.embed(EXPR, name="e")
        assert np.array_equal(V, s.mesh.read_positions(tmp_path / "cli.ply"))
        assert np.array_equal(F, s.faces)
    # the report is the stored one, field by field (%.17g attributes)
    # each result is its own file beside the store (format 3), laid out as inside one
    with h5py.File(f"{cli_store}.results/embed/e.h5", "r") as f:
        attrs = dict(f["analysis/embed/e"].attrs)
    def text(v):
        return v.decode() if isinstance(v, bytes) else str(v)
    for k in ("rms_ratio", "max_rel", "closure_after", "bend_ratio", "prior_rms", "prior_max"):
        assert rep[k] == float(text(attrs[k])), k
    assert rep["has_prior"] == 1 and rep["init"] == text(attrs["init"])
    assert 0.9 < rep["bend_ratio"] < 1.3 and rep["prior_rms"] < 0.05
    assert rep["rms_ratio"] < 1e-3 and rep["realized"] == 1


def test_an_array_embeds_near_the_stores_prior_as_the_store_does(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        pt = s.point_weights(EXPR)
        prior = s.prior(pt.weights)
        a = es.embed(pt.lengths, s.mesh, scale=pt.scale, prior=prior, ctx=ctx)
        b = s.embed(EXPR)
        assert np.array_equal(a.V, b.V)
        assert a.report["rms_ratio"] == b.report["rms_ratio"]
        # numpy oracle: the output's edge lengths against the target
        E = s.edges
        got = np.linalg.norm(a.V[E[:, 0]] - a.V[E[:, 1]], axis=1)
        target = pt.lengths * pt.scale
        rms = np.sqrt(np.mean((got - target) ** 2)) / target.mean()
        assert np.isclose(rms, a.report["rms_ratio"], rtol=1e-6)
        assert np.isclose(got.sum(), pt.scale, rtol=1e-3)


def test_a_row_from_another_rows_start_without_a_prior(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        L, sc, X = s.lengths(5)[0], s.scales()[5], s.positions(0)
        emb = es.Embedder(s.mesh, ctx=ctx)
        V, F, rep = emb.solve(L, scale=sc, init_vertices=X, refine_max_iter=60)
        assert rep["has_prior"] == 0 and rep["realized"] == 1
        got = np.linalg.norm(V[s.edges[:, 0]] - V[s.edges[:, 1]], axis=1)
        assert np.max(np.abs(got - L * sc) / (L * sc)) < 1e-3   # numpy oracle
        assert np.array_equal(rep["max_rel"] <= 1e-2, True)
        assert emb.vertex_closure().shape == (s.nverts,)
        assert emb.vertex_deviation() is None                       # no prior
        with pytest.raises(TypeError, match="unknown embedding option"):
            emb.solve(L, nonsense=1)
        with pytest.raises(es.InvalidError, match="edge"):         # a length <= 0
            emb.solve(np.where(np.arange(len(L)) == 7, -1.0, L), init_vertices=X)


def test_interpolation_matches_the_command(store_path, tmp_path, cli, ctx):
    cli_store = tmp_path / "cli.h5"
    shutil.copyfile(store_path, cli_store)
    cli("interp", cli_store, "--from", "row:face_s01_neutral", "--to", "row:face_s01_happy",
        "--steps", "3", "-o", tmp_path / "f_%d.ply", "--no-store")
    with es.Store(store_path, ctx=ctx) as s:
        frames = s.interp("row:face_s01_neutral", "row:face_s01_happy", steps=3)
        assert [f.report["heading"].split(" (")[0] for f in frames] == \
            ["t = 0", "t = 0.5", "t = 1"]
        for i, f in enumerate(frames):
            assert np.array_equal(f.V, s.mesh.read_positions(tmp_path / f"f_{i}.ply"))
        # embed of lerp(A, B, t) is the walk's frame t when the walk starts every
        # frame from its own prior (cold); warm, within the solver's tolerance
        mid = s.embed("lerp(row:face_s01_neutral, row:face_s01_happy, 0.5)")
        cold = s.interp("row:face_s01_neutral", "row:face_s01_happy", steps=3, cold=True)
        assert np.array_equal(mid.V, cold[1].V)
        diag = np.linalg.norm(mid.V.max(0) - mid.V.min(0))
        assert np.sqrt(((frames[1].V - mid.V) ** 2).sum(1).mean()) <= 1e-3 * diag


def test_mesh_helpers(tmp_path, ctx):
    syn = es.synth("face", n=1, ctx=ctx)
    X, F = syn["vertices"][0], syn["faces"]
    m = es.Mesh(F, X, ctx=ctx)
    E = m.edges
    assert np.allclose(m.edge_lengths(), np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1),
                       rtol=1e-15, atol=0)
    s = m.summary()
    assert s["n_boundary_loops"] == 4 and s["nedges"] == m.nedges   # eyes, mouth, rim
    assert m.check_lengths(m.edge_lengths())["valid"] == 1
    n, sc = es.normalize_lengths(m.edge_lengths(), ctx=ctx)
    assert np.isclose(n.sum(), 1) and np.isclose(sc, m.edge_lengths().sum())
    m.write(tmp_path / "x.ply")
    r = es.read_mesh(tmp_path / "x.ply", ctx=ctx)
    assert np.array_equal(r.vertices, X) and np.array_equal(r.faces, F)
    alpha = m.dihedral_angles()
    assert alpha.shape == (m.nedges,) and np.all(np.abs(alpha) <= np.pi)
    assert m.length_error(X, m.edge_lengths())[0] == 0


def _rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    pytest.skip("no /proc/self/status")


def test_no_leaks_over_1000_embeddings(ctx):
    """RSS stays flat over 1,000 embeddings on a small mesh (a leak of just
    the output, V x 3 doubles, would add ~2 MB; of the embedder's buffers,
    far more)."""
    syn = es.synth("tube", n=2, resolution=6, ctx=ctx)
    X, F = syn["vertices"], syn["faces"]
    mesh = es.Mesh(F, X[0], ctx=ctx)
    target = mesh.edge_lengths(X[1])
    prior = {"xyz": X[0], "alpha": None, "sd": None}

    def run(n):
        for i in range(n):
            if i % 2:
                es.embed(target, mesh, init_vertices=X[0], ctx=ctx, refine_max_iter=3)
            else:
                es.embed(target, mesh, prior=prior, ctx=ctx, refine_max_iter=3)
    run(100)                         # warm up: allocator pools, caches
    before = _rss_kib()
    run(1000)
    grown = _rss_kib() - before
    assert mesh.nverts * 3 * 8 * 1000 > 2 * 1024 * 1024 * 0.9   # the bound would see one
    assert grown < 1024, f"RSS grew by {grown} KiB over 1,000 embeddings"


def test_sessions_embed_as_the_command_and_keep_their_work(store_path, faces_dir, ctx):
    """Store.embedder() and Store.embed's own session (es_study_embedder):
    cold embeddings equal es_study_embed's whatever came before, warm ones
    stay within the solver's tolerance, the cache file appears beside the
    store, a session made before rows were added refuses, and closing the
    store closes its sessions."""
    pts = ["mean", "mean[expression=happy]", "lerp(row:face_s01_neutral, row:face_s02_angry, 0.4)"]
    with es.Store(store_path, write=True, ctx=ctx) as s:
        cold = [s.embed(p).V for p in pts]
        assert os.path.exists(str(store_path) + ".es-cache")
        again = [s.embed(p).V for p in reversed(pts)][::-1]     # the order does not matter
        for a, b in zip(cold, again):
            assert np.array_equal(a, b)
        se = s.embedder()
        for p, c in zip(pts, cold):
            assert np.array_equal(se.embed(p, warm=False, fast=False).V, c)
        w = s.embed(pts[1], warm=True)        # from the last call's correction
        diag = np.linalg.norm(cold[1].max(0) - cold[1].min(0))
        assert np.sqrt(((w.V - cold[1]) ** 2).sum(1).mean()) <= 1e-3 * diag
        assert "correction" in w.report["init"] or "prior of" in w.report["init"]
        f = se.embed(pts[0], fast=True)
        assert f.report["refine_iters"] == 0 and f.report["lg_iters"] <= 30
        # rows added: the old session refuses, Store.embed makes a new one
        X = s.mesh.read_positions(faces_dir / "face_s01_neutral.obj")[None]
        s.append(["again"], X, labels={"subject": ["s01"], "expression": ["neutral"]})
        with pytest.raises(es.MismatchError, match="rows were added"):
            se.embed("mean")
        assert s.embed("mean").V.shape == cold[0].shape
    with pytest.raises(ValueError, match="closed"):
        se.embed("mean")


@pytest.mark.parametrize("method, extra, cli_extra", [
    ("multiscale", {"seed": 5, "tries": 2}, ["--seed", "5", "--tries", "2"]),
    ("data-driven-el", {"knn": 3, "sigma": 2.0}, ["--knn", "3", "--sigma", "2"]),
])
def test_interp_takes_the_commands_methods(store_path, tmp_path, cli, ctx, method, extra,
                                           cli_extra):
    """Store.interp(method=...) walks as `edgespace interp --method` does with
    the same options: the command's frame files are the oracle, frame by
    frame (written by the same library; each run alone)."""
    a, b = "row:face_s01_neutral", "row:face_s01_happy"
    pat = str(tmp_path / "c_%02d.obj")
    cli("interp", store_path, "--from", a, "--to", b, "--steps", "3", "--method", method,
        *cli_extra, "-o", pat, "--no-store")
    with es.Store(store_path, ctx=ctx) as s:
        frames = s.interp(a, b, steps=3, method=method, **extra)
        assert len(frames) == 3
        for i, f in enumerate(frames):
            V = s.mesh.read_positions(tmp_path / f"c_{i:02d}.obj")
            assert np.allclose(f.V, V, rtol=0, atol=1e-6 * np.ptp(V)), (method, i)


def test_interp_refuses_a_method_it_does_not_know(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        with pytest.raises(es.Error, match="nope"):
            s.interp("row:face_s01_neutral", "row:face_s01_happy", steps=3, method="nope")
        with pytest.raises(ValueError, match="knn"):
            s.interp("row:face_s01_neutral", "row:face_s01_happy", steps=3,
                     method="data-driven", knn=0)
