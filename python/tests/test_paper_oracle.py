"""The published pipeline's stage 1 (es_embed_paper_solve, lib/embed/paper.c)
against the minimizer the paper used: SciPy's fmin_l_bfgs_b with its default
settings, on the same closure energy E(alpha) (eq. 3, es_embed_closure) and
from the same start.

Oracle: scipy.optimize.fmin_l_bfgs_b (Debian python3-scipy). The two
L-BFGS codes differ in their line searches (Moré-Thuente's dcsrch against
bracketing and zooming), so the iterates differ; what must agree is where
they stop: the energies to within SciPy's own stopping tolerance, and
iteration counts of the same size."""
import numpy as np
import pytest

import edgespace as es
from edgespace import ffi, lib

optimize = pytest.importorskip("scipy.optimize")


def closure(mesh, lengths, ctx):
    E = mesh.nedges
    L = np.ascontiguousarray(lengths, dtype=np.float64)
    f = ffi.new("double *")
    g = np.empty(E)

    def fg(alpha):
        a = np.ascontiguousarray(alpha, dtype=np.float64)
        ctx.call(lib.es_embed_closure, mesh.ptr, ffi.from_buffer("double[]", L),
                 ffi.from_buffer("double[]", a), f, ffi.from_buffer("double[]", g), ffi.NULL)
        return f[0], g.copy()
    return fg


def noisy_member(family, sd, seed):
    s = es.synth(family, n=3)
    V = s["vertices"][1]          # the middle member: bent 90 degrees
    mesh = es.Mesh(s["faces"], V)
    E = mesh.edges
    L = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    alpha = mesh.dihedral_angles(V)
    rng = np.random.default_rng(seed)
    alpha = alpha + sd * rng.standard_normal(alpha.shape)
    return mesh, V, L, alpha


@pytest.mark.parametrize("family", ["tube", "tube-closed", "face"])
def test_stage_one_stops_where_scipy_stops(family):
    ctx = es.Context(progress=None)
    mesh, V, L, alpha0 = noisy_member(family, 0.02, 3)
    fg = closure(mesh, L, ctx)
    x, f_scipy, info = optimize.fmin_l_bfgs_b(fg, alpha0.copy())   # SciPy's defaults
    emb = es.Embedder(mesh, ctx=ctx)
    po = ffi.new("es_embed_paper_opts *")
    lib.es_embed_paper_opts_init(po)
    out = np.empty((mesh.nverts, 3))
    rep = ffi.new("es_embed_report *")
    a = np.ascontiguousarray(alpha0)
    ctx.call(lib.es_embed_paper_solve, emb._ptr, ffi.from_buffer("double[]", L), 0.0,
             ffi.from_buffer("double[]", a), ffi.NULL, po, ffi.from_buffer("double[]", out), rep)
    r = rep[0]
    f0 = fg(alpha0)[0]
    print(f"{family}: E {f0:.3g} -> ours {r.closure_stage1:.3g} in {r.dihedral_iters} "
          f"iterations, SciPy {f_scipy:.3g} in {info['nit']} ({info['task']})")
    assert r.closure_before == pytest.approx(f0, rel=1e-12)
    # both stop once an iteration gains < factr * eps = 2.2e-9 (E < 1 here), so
    # both end far below the start and within a few such steps of each other
    assert f_scipy < 1e-5 * f0 and r.closure_stage1 < 1e-5 * f0
    assert abs(r.closure_stage1 - f_scipy) < max(1e-6, 0.5 * f_scipy)
    assert 0.3 < r.dihedral_iters / max(info["nit"], 1) < 3
