"""python/edgespace/session.py — an embedding session on a store
(es_study_embedder, es_study.h).

Store.embedder() opens one: the mesh, the embedder and the rows made ready
for priors are made once (read from STORE.es-cache beside the store when it
is current), and every embed() after the first costs only its solve. With
warm=True (the default) a point starts from the last one's correction of
its prior: what a slider or a walk wants (es_study_embedder_solve).
"""
import numpy as np

from . import _arrays as A
from ._native import ffi, lib
from .mesh import set_embed_opts, study_embedding


class StudyEmbedder:
    """Embeds points of a store's space near their priors, fast; see the
    module's text. Made by Store.embedder(); closed with the store (or by
    close()). Threads that share one take turns (the store's context's lock),
and a close() from another thread waits for the running embedding."""

    def __init__(self, store, cache=True):
        self.store = store           # kept alive while the session is
        self.ctx = store.ctx
        p = ffi.new("es_study_embedder **")
        with self.ctx.hold():   # the store not closed meanwhile
            store._call(lib.es_study_embedder_open, 1 if cache else 0, p)
            self._ptr = A.owned(self.ctx, p[0], lib.es_study_embedder_free)
            self.faces = store.mesh.faces
            self.nrows = store.nrows   # the rows it was made for

    @property
    def ptr(self):
        if self._ptr is None:
            raise ValueError("the embedding session is closed")
        return self._ptr

    @staticmethod
    def _opts(fast, opts):
        eo = ffi.new("es_embed_opts *")
        if fast:
            lib.es_embed_opts_fast(eo)
        else:
            lib.es_embed_opts_init(eo)
        set_embed_opts(eo, opts)
        return eo

    def _result(self, xyz, res):
        return study_embedding(xyz, self.faces, res)

    def solve(self, lengths, scale, weights, warm=True, exact=False, fast=False, **opts):
        """Embedding(V, F, report) of lengths (E,) at sum `scale` near the
        prior of row weights (N,) (es_study_embedder_solve): what embed()
        does after evaluating its expression, for callers that form lengths
        and weights themselves (a slider: the mean plus multiples of
        directions evaluated once). exact: the lengths are one real mesh's."""
        L = A.f64(lengths, (self.store.nedges,), "lengths")
        w = A.f64(weights, (self.store.nrows,), "weights")
        eo = self._opts(fast, opts)
        xyz = np.empty((self.store.nverts, 3))
        res = ffi.new("es_study_embed_result *")
        with self.ctx.hold():   # a close() from another thread waits
            self.ctx.call(lib.es_study_embedder_solve, self.ptr, A.dptr(L), float(scale),
                          A.dptr(w), eo, 1 if warm else 0, 1 if exact else 0, A.dptr(xyz), res)
        return self._result(xyz, res)

    def vertex_deviation(self):
        """(V,) each vertex's distance from the prior's realization in the
        last solve, as a fraction of its bounding-box diagonal
        (es_embedder_vertex_deviation; a copy), or None before one."""
        p = lib.es_embedder_vertex_deviation(lib.es_study_embedder_embedder(self.ptr))
        if p == ffi.NULL:
            return None
        return np.array(A.view(p, (self.store.nverts,), self))

    def prior_positions(self, weights):
        """(V, 3) the prior's realization of row weights (N,) in the store's
        frame (es_study_prior on the session's rows): for one row weighted 1,
        that row's mesh aligned into the frame every embedding shares."""
        w = A.f64(weights, (self.store.nrows,), "weights")
        xyz = np.empty((self.store.nverts, 3))
        self.ctx.call(lib.es_study_prior, lib.es_study_embedder_rows(self.ptr), A.dptr(w),
                      A.dptr(xyz), ffi.NULL, ffi.NULL)
        return xyz

    def embed(self, point, pca=None, scale=0.0, warm=True, fast=False, **opts):
        """Embedding(V, F, report) of a point expression
        (datasets-spec/point-syntax.md) in the store's frame. warm: from the
        last point's correction of its prior; fast: es_embed_opts_fast (a
        slider's accuracy); opts: es_embed_opts fields."""
        eo = self._opts(fast, opts)
        xyz = np.empty((self.store.nverts, 3))
        res = ffi.new("es_study_embed_result *")
        keep = [A.cstr(str(point)), A.cstr(None if pca is None else str(pca))]
        with self.ctx.hold():   # a close() from another thread waits
            self.ctx.call(lib.es_study_embedder_point, self.ptr, keep[0], keep[1], float(scale),
                          eo, 1 if warm else 0, A.dptr(xyz), res)
        return self._result(xyz, res)

    def forget(self):
        """The next warm embedding starts from its own prior."""
        with self.ctx.hold():
            lib.es_study_embedder_forget(self.ptr)

    def close(self):
        """Free the session: waits for an embedding running in another
        thread; refused from a callback of a call running on the context."""
        with self.ctx.closing():
            if self._ptr is not None:
                ffi.release(self._ptr)
                self._ptr = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
