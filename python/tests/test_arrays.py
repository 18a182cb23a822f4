"""Arrays across the boundary without copies (python/edgespace/_arrays.py):
inputs in the library's layout pass by pointer, other layouts are converted
once, library-allocated results are read-only numpy views of the library's
own memory that keep it alive. Checked by addresses (numpy's data pointer
against the C struct's), not by values alone."""
import gc

import numpy as np
import pytest

import edgespace as es
from edgespace import _arrays as A
from edgespace import ffi


def addr(p):
    return int(ffi.cast("uintptr_t", p))


def test_inputs_in_the_librarys_layout_pass_by_pointer():
    X = np.random.default_rng(3).random((5, 7))
    assert A.f64(X) is X
    assert addr(A.dptr(X)) == X.ctypes.data
    m, keep = A.mat(X)                      # (N, E) C order is the E x N column-major matrix
    assert addr(m[0].data) == X.ctypes.data
    assert (m[0].rows, m[0].cols, m[0].ld) == (7, 5, 7)
    T = A.f64(X.T)                          # a transposed view: converted once, values kept
    assert T is not X.T and T.flags.c_contiguous and np.array_equal(T, X.T)
    I = A.f64(np.arange(6).reshape(2, 3))    # another dtype: converted
    assert I.dtype == np.float64 and np.array_equal(I, [[0, 1, 2], [3, 4, 5]])
    with pytest.raises(ValueError, match=r"want \(\*, 3\)"):
        A.f64(X, (None, 3), "X")


def test_results_are_views_of_the_librarys_memory(ctx):
    X = np.random.default_rng(4).random((12, 30))
    with pytest.raises(ValueError, match="one of auto, gram"):
        es.pca(X, method="exact", ctx=ctx)
    p = es.pca(X, components=3, method="gram", ctx=ctx)
    assert p.components.__array_interface__["data"][0] == addr(p.ptr.components)
    assert p.mean.__array_interface__["data"][0] == addr(p.ptr.mean)
    assert p.scores.shape == (12, 3) and not p.components.flags.writeable
    with pytest.raises(ValueError):
        p.components[0, 0] = 1.0
    # numpy oracle for what the views show: the centred SVD
    U, S, Vt = np.linalg.svd(X - X.mean(axis=0), full_matrices=False)
    assert np.allclose(np.abs(p.components), np.abs(Vt[:3]), rtol=0, atol=1e-12)
    assert np.allclose(p.eigenvalues, S[:3] ** 2 / 11, rtol=1e-12)
    # a view outlives the PCA object: it keeps the es_pca alive
    comps, scores = p.components, p.scores
    want = np.array(comps), np.array(scores)
    del p
    gc.collect()
    _ = [np.ones(30 * 3) for _ in range(100)]   # reuse freed memory, were it freed
    assert np.array_equal(comps, want[0]) and np.array_equal(scores, want[1])


EXIT_SCRIPT = """
import sys
import edgespace as es
s = es.Store(sys.argv[1], ctx=es.Context(progress=None))
KEEP = [s.load_pca("p"), s.get_vector("pca/p/mean"), s.mesh, s]   # alive until exit
try:
    import ipywidgets  # noqa: F401  (imports IPython and ipykernel: another exit order)
except ImportError:
    pass
"""


def test_library_memory_alive_at_exit_is_freed_quietly(store_path, tmp_path):
    """Objects holding library memory when the interpreter exits are freed
    after the module globals are cleared and cffi's library handle is
    closed: that takes es_free bound in advance and a library that stays
    mapped (RTLD_NODELETE); before, the suite's process ended in SIGSEGV
    once the widgets' tests had imported ipywidgets."""
    import os
    import subprocess
    import sys
    with es.Store(store_path, write=True, ctx=es.Context(progress=None)) as s:
        s.pca("p", components=2)
    script = tmp_path / "exit.py"
    script.write_text(EXIT_SCRIPT)
    env = dict(os.environ, MALLOC_PERTURB_="17")
    for _ in range(3):
        r = subprocess.run([sys.executable, str(script), str(store_path)], env=env,
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 0 and "Exception ignored" not in r.stderr, r.stderr
