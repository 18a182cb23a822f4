"""Errors, warnings, progress and the seed: the library's context from Python.

Every es_status maps to its exception class (also a builtin of the same
kind) carrying the library's own message (es_ctx_errmsg), checked on real
failing calls; callbacks reach Python and an exception raised in one comes
out of the call that ran it; the seed makes synthetic data reproducible."""
import sys
import threading
import types
import warnings

import numpy as np
import pytest

import edgespace as es
from edgespace._errors import check, error_class

KINDS = [("ES_ENOMEM", es.NoMemoryError, MemoryError), ("ES_EINVAL", es.InvalidError, ValueError),
         ("ES_ERANGE", es.RangeError, OverflowError), ("ES_EIO", es.IOFailure, OSError),
         ("ES_EFORMAT", es.FormatError, ValueError),
         ("ES_ENUMERIC", es.NumericError, ArithmeticError),
         ("ES_ENOCONV", es.ConvergenceError, ArithmeticError),
         ("ES_ENOTFOUND", es.NotFoundError, LookupError), ("ES_EEXIST", es.ExistsError, None),
         ("ES_EMISMATCH", es.MismatchError, ValueError),
         ("ES_ETOPOLOGY", es.TopologyError, ValueError)]


@pytest.mark.parametrize("name,cls,builtin", KINDS)
def test_every_status_has_its_class(name, cls, builtin, ctx):
    code = getattr(es.lib, name)
    assert error_class(code) is cls and issubclass(cls, es.Error)
    if builtin:
        assert issubclass(cls, builtin)
    es.lib.es_ctx_clear_error(ctx.ptr)   # no message: es_strerror's text
    with pytest.raises(cls) as e:
        check(ctx.ptr, code)
    assert e.value.status == code and e.value.code == name
    assert str(e.value) == es.ffi.string(es.lib.es_strerror(code)).decode()


def test_missing_store_is_not_found_naming_the_file(tmp_path, ctx):
    with pytest.raises(es.NotFoundError) as e:
        es.Store(tmp_path / "nope.h5", ctx=ctx)
    assert "nope.h5" in str(e.value) and isinstance(e.value, LookupError)


def test_not_a_store_is_a_format_error(tmp_path, ctx):
    p = tmp_path / "x.h5"
    p.write_text("not hdf5\n")
    with pytest.raises(es.FormatError) as e:
        es.Store(p, ctx=ctx)
    assert "x.h5" in str(e.value)


def test_point_syntax_error_names_the_column(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        with pytest.raises(es.FormatError) as e:
            s.point("mean + * 2")
        assert "column" in str(e.value)
        with pytest.raises(es.NotFoundError) as e:
            s.point("row:nobody")
        assert "nobody" in str(e.value)


def test_bad_faces_are_a_topology_error(ctx):
    with pytest.raises(es.TopologyError) as e:   # an edge shared by three faces
        es.Mesh([[0, 1, 2], [0, 1, 3], [0, 1, 4]], ctx=ctx)
    assert "edge" in str(e.value)


def test_ingest_errors_name_the_manifest_line(tmp_path, faces_dir, ctx):
    m = tmp_path / "m.csv"
    m.write_text(f"file,subject\n{faces_dir}/face_s01_neutral.obj,s01\n"
                 f"{faces_dir}/missing.obj,s02\n")
    with pytest.raises(es.Error) as e:
        es.ingest(tmp_path / "s.h5", manifest=m, ctx=ctx)
    assert "missing.obj" in str(e.value)
    assert not (tmp_path / "s.h5").exists()   # all-or-nothing


def test_shape_errors_are_caught_before_the_library(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        with pytest.raises(ValueError, match="shape"):
            s.nearest_row(np.zeros(3))


def test_progress_reaches_the_callback(store_path):
    seen = []
    ctx = es.Context(progress=lambda what, done, total: seen.append((what, done, total)))
    with es.Store(store_path, ctx=ctx) as s:
        s.pca(components=3)
    stages = {w for w, _, _ in seen}
    assert any(w.startswith("pca") for w in stages)
    for w in stages:   # every stage ends at done == total
        last = [x for x in seen if x[0] == w][-1]
        assert last[1] == last[2] > 0


def test_an_exception_in_a_callback_comes_out_of_the_call(store_path):
    class Stop(Exception):
        pass

    def boom(what, done, total):
        raise Stop(what)

    ctx = es.Context(progress=boom)
    with es.Store(store_path, ctx=ctx) as s:
        with pytest.raises(Stop):
            s.pca(components=2)
        ctx.progress = None           # and the context is usable afterwards
        assert s.pca(components=2).ncomp == 2


def test_tqdm_progress_when_installed(store_path):
    pytest.importorskip("tqdm")
    ctx = es.Context(progress=True)
    assert ctx.progress is not None
    with es.Store(store_path, ctx=ctx) as s:
        assert s.pca(components=2).ncomp == 2


def test_no_notebook_bars_outside_a_kernel_or_with_old_widgets(monkeypatch):
    """ipywidgets imports ipykernel in any process: that is no kernel. In a
    kernel, tqdm.notebook needs ipywidgets >= 7 (Debian 12 ships 6, whose
    FloatProgress lacks .style): no bars then, rather than an error."""
    pytest.importorskip("tqdm")
    from edgespace import _context
    monkeypatch.setitem(sys.modules, "ipykernel", types.ModuleType("ipykernel"))
    from tqdm.std import tqdm
    assert _context._tqdm() is tqdm
    shell = types.SimpleNamespace(kernel=object())
    fake_ipython = types.SimpleNamespace(get_ipython=lambda: shell)
    monkeypatch.setitem(sys.modules, "IPython", fake_ipython)
    monkeypatch.setitem(sys.modules, "ipywidgets", types.SimpleNamespace(__version__="6.0.0"))
    assert _context._tqdm() is None
    pytest.importorskip("tqdm.notebook")
    monkeypatch.setitem(sys.modules, "ipywidgets", types.SimpleNamespace(__version__="8.1.2"))
    from tqdm.notebook import tqdm as notebook_tqdm
    assert _context._tqdm() is notebook_tqdm


def test_library_warnings_become_python_warnings(tmp_path, faces_dir, ctx):
    # identical content under a new id is ingested with a warning naming the row
    m = tmp_path / "m.csv"
    f = faces_dir / "face_s01_neutral.obj"
    m.write_text(f"id,file\na,{f}\nb,{f}\n")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        es.ingest(tmp_path / "s.h5", manifest=m, ctx=ctx)
    msgs = [str(x.message) for x in w if issubclass(x.category, es.EdgespaceWarning)]
    assert msgs == [f"'{f}' has the same content as '{f}'"]


def test_the_seed_makes_synthetic_data_reproducible():
    a = es.synth("face", n=3, ctx=es.Context(seed=7, progress=None))
    b = es.synth("face", n=3, ctx=es.Context(seed=7, progress=None))
    c = es.synth("face", n=3, ctx=es.Context(seed=8, progress=None))
    assert np.array_equal(a["vertices"], b["vertices"])
    assert not np.array_equal(a["vertices"], c["vertices"])
    assert es.Context(progress=None).seed == 0x5eed


def test_each_thread_has_its_own_default_context():
    got = []
    t = threading.Thread(target=lambda: got.append(es.default_context()))
    t.start()
    t.join()
    assert got[0] is not es.default_context()
    assert es.default_context() is es.default_context()
