"""python/tests/test_robustness.py — the binding against careless and hostile
use (issue 25), each case a finding of the audit:

- Store.lengths(out=...) writes only into writable float64 arrays: a
  read-only array, one over immutable bytes, a read-only memory map are
  refused (they were written into; the memory map segfaulted);
- Store.close() from another thread while a call runs waits for it (it
  freed the store under pca(): heap-use-after-free), and from a callback of
  that call is refused;
- one Embedder shared by two and four threads: the solves take turns and
  agree with one thread's (they hung in CHOLMOD, or segfaulted); the same
  for an embedding session (Store.embedder()), whose close() from another
  thread waits for the running embedding;
- NUL inside a string argument is refused (it cut the string short), and a
  float where an index or count belongs (it was truncated);
- an exception in a progress callback cancels the work: it is raised, and
  the store's file is byte for byte as before (the result was stored
  anyway); Ctrl-C arriving while the library works does the same.

CI also runs this file with the AddressSanitizer-built library preloaded
(python/meson.build, test python-asan), where a use after free or a write
through a read-only buffer is an error rather than luck.
"""
import _thread
import os
import threading

import numpy as np
import pytest

import edgespace as es


def file_bytes(path):
    with open(path, "rb") as f:
        return f.read()


# ---- out= must be writable --------------------------------------------------------

def test_lengths_out_refuses_what_it_must_not_write(store_path, ctx, tmp_path):
    with es.Store(store_path, ctx=ctx) as s:
        n, E = s.nrows, s.nedges
        good = np.zeros((n, E))
        assert s.lengths(out=good) is good and np.array_equal(good, s.lengths())
        ro = np.zeros((n, E))
        ro.flags.writeable = False
        with pytest.raises(ValueError, match="read-only"):
            s.lengths(out=ro)
        assert not ro.any()
        frozen = bytes(8 * n * E)
        with pytest.raises(TypeError, match="numpy array"):
            s.lengths(out=frozen)
        with pytest.raises(ValueError, match="read-only"):
            s.lengths(out=np.frombuffer(frozen).reshape(n, E))
        assert frozen == bytes(8 * n * E)
        mm_path = tmp_path / "out.bin"
        np.zeros((n, E)).tofile(mm_path)
        mm = np.memmap(mm_path, dtype=np.float64, mode="r", shape=(n, E))
        with pytest.raises(ValueError, match="read-only"):
            s.lengths(out=mm)
        del mm
        assert not np.fromfile(mm_path).any()
        with pytest.raises(ValueError, match="C-contiguous float64"):
            s.lengths(out=np.zeros((E, n)).T)
        with pytest.raises(ValueError, match="C-contiguous float64"):
            s.lengths(out=np.zeros((n, E), dtype=np.float32))


# ---- close while in use ----------------------------------------------------------

def test_close_from_another_thread_waits_for_the_running_call(store_path):
    ctx = es.Context(progress=None)
    s = es.Store(store_path, ctx=ctx)
    started, done, errors = threading.Event(), [], []
    ctx.progress = lambda what, d, t: started.set()

    def work():
        try:
            done.append(s.model("~ expression", permutations=20000))
        except BaseException as e:   # noqa: B036 (reported by the main thread)
            errors.append(e)
    t = threading.Thread(target=work)
    t.start()
    assert started.wait(30)
    s.close()                       # waits for the model, then frees the store
    t.join(60)
    assert not t.is_alive() and not errors, errors
    assert len(done) == 1 and done[0].p[0] < 0.05
    with pytest.raises(ValueError, match="closed"):
        s.nrows
    with pytest.raises(ValueError, match="closed"):
        s.lengths()


def test_close_from_a_callback_of_a_call_on_it_is_refused(store_path):
    ctx = es.Context(progress=None)
    with es.Store(store_path, ctx=ctx) as s:
        def close_it(what, d, t):
            s.close()
        ctx.progress = close_it
        with pytest.raises(RuntimeError, match="cannot be closed from a callback"):
            s.pca(components=2)
        ctx.progress = None
        assert s.nrows == 18 and s.pca(components=2).ncomp == 2


def test_a_library_call_from_a_callback_is_refused(store_path):
    ctx = es.Context(progress=None)
    with es.Store(store_path, ctx=ctx) as s:
        ctx.progress = lambda what, d, t: s.lengths(0)
        with pytest.raises(RuntimeError, match="from a callback"):
            s.pca(components=2)


# ---- a shared embedder ---------------------------------------------------------------

@pytest.mark.parametrize("nthreads", [2, 4])
def test_shared_embedder_takes_turns(store_path, nthreads):
    ctx = es.Context(progress=None)
    with es.Store(store_path, ctx=ctx) as s:
        mesh = s.mesh
        L = s.lengths()
    emb = es.Embedder(mesh, ctx=ctx)
    want = [emb.solve(L[i], init_vertices=mesh.vertices).V for i in range(nthreads)]
    got, errors = [None] * nthreads, []
    barrier = threading.Barrier(nthreads)

    def work(i):
        try:
            barrier.wait()
            for _ in range(2):
                got[i] = emb.solve(L[i], init_vertices=mesh.vertices).V
        except BaseException as e:   # noqa: B036
            errors.append(e)
    ts = [threading.Thread(target=work, args=(i,)) for i in range(nthreads)]
    for t in ts:
        t.start()
    for t in ts:
        t.join(120)
    assert not errors and not any(t.is_alive() for t in ts), errors
    for i in range(nthreads):
        assert np.array_equal(got[i], want[i])


def test_shared_session_takes_turns_and_close_waits(store_path):
    ctx = es.Context(progress=None)
    s = es.Store(store_path, ctx=ctx)
    se = s.embedder(cache=False)
    a, b = s.ids[0], s.ids[1]
    points = ["mean", f"row:{a}", f"lerp(row:{a}, row:{b}, 0.5)"]
    want = [se.embed(p, warm=False).V for p in points]
    got, errors = [None] * len(points), []
    barrier = threading.Barrier(len(points))

    def work(i):
        try:
            barrier.wait()
            for _ in range(2):
                got[i] = se.embed(points[i], warm=False).V
        except BaseException as e:   # noqa: B036
            errors.append(e)
    ts = [threading.Thread(target=work, args=(i,)) for i in range(len(points))]
    for t in ts:
        t.start()
    for t in ts:
        t.join(120)
    assert not errors and not any(t.is_alive() for t in ts), errors
    for i in range(len(points)):
        assert np.array_equal(got[i], want[i])
    # a close from another thread while an embedding runs waits for it
    started, done = threading.Event(), []
    ctx.progress = lambda what, d, t: started.set()

    def one():
        try:
            done.append(se.embed(points[1], warm=False).V)
        except BaseException as e:   # noqa: B036
            errors.append(e)
    t = threading.Thread(target=one)
    t.start()
    assert started.wait(30)
    s.close()                       # closes the session too, after the embedding
    t.join(60)
    assert not t.is_alive() and not errors, errors
    assert len(done) == 1 and np.array_equal(done[0], want[1])
    with pytest.raises(ValueError, match="closed"):
        se.embed("mean")


# ---- strings and indices -------------------------------------------------------------

def test_nul_in_strings_is_refused(store_path, ctx):
    with pytest.raises(ValueError, match="NUL"):
        es.Store(str(store_path) + "\0.bak", ctx=ctx)
    with es.Store(store_path, write=True, ctx=ctx) as s:
        with pytest.raises(ValueError, match="NUL"):
            s.select("expression=happy\0,subject=s01")
        with pytest.raises(ValueError, match="NUL"):
            s.mean(by="expression", name="m\0x")
        with pytest.raises(ValueError, match="NUL"):
            s.find_row("face_s01_happy\0")
        with pytest.raises(ValueError, match="NUL"):
            s.model("~ expression\0 + subject")
        assert s.results() == []
    with pytest.raises(ValueError, match="NUL"):
        es.read_mesh("x.obj\0y", ctx=ctx)


def test_non_integer_indices_are_refused(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        assert np.array_equal(s.lengths(np.int64(1)), s.lengths([1]))
        for bad in (1.5, 1.0, True, "1"):
            with pytest.raises(TypeError, match="row must be an integer"):
                s.lengths(bad)
        with pytest.raises(TypeError, match="rows must be integers"):
            s.lengths([0, 1.5])
        with pytest.raises(TypeError, match="rows must be integers"):
            s.lengths(np.array([True, False]))
        with pytest.raises(TypeError, match="row must be an integer"):
            s.positions(0.0)
        with pytest.raises(TypeError, match="row must be an integer"):
            s.source_path(2.9)
        with pytest.raises(TypeError, match="components must be an integer"):
            s.pca(components=2.5)
        with pytest.raises(TypeError, match="permutations must be an integer"):
            s.model("~ expression", permutations=99.9)


# ---- exceptions in callbacks, Ctrl-C ------------------------------------------------

@pytest.mark.parametrize("call", ["model", "pca", "mean"])
def test_callback_exception_cancels_and_stores_nothing(store_path, call):
    before = file_bytes(store_path)
    ctx = es.Context(progress=None)
    reports = []

    def boom(what, d, t):
        reports.append(what)
        raise ZeroDivisionError("the user's callback failed")
    with es.Store(store_path, write=True, ctx=ctx) as s:
        ctx.progress = boom
        with pytest.raises(ZeroDivisionError, match="user's callback"):
            if call == "model":
                s.model("~ expression + subject", permutations=50000, name="m")
            elif call == "pca":
                s.pca(name="p", components=3)
            else:
                s.mean(by="expression", name="x")
        assert len(reports) == 1          # not called again once it raised
        ctx.progress = None
        assert s.results() == [] and not lib_pending(s)
    assert file_bytes(store_path) == before
    with es.Store(store_path, write=True, ctx=ctx) as s:   # and it still works
        s.mean(by="expression", name="x")
        assert s.results("mean") == ["x"]


def lib_pending(s):
    return bool(es.lib.es_store_pending(s.ptr))


def begin_result(s, kind, name):
    """es_store_result_begin: a result written, not committed."""
    command = es.ffi.new("char[]", b"test")
    prov = es.ffi.new("es_provenance *", {"command": command, "nrows": -1})
    s._call(es.lib.es_store_result_begin, kind.encode(), name.encode(), prov)


def test_ctrl_c_cancels_long_work(store_path):
    before = file_bytes(store_path)
    ctx = es.Context(progress=None)     # no progress function: Ctrl-C still reaches it
    timer = threading.Timer(0.2, _thread.interrupt_main)
    with es.Store(store_path, write=True, ctx=ctx) as s:
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            # 3 s of permutations uninterrupted here (more under ASan)
            s.model("~ expression + subject", permutations=2_000_000, name="m")
        # the library stopped at a progress report, not at the end
        msg = es.ffi.string(es.lib.es_ctx_errmsg(ctx.ptr)).decode()
        assert "cancelled during" in msg and "nothing stored" in msg, msg
        assert s.results() == []
    timer.cancel()
    assert file_bytes(store_path) == before


def test_failed_call_discards_its_partial_writes_only(store_path, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as s:
        s.mean(by="expression", name="kept")
        # a pending write of the user's stays through a failing call
        begin_result(s, "mean", "pending")
        with pytest.raises(es.NotFoundError):
            s.model("~ mood", name="m")
        assert s.has("mean/pending") and lib_pending(s)
    with es.Store(store_path, ctx=ctx) as s:
        assert sorted(s.results("mean")) == ["kept", "pending"]


def test_store_rollback(store_path, ctx):
    before = file_bytes(store_path)
    with es.Store(store_path, write=True, ctx=ctx) as s:
        begin_result(s, "mean", "gone")
        assert s.has("mean/gone")
        s.rollback()
        assert not s.has("mean/gone") and s.nrows == 18
    assert file_bytes(store_path) == before
    assert not [f for f in os.listdir(os.path.dirname(store_path)) if ".tmp-" in f]
