#!/usr/bin/python3
"""tools/bench/bench_python.py — what the Python binding costs over the C calls
it makes, side by side in one run.

1. Reading 600 x 28K lengths: Store.lengths() (the binding: argument checks,
   the numpy array, the es_mat) against es_store_read_lengths called through
   cffi (the C call itself; cffi's call overhead is about a microsecond), both
   into a new array and into one the caller holds, and for reference h5py
   reading the same dataset.
2. One embedding of the store's mean: Store.embed() against es_study_embed
   called directly, and Embedder.solve(prior=...) against
   es_embed_prior_solve on preallocated arguments.
Figures: median wall and CPU seconds of `--repeat` runs each, alternating
the two sides so the page cache and the machine's load treat them alike, and
the overhead (binding - C) in ms and percent. On a loaded machine the
difference of two medians of seconds-long embeddings is noise, so the
wrapper's own work is also timed alone: the same wrapper calls with the
context's call() replaced by one that returns without calling the library
(everything but the C call: argument checks, arrays, option structs, the
report dict), 1,000 times.

Data: a store of 600 rows on face-study's topology (9,409 vertices, 27,871
edges): face-study's meshes with seeded per-vertex noise (../shared/data),
else the synthetic face at resolution 28 (27K edges). Made once under
--work (default /tmp/edgespace-bench-python).

    OPENBLAS_NUM_THREADS=1 /usr/bin/python3 tools/bench/bench_python.py
"""
import argparse
import os
import pathlib
import statistics
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent / "python"))

import numpy as np  # noqa: E402

import edgespace as es  # noqa: E402
from edgespace import _arrays as A  # noqa: E402
from edgespace import ffi, lib  # noqa: E402


def make_store(path, nrows, shared, ctx):
    src = pathlib.Path(shared) / "data" / "face-study"
    if src.is_dir():
        files = sorted(src.glob("*.obj"))
        mesh = es.read_mesh(files[0], ctx=ctx)
        base = np.stack([mesh.read_positions(f) for f in files])
        what = f"face-study ({len(files)} meshes) with noise"
        F = mesh.faces
    else:
        syn = es.synth("face", n=10, resolution=28, ctx=ctx)
        base, F = syn["vertices"], syn["faces"]
        what = "synthetic faces (resolution 28) with noise"
    rng = np.random.default_rng(1)
    scale = np.abs(base[0]).max() * 1e-3
    with es.Store.create(path, faces=F, vertices=base[0], ctx=ctx) as s:
        for b in range(0, nrows, 100):   # 100 rows per append keeps memory modest
            n = min(100, nrows - b)
            V = base[np.arange(b, b + n) % len(base)] + rng.normal(scale=scale,
                                                                    size=(n,) + base.shape[1:])
            s.append([f"r{i:04d}" for i in range(b, b + n)], V)
    return what


def timed(fn):
    w, c = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - w, time.process_time() - c


def compare(name, binding, raw, repeat):
    if repeat < 1:
        return
    tb, tr = [], []
    for i in range(repeat):   # alternate which side goes first: neither inherits the other's cache
        if i % 2:
            tr.append(timed(raw))
            tb.append(timed(binding))
        else:
            tb.append(timed(binding))
            tr.append(timed(raw))
    mb = [statistics.median(x[i] for x in tb) for i in (0, 1)]
    mr = [statistics.median(x[i] for x in tr) for i in (0, 1)]
    print(f"{name}")
    print(f"  binding  wall {mb[0]*1e3:10.3f} ms   cpu {mb[1]*1e3:10.3f} ms")
    print(f"  C call   wall {mr[0]*1e3:10.3f} ms   cpu {mr[1]*1e3:10.3f} ms")
    print(f"  overhead wall {(mb[0]-mr[0])*1e3:+10.3f} ms ({100*(mb[0]/mr[0]-1):+.2f} %)   "
          f"cpu {(mb[1]-mr[1])*1e3:+10.3f} ms; ratio binding/C {mb[0]/mr[0]:.4f}")


class _NoLibrary:
    """A stand-in for an es.Context whose call() does not call the library:
    what remains of a wrapper call is the binding's own work."""

    def call(self, fn, *args):
        return 0


def own_work(name, obj, fn, n=1000):
    fn()   # once for real first: what the object caches (its es_mesh) is made by the library
    real, obj.ctx = obj.ctx, _NoLibrary()
    try:
        w, c = timed(lambda: [fn() for _ in range(n)])
    finally:
        obj.ctx = real
    print(f"  the binding's own work per call ({name}, library call left out): "
          f"wall {w / n * 1e3:.4f} ms   cpu {c / n * 1e3:.4f} ms")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rows", type=int, default=600)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--embed-repeat", type=int, default=3)
    ap.add_argument("--work", default="/tmp/edgespace-bench-python")
    ap.add_argument("--shared", default=os.environ.get(
        "EDGESPACE_SHARED", str(HERE.parent.parent.parent / "shared")))
    a = ap.parse_args()
    ctx = es.Context(progress=None)
    work = pathlib.Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    path = work / f"bench_{a.rows}.h5"
    if not path.exists():
        print(f"making {path}: {make_store(path, a.rows, a.shared, ctx)}")
    s = es.Store(path, ctx=ctx)
    N, E = s.nrows, s.nedges
    print(f"libedgespace {es.version()} ({es.LIBRARY_PATH}); store {N} rows x {E} edges "
          f"({N * E * 8 / 2**20:.0f} MiB of lengths), {s.nverts} vertices; "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}")

    # 1. reading every row's lengths: into a new array (the binding allocates
    # one; the C side gets a fresh one too, as a C program would malloc it, so
    # both pay the first touch of 128 MiB), and into the caller's array
    buf = np.empty((N, E))
    m, keep = A.mat(buf)
    mat = m[0]
    first = s.lengths()   # warm the page cache for both sides alike

    def raw_new():
        b = np.empty((N, E))
        mb, kb = A.mat(b)
        ctx.call(lib.es_store_read_lengths, s.ptr, 0, N, mb[0])
    compare(f"read {N} x {E} lengths into a new array (Store.lengths() vs "
            "es_store_read_lengths)", lambda: s.lengths(), raw_new, a.repeat)
    compare(f"read {N} x {E} lengths into the caller's array (Store.lengths(out=) vs "
            "es_store_read_lengths)", lambda: s.lengths(out=buf),
            lambda: ctx.call(lib.es_store_read_lengths, s.ptr, 0, N, mat), a.repeat)
    assert np.array_equal(buf, first)
    own_work("Store.lengths()", s, lambda: s.lengths())
    own_work("Store.lengths(out=)", s, lambda: s.lengths(out=buf))
    # the fixed cost of a call: one row, a thousand times per timing
    one = np.empty((1, E))
    m1, k1 = A.mat(one)
    compare("  per call: 1,000 reads of one row (Store.lengths(i, out=) vs the C call)",
            lambda: [s.lengths(i % N, out=one) for i in range(1000)],
            lambda: [ctx.call(lib.es_store_read_lengths, s.ptr, i % N, 1, m1[0])
                     for i in range(1000)], a.repeat)
    try:
        import h5py
    except ImportError:
        pass
    else:
        with h5py.File(path, "r") as f:
            d = f["shapes/lengths"]
            compare("  for reference: h5py d[:] vs es_store_read_lengths", lambda: d[:],
                    lambda: ctx.call(lib.es_store_read_lengths, s.ptr, 0, N, mat), a.repeat)

    # 2. one embedding of the store's mean
    o = ffi.new("es_study_embed_opts *")
    lib.es_study_embed_opts_init(o)
    spec = ffi.new("char[]", b"mean")
    o.point = spec
    xyz, res = np.empty((s.nverts, 3)), ffi.new("es_study_embed_result *")
    pxyz = A.dptr(xyz)
    out = {}
    compare("embed the mean (Store.embed vs es_study_embed)",
            lambda: out.__setitem__("b", s.embed("mean")),
            lambda: ctx.call(lib.es_study_embed, s.ptr, o, pxyz, res), a.embed_repeat)
    assert a.embed_repeat < 1 or np.array_equal(out["b"].V, xyz)
    own_work("Store.embed", s, lambda: s.embed("mean"))

    pt = s.point_weights("mean")
    prior = s.prior(pt.weights)
    emb = es.Embedder(s.mesh, ctx=ctx)
    T, X, Al, Sd = (A.f64(v) for v in (pt.lengths, prior["xyz"], prior["alpha"], prior["sd"]))
    pr = ffi.new("es_embed_prior *")
    bufs = (A.dptr(X), A.dptr(Al), A.dptr(Sd))
    pr.xyz, pr.alpha, pr.sd = bufs
    eo, rep, pT = es.embed_opts(), ffi.new("es_embed_report *"), A.dptr(T)
    compare("embed lengths near a prior (Embedder.solve vs es_embed_prior_solve)",
            lambda: out.__setitem__("e", emb.solve(pt.lengths, pt.scale, prior=prior)),
            lambda: ctx.call(lib.es_embed_prior_solve, emb._ptr, pT, pt.scale, pr, eo, pxyz,
                             rep), a.embed_repeat)
    assert a.embed_repeat < 1 or np.array_equal(out["e"].V, xyz)
    own_work("Embedder.solve", emb, lambda: emb.solve(pt.lengths, pt.scale, prior=prior))
    s.close()


if __name__ == "__main__":
    main()
