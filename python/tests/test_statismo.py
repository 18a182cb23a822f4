"""Statismo export against its description (datasets-spec/statismo.md), read
with h5py: every group, dataset, type, shape and attribute the readers
(statismo's StatismoIO, scalismo's StatismoIO/jhdf) need; the Procrustes
model against the GPA it comes from; the edge-length model against
embeddings made here (numpy: the linearization D D^T == U diag(var) U^T)."""
import shutil

import h5py
import numpy as np
import pytest

import edgespace as es


def s(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def check_layout(path, V, F, K):
    """The format description, item by item."""
    with h5py.File(path, "r") as f:
        assert f["version/majorVersion"].shape == () and f["version/majorVersion"][()] == 0
        assert f["version/minorVersion"][()] == 9
        assert f["version/majorVersion"].dtype == np.int32
        rep = f["representer"]
        assert {k: s(v) for k, v in rep.attrs.items()} == {
            "name": "itkStandardMeshRepresenter", "version": "1.0",
            "datasetType": "POLYGON_MESH"}
        for k in rep.attrs:   # fixed-length, NUL-terminated (statismo's writeStringAttribute)
            t = rep.attrs.get_id(k).get_type()
            assert not t.is_variable_str() and t.get_size() == len(s(rep.attrs[k])) + 1
        assert rep["points"].shape == (3, V) and rep["points"].dtype == np.float32
        assert rep["cells"].shape == (3, F) and rep["cells"].dtype == np.int32
        assert "pointData" in rep and "cellData" in rep
        m = f["model"]
        assert m["mean"].shape == (3 * V,) and m["mean"].dtype == np.float32
        assert m["pcaBasis"].shape == (3 * V, K) and m["pcaBasis"].dtype == np.float32
        assert m["pcaVariance"].shape == (K,) and m["pcaVariance"].dtype == np.float32
        assert m["noiseVariance"].shape == () and m["noiseVariance"].dtype == np.float32
        info = f["modelinfo"]
        assert info["scores"].dtype == np.float32 and info["scores"].shape[0] in (K, 1)
        b = info["modelBuilder-0"]
        assert s(b["builderName"][()]) == "edgespace export --statismo"
        assert set(b["parameters"]) == {"method", "source", "store", "sd_step", "command"}
        assert "dataInfo" in b and "build-time" in info
        U = m["pcaBasis"][()].astype(np.float64)
        assert np.allclose(U.T @ U, np.eye(K), atol=1e-5)   # orthonormal (float32)
        assert np.all(np.diff(m["pcaVariance"][()]) <= 0)
        # the representer's points are the mean, vertex-interleaved
        assert np.array_equal(rep["points"][()].T.reshape(-1), m["mean"][()])
        return {k: f["model/" + k][()] for k in ("mean", "pcaBasis", "pcaVariance",
                                                 "noiseVariance")} | {
            "scores": info["scores"][()], "cells": rep["cells"][()],
            "params": {k: s(v[()]) for k, v in b["parameters"].items()}}


def test_procrustes_model(store_path, tmp_path, cli, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as st:
        g = st.gpa("g")
        rep = st.export_statismo(tmp_path / "g.h5", gpa="g")
        V, F, faces = st.nverts, st.nfaces, st.faces
    K = len(g.pc_sdev)
    assert rep["ncomp"] == K and rep["source"] == "gpa/g"
    m = check_layout(tmp_path / "g.h5", V, F, K)
    assert np.array_equal(m["cells"].T, faces)
    # the GPA's own numbers, in single precision
    assert np.array_equal(m["mean"], g.mean.reshape(-1).astype(np.float32))
    assert np.array_equal(m["pcaVariance"], (g.pc_sdev ** 2).astype(np.float32))
    for k in range(K):
        assert np.array_equal(m["pcaBasis"][:, k], g.pc_loadings[k].reshape(-1).astype(np.float32))
    assert np.array_equal(m["scores"], (g.pc_scores / g.pc_sdev).T.astype(np.float32))
    total = g.pc_sdev[0] ** 2 * 100 / g.pc_percent[0]
    noise = (total - (g.pc_sdev ** 2).sum()) / (3 * V - K)
    assert np.isclose(m["noiseVariance"], noise, rtol=1e-6) and rep["noise_variance"] > 0
    assert m["params"]["source"] == "gpa/g"
    # the command writes the same model (up to its build time and command line)
    cli("export", store_path, "--statismo", tmp_path / "g_cli.h5", "--gpa", "g")
    c = check_layout(tmp_path / "g_cli.h5", V, F, K)
    for k in ("mean", "pcaBasis", "pcaVariance", "noiseVariance", "scores"):
        assert np.array_equal(c[k], m[k])


def test_edge_length_model_is_the_linearized_embeddings(store_path, tmp_path, ctx):
    K = 3
    with es.Store(store_path, write=True, ctx=ctx) as st:
        p = st.pca("faces", components=5)
        rep = st.export_statismo(tmp_path / "p.h5", pca="faces", components=K)
        # the same embeddings made here (es_study_embed)
        X0 = st.embed("mean", pca="faces").V
        D = np.stack([(st.embed(f"mean + 1*pc:{k}", pca="faces").V -
                       st.embed(f"mean + -1*pc:{k}", pca="faces").V).reshape(-1) / 2
                      for k in range(1, K + 1)], axis=1)
        V, F = st.nverts, st.nfaces
    assert rep["ncomp"] == K and rep["source"] == "pca/faces"
    assert rep["worst_rms_ratio"] < 1e-3 and 0 <= rep["nonlinearity"] < 1
    m = check_layout(tmp_path / "p.h5", V, F, K)
    assert np.array_equal(m["mean"], X0.reshape(-1).astype(np.float32))
    U, var = m["pcaBasis"].astype(np.float64), m["pcaVariance"].astype(np.float64)
    # numpy oracle: the model's covariance is the linearization's, D D^T
    C_model = U @ np.diag(var) @ U.T
    C_lin = D @ D.T
    assert np.allclose(C_model, C_lin, rtol=0, atol=1e-5 * np.abs(C_lin).max())
    sv = np.linalg.svd(D, compute_uv=False)
    assert np.allclose(np.sort(var)[::-1], sv ** 2, rtol=1e-5)
    assert m["noiseVariance"] == 0 and m["params"]["sd_step"] == "1"
    # scores: each row's PC coefficients in sd units, rotated like the modes
    alpha = p.scores[:, :K] / np.sqrt(p.eigenvalues[:K])
    W = (U.T @ D) / np.sqrt(var)[:, None]               # K modes x K PCs
    assert np.allclose(m["scores"], W @ alpha.T, rtol=0, atol=1e-4 * np.abs(alpha).max())


def test_export_takes_the_embedding_options(store_path, tmp_path, cli, ctx):
    """--fast (and the other embedding options) reach the model's embeddings:
    its mean is `edgespace embed --point mean --fast`'s mesh (the oracle: the
    embed command's OBJ, read back), and they go with --statismo of a PCA only."""
    with es.Store(store_path, write=True, ctx=ctx) as st:
        st.pca("faces", components=3)
        mesh = st.mesh
    cli("export", store_path, "--statismo", tmp_path / "fast.h5", "--pca", "faces", "-k", "2",
        "--fast")
    cli("embed", store_path, "--point", "mean", "--pca", "faces", "--fast", "--no-store", "-o",
        tmp_path / "mean.obj")
    X = mesh.read_positions(tmp_path / "mean.obj")
    with h5py.File(tmp_path / "fast.h5", "r") as f:
        mean = f["model/mean"][:]
    assert np.allclose(mean, X.reshape(-1).astype(np.float32), rtol=0, atol=1e-6 * np.abs(X).max())
    r = cli("export", store_path, "--meshes", tmp_path / "m", "--fast", check=False)
    assert r.returncode == 2 and "go with --statismo of a PCA" in r.stderr


def test_export_errors(store_path, tmp_path, cli, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as st:
        st.pca("faces", components=3)
        with pytest.raises(es.NotFoundError, match="no PCA named 'nope'"):
            st.export_statismo(tmp_path / "x.h5", pca="nope")
        with pytest.raises(es.NotFoundError, match="no GPA result 'nope'"):
            st.export_statismo(tmp_path / "x.h5", gpa="nope")
        with pytest.raises(es.InvalidError, match="not both"):
            st.export_statismo(tmp_path / "x.h5", pca="faces", gpa="g")
        with pytest.raises(es.InvalidError, match="4 modes asked"):
            st.export_statismo(tmp_path / "x.h5", pca="faces", components=4)
        with pytest.raises(es.InvalidError, match="sd"):
            st.export_statismo(tmp_path / "x.h5", pca="faces", sd=0)
        # never over a store; over an earlier model, yes
        other = tmp_path / "other.h5"
        shutil.copyfile(store_path, other)
        with pytest.raises(es.ExistsError, match="not a statismo model"):
            st.export_statismo(other, pca="faces", components=1)
        with pytest.raises(es.ExistsError, match="refusing to overwrite the store"):
            st.export_statismo(store_path, pca="faces", components=1)
        st.export_statismo(tmp_path / "m.h5", pca="faces", components=1)
        st.export_statismo(tmp_path / "m.h5", pca="faces", components=2)
    with h5py.File(tmp_path / "m.h5", "r") as f:
        assert f["model/pcaBasis"].shape[1] == 2
    assert not list(tmp_path.glob("*.part"))
    r = cli("export", store_path, "--statismo", tmp_path / "y.h5", "--gpa", "g", check=False)
    assert r.returncode == 1 and "no GPA result 'g'" in r.stderr
    r = cli("export", store_path, "--statismo", tmp_path / "y.h5", "--lengths", "x.csv",
            check=False)
    assert r.returncode == 2
