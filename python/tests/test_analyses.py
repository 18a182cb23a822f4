"""Analyses on a store from Python against the command's CSV outputs, bit for
bit (the command writes %.17g; both call the same es_study_* function on
copies of one store), and against numpy as an independent oracle."""
import csv
import shutil

import h5py
import numpy as np
import pytest

import edgespace as es


def table(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def columns(path, first):
    """Numeric columns first.. of a CSV as an array (rows x cols) and the header."""
    head, body = table(path)
    return head, np.array([[float(x) for x in r[first:]] for r in body])


@pytest.fixture
def cli_copy(store_path, tmp_path):
    p = tmp_path / "cli.h5"
    shutil.copyfile(store_path, p)
    return p


def test_mean_by_group(store_path, cli_copy, tmp_path, cli, ctx):
    cli("mean", cli_copy, "--by", "expression", "--output", tmp_path / "m.csv")
    head, M = columns(tmp_path / "m.csv", 3)
    with es.Store(store_path, write=True, ctx=ctx) as s:
        r = s.mean(by="expression", name="expression")
        assert head[3:] == r.groups == ["neutral", "happy", "angry"]
        assert np.array_equal(r.means, M.T)                       # bit for bit
        L, expr = s.lengths(), s.label("expression")
        for g, name in enumerate(r.groups):                        # numpy oracle
            assert np.allclose(r.means[g], L[expr == name].mean(axis=0), rtol=1e-13, atol=0)
            assert r.counts[g] == (expr == name).sum()
            assert np.isclose(r.scales[g], s.scales()[expr == name].mean(), rtol=1e-14)
        assert s.results("mean") == ["expression"]


def test_pca(store_path, cli_copy, tmp_path, cli, ctx):
    cli("pca", cli_copy, "--name", "p", "--components", "4", "--output", tmp_path / "p")
    _, comp = columns(tmp_path / "p_components.csv", 3)
    _, eig = columns(tmp_path / "p_eigenvalues.csv", 1)
    head, body = table(tmp_path / "p_scores.csv")
    with es.Store(store_path, write=True, ctx=ctx) as s:
        p = s.pca("p", components=4)
        assert np.array_equal(p.mean, comp[:, 0])
        assert np.array_equal(p.components, comp[:, 1:].T)
        assert np.array_equal(p.eigenvalues, eig[:, 0])
        assert np.array_equal(p.explained, eig[:, 1])
        assert np.array_equal(p.scores, np.array([[float(x) for x in r[-4:]] for r in body]))
        assert [r[0] for r in body] == list(s.ids[p.rows])
        # numpy oracle: the SVD of the centred lengths
        L = s.lengths()
        Y = L - L.mean(axis=0)
        U, sv, Vt = np.linalg.svd(Y, full_matrices=False)
        lam = sv ** 2 / (len(L) - 1)
        assert np.allclose(p.eigenvalues, lam[:4], rtol=1e-9, atol=0)
        assert np.isclose(p.total_variance, lam.sum(), rtol=1e-10)
        for k in range(4):   # unit components, up to sign
            assert np.isclose(abs(p.components[k] @ Vt[k]), 1, atol=1e-8)
        # the same PCA on the array (es_pca_fit on the matrix, no store)
        q = es.pca(L, components=4, ctx=ctx)
        assert np.allclose(q.eigenvalues, p.eigenvalues, rtol=1e-12, atol=0)
        # load it back; project rows onto it
        r = s.load_pca("p")
        assert np.array_equal(r.components, p.components) and r.method == p.method
        sc, res = p.project(L[:3])
        assert np.allclose(sc, p.scores[:3], rtol=1e-9, atol=1e-15)
        # row weights (ridge 0) rebuild the row's part in the kept components
        w = p.row_weights(L[2], ridge_rel=0)
        x = p.mean + p.components.T @ (p.components @ (L[2] - p.mean))
        assert np.isclose(w.sum(), 1, rtol=0, atol=1e-12)
        assert np.allclose(w @ L, x, rtol=1e-8, atol=1e-13)


def test_paired_difference(store_path, cli_copy, tmp_path, cli, ctx):
    cli("diff", cli_copy, "--pair-by", "subject", "--from", "neutral", "--to", "happy",
        "--name", "smile", "--output", tmp_path / "d.csv")
    _, D = columns(tmp_path / "d.csv", 3)
    with es.Store(store_path, write=True, ctx=ctx) as s:
        d = s.diff("smile", pair_by="subject", column="expression", from_="neutral", to="happy")
        for j, f in enumerate(("mean", "sd", "se", "t")):
            assert np.array_equal(getattr(d, f), D[:, j])
        L = s.lengths()
        delta = L[d.pair_to] - L[d.pair_from]                     # numpy oracle
        assert np.allclose(d.mean, delta.mean(0), rtol=1e-12, atol=1e-18)
        assert np.allclose(d.sd, delta.std(0, ddof=1), rtol=1e-9, atol=1e-18)
        subj = s.label("subject")
        assert all(subj[a] == subj[b] for a, b in zip(d.pair_from, d.pair_to))
        assert d.npairs == 6 and len(d.unpaired) == 0


def test_points_with_their_row_weights(store_path, cli_copy, tmp_path, cli, ctx):
    expr = "mean[expression=neutral] + 0.5*(row:face_s02_happy - row:face_s02_neutral)"
    cli("point", cli_copy, expr, "--output", tmp_path / "pt.csv")
    _, P = columns(tmp_path / "pt.csv", 3)
    with es.Store(store_path, write=True, ctx=ctx) as s:
        pt = s.point(expr, name="half_smile")
        assert np.array_equal(pt.lengths, P[:, 0])
        L, ids = s.lengths(), list(s.ids)
        assert np.allclose(pt.weights @ L, pt.lengths, rtol=1e-12, atol=1e-17)
        neutral = s.label("expression") == "neutral"
        w = np.where(neutral, 1 / neutral.sum(), 0.0)
        w[ids.index("face_s02_happy")] += 0.5
        w[ids.index("face_s02_neutral")] -= 0.5
        assert np.allclose(pt.weights, w, rtol=1e-15, atol=1e-15)
        assert pt.info["validity"]["valid"] == 1 and pt.info["nshapes"] == 3
        # a stored point reads back by name, with its weights
        pw = s.point_weights("half_smile")
        assert np.array_equal(pw.lengths, pt.lengths) and np.array_equal(pw.weights, pt.weights)
        assert pw.scale == pt.scale


def test_projection(store_path, cli_copy, tmp_path, cli, ctx):
    cli("pca", cli_copy, "--name", "p", "--components", "3")
    cli("project", cli_copy, "--pca", "p", "--where", "expression=angry", "--output",
        tmp_path / "pr.csv", "face_s01_neutral")
    head, body = table(tmp_path / "pr.csv")
    with es.Store(store_path, write=True, ctx=ctx) as s:
        s.pca("p", components=3)
        r = s.project(["face_s01_neutral"], where="expression=angry", pca="p")
        assert r["names"] == [b[0] for b in body]
        assert np.array_equal(r["scores"], np.array([[float(x) for x in b[1:4]] for b in body]))
        assert np.array_equal(r["residuals"], np.array([float(b[4]) for b in body]))


def test_gpa_and_compare(store_path, cli_copy, tmp_path, cli, ctx):
    cli("gpa", cli_copy, "--name", "g", "-q")
    cli("compare", cli_copy, "--gpa", "g", "--by", "expression", "--permutations", "99",
        "--no-figures", "-o", tmp_path / "cmp", "-q")
    with es.Store(store_path, write=True, ctx=ctx) as s:
        g = s.gpa("g")
        n, k = s.nrows, s.nverts
        assert g.aligned.shape == (n, k, 3) and g.pc_loadings.shape[1:] == (k, 3)
        assert g.report["converged"] == 1
        # the aligned configurations are the rows rigidly moved and scaled
        X = s.positions()
        for j in (0, n - 1):
            Xc = (X[j] - X[j].mean(0)) @ g.rotation[j] * g.scale[j]
            assert np.allclose(Xc, g.aligned[j], rtol=0, atol=1e-10 * np.abs(Xc).max())
        assert np.allclose(g.mean, g.aligned.mean(0), rtol=0, atol=1e-12)
        c = s.compare("g", by="expression", permutations=99, name="g")
    # the binding's GPA is the command's, dataset by dataset
    # each result is its own file beside the store (format 3), laid out as inside one
    with h5py.File(f"{store_path}.results/gpa/g.h5", "r") as a, \
            h5py.File(f"{cli_copy}.results/gpa/g.h5", "r") as b:
        for ds in ("aligned", "mean", "pc_sdev", "pc_scores", "pc_loadings", "rotation"):
            assert np.array_equal(a["analysis/gpa/g/" + ds][()], b["analysis/gpa/g/" + ds][()])
    _, DL = columns(tmp_path / "cmp" / "distances_lengths.csv", 1)
    _, DP = columns(tmp_path / "cmp" / "distances_procrustes.csv", 1)
    assert np.array_equal(c.d_len, DL) and np.array_equal(c.d_proc, DP)
    summary = dict(table(tmp_path / "cmp" / "summary.csv")[1])
    assert c.mantel_rho == float(summary["spearman_rho"])
    assert c.mantel_p == float(summary["mantel_p"])            # same seed, same p
    assert c.nn_agreement == float(summary["nn_agreement"])
    # numpy oracle: Euclidean distances of the normalized lengths
    with es.Store(store_path, ctx=ctx) as s:
        L = s.lengths()
    ref = np.sqrt(((L[:, None, :] - L[None, :, :]) ** 2).sum(-1))
    assert np.allclose(c.d_len, ref, rtol=1e-7, atol=1e-12)
    assert c.group_names == ["neutral", "happy", "angry"] and c.mean_len.shape == (3, 3)


def test_model(store_path, cli_copy, tmp_path, cli, ctx):
    """Store.model against `edgespace model`'s ANOVA CSV bit for bit, and
    numpy: the balanced expression SS, SS + RSS = TSS, and coefficients
    rebuilt from their row weights."""
    cli("model", cli_copy, "~ expression + subject", "--block", "subject", "--permutations", "99",
        "--name", "m", "--output", tmp_path / "anova.csv")
    head, body = table(tmp_path / "anova.csv")
    with es.Store(store_path, write=True, ctx=ctx) as s:
        m = s.model("~ expression + subject", block="subject", permutations=99, name="m")
        assert m.terms == [r[0] for r in body[:len(m.terms)]] == ["expression", "subject"]
        for j in range(len(m.terms)):
            row = body[j]
            assert int(row[1]) == m.df[j]
            for col, v in zip(row[2:6], (m.ss[j], m.ms[j], m.r2[j], m.f[j])):
                assert float(col) == v                              # bit for bit
        assert float(body[0][7]) == m.p[0] and np.isnan(m.p[1])    # the block: untestable
        L, expr = s.lengths(), s.label("expression")
        grand = L.mean(axis=0)
        ss = sum((expr == g).sum() * ((L[expr == g].mean(axis=0) - grand) ** 2).sum()
                 for g in np.unique(expr))
        assert np.isclose(m.ss[0], ss, rtol=1e-10, atol=0)          # numpy oracle
        assert np.isclose(m.ss.sum() + m.rss, m.tss, rtol=1e-12)
        assert np.isclose(m.tss, ((L - grand) ** 2).sum(), rtol=1e-12)
        ok = ~np.isnan(m.coef[:, 0])
        assert np.allclose(m.coef_weights[ok] @ L[m.rows], m.coef[ok], rtol=0,
                           atol=1e-10 * np.abs(L).max())
        assert m.coef_names[0] == "intercept" and "expression=neutral" in m.coef_names
        assert s.results("model") == ["m"]
        with pytest.raises(es.Error, match="no label column 'mood'"):
            s.model("~ mood", permutations=0)
        with pytest.raises(ValueError):
            s.model("~ expression", permute="shuffle")


def test_model_nested(store_path, ctx):
    """A nested formula is a string like any other: ~ expression/log(size)
    (a size slope within each expression) has R's terms, expression and
    expression:log(size), and the nested term's type I SS is the drop in
    the residual sum of squares from one slope to three, fitted here by
    numpy's least squares on the same lengths and scales."""
    with es.Store(store_path, write=True, ctx=ctx) as s:
        m = s.model("~ expression/log(size)", permutations=19, errors={
            "expression": "log(size):expression"})
        assert m.terms == ["expression", "expression:log(size)"]
        assert m.df.tolist() == [2, 3] and m.error == ["expression:log(size)", "Residual"]
        L, expr = s.lengths()[m.rows], s.label("expression")[m.rows]
        x = np.log(s.scales()[m.rows])
        groups = [expr == g for g in np.unique(expr)]
        within = np.column_stack(groups + [g * x for g in groups]).astype(float)
        common = np.column_stack(groups).astype(float)

        def rss(X):
            return ((L - X @ np.linalg.lstsq(X, L, rcond=None)[0]) ** 2).sum()

        assert np.isclose(m.ss[1], rss(common) - rss(within), rtol=1e-8, atol=0)   # numpy
        assert np.isclose(m.rss, rss(within), rtol=1e-8)
        assert np.isclose(m.f[0], m.ms[0] / m.ms[1], rtol=1e-12)
        with pytest.raises(es.Error, match="column 14: expected a term after the '/' at column 13"):
            s.model("~ expression/", permutations=0)


def test_model_pairwise_z(store_path, cli_copy, tmp_path, cli, ctx):
    """Z and the pairwise table as `edgespace model -o` writes them, bit for
    bit; the LS means from their row weights (numpy); the summary; the
    aliased copy left out with a warning; the comparison with a null model."""
    cli("model", cli_copy, "~ expression + subject", "--block", "subject", "--permutations", "49",
        "--pairwise", "expression", "--reference", "neutral", "--no-store",
        "--output", tmp_path / "a.csv")
    head, body = table(tmp_path / "a.csv")
    phead, pbody = table(tmp_path / "a.pairwise.csv")
    with es.Store(store_path, write=True, ctx=ctx) as s:
        m = s.model("~ expression + subject", block="subject", permutations=49,
                    pairwise="expression", reference="neutral")
        assert head[6] == "z" and float(body[0][6]) == m.z[0] and np.isnan(m.z[1])
        assert m.error == ["Residual", "Residual"] and m.dropped == {}
        assert m.coef_names[1].startswith("expression=") and "neutral" not in m.coef_names[1]
        pw = m.pairwise
        assert phead == ["level_a", "level_b", "d", "ucl", "z", "p"] and not pw.slopes
        t = pw.table()
        for row, (a, b) in zip(pbody, [(0, 1), (0, 2), (1, 2)]):
            assert row[:2] == [pw.levels[a], pw.levels[b]]
            assert [float(v) for v in row[2:]] == [pw.d[a, b], pw.ucl[a, b], pw.z[a, b],
                                                   pw.p[a, b]]
        assert len(t["d"]) == 3
        L = s.lengths()[m.rows]
        assert np.allclose(pw.weights @ L, pw.lsmeans, rtol=0, atol=1e-12)   # numpy
        assert np.isclose(pw.d[0, 1], np.linalg.norm(pw.lsmeans[0] - pw.lsmeans[1]), rtol=1e-10)
        assert "pairwise distances of LS means" in m.summary and "expression" in m.summary
        with pytest.warns(es.EdgespaceWarning, match="'factor.expression.' duplicates"):
            c = s.model("~ expression + factor(expression)", permutations=0)
        assert c.terms == ["expression"] and c.dropped == {
            "factor(expression)": "duplicates 'expression'"}
        n = s.model("~ expression + subject", permutations=19, null="~ subject")
        assert n.comparison["df"] == 2 and n.comparison["f"] > 1
