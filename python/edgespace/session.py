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
from .mesh import Embedding, report_dict, set_embed_opts


class StudyEmbedder:
    """Embeds points of a store's space near their priors, fast; see the
    module's text. Made by Store.embedder(); closed with the store (or by
    close()). One thread at a time."""

    def __init__(self, store, cache=True):
        self.store = store           # kept alive while the session is
        self.ctx = store.ctx
        p = ffi.new("es_study_embedder **")
        self.ctx.call(lib.es_study_embedder_open, store.ptr, 1 if cache else 0, p)
        self._ptr = A.owned(self.ctx, p[0], lib.es_study_embedder_free)
        self.faces = store.mesh.faces
        self.nrows = store.nrows   # the rows it was made for

    @property
    def ptr(self):
        if self._ptr is None:
            raise ValueError("the embedding session is closed")
        return self._ptr

    def embed(self, point, pca=None, scale=0.0, warm=True, fast=False, **opts):
        """Embedding(V, F, report) of a point expression
        (datasets-spec/point-syntax.md) in the store's frame. warm: from the
        last point's correction of its prior; fast: es_embed_opts_fast (a
        slider's accuracy); opts: es_embed_opts fields."""
        eo = ffi.new("es_embed_opts *")
        if fast:
            lib.es_embed_opts_fast(eo)
        else:
            lib.es_embed_opts_init(eo)
        set_embed_opts(eo, opts)
        xyz = np.empty((self.store.nverts, 3))
        res = ffi.new("es_study_embed_result *")
        keep = [ffi.new("char[]", str(point).encode()),
                ffi.new("char[]", str(pca).encode()) if pca is not None else ffi.NULL]
        self.ctx.call(lib.es_study_embedder_point, self.ptr, keep[0], keep[1], float(scale), eo,
                      1 if warm else 0, A.dptr(xyz), res)
        rep = report_dict(res.report)
        rep["scale"] = float(res.scale)
        rep["init"] = ffi.string(res.init).decode("utf-8", "replace")
        return Embedding(xyz, self.faces, rep)

    def forget(self):
        """The next warm embedding starts from its own prior."""
        lib.es_study_embedder_forget(self.ptr)

    def close(self):
        if self._ptr is not None:
            ffi.release(self._ptr)
            self._ptr = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
