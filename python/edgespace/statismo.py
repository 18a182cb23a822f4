"""python/edgespace/statismo.py — a statismo shape model read back
(es_statismo_read, datasets-spec/statismo.md): the files `edgespace export
--statismo`, statismo and scalismo write, as numpy arrays, so that a model's
mean and modes become points of a study (embedded with Store.embed of their
edge lengths, projected with PCA.project) or meshes to write.
"""
import numpy as np

from . import _arrays as A
from ._context import ctx_of
from ._native import ffi, lib


class StatismoModel:
    """dataset_type ("POLYGON_MESH" or "POINT_SET"), version (major, minor),
    mean and points (V, 3), faces (F, 3) or None for a point set, basis
    (K, V, 3) unit modes, variance (K,), noise_variance."""

    def __init__(self, path, ctx=None):
        ctx = ctx_of(ctx)
        out = ffi.new("es_statismo_data **")
        ctx.call(lib.es_statismo_read, str(path).encode(), out)
        m = out[0]
        try:
            V, F, K = int(m.nverts), int(m.nfaces), int(m.ncomp)
            self.path = str(path)
            self.dataset_type = ffi.string(m.dataset_type).decode()
            self.version = (int(m.major), int(m.minor))
            self.mean = np.array(A.view(m.mean, (V, 3), None))
            self.points = np.array(A.view(m.points, (V, 3), None))
            self.faces = np.array(A.view(m.faces, (F, 3), None, "i8")) if F else None
            self.basis = np.array(A.view(m.basis, (K, V, 3), None))
            self.variance = np.array(A.view(m.variance, (K,), None))
            self.noise_variance = float(m.noise_variance)
        finally:
            lib.es_statismo_data_free(m)

    ncomp = property(lambda self: len(self.variance))

    def instance(self, b=None):
        """Positions (V, 3) of mean + sum_k b_k sqrt(variance_k) basis_k
        (b: coefficients in standard deviations, the first len(b) modes;
        None: the mean), as statismo's DrawSample and scalismo's instance."""
        if b is None:
            return self.mean.copy()
        b = np.asarray(b, dtype=np.float64).ravel()
        if len(b) > self.ncomp:
            raise ValueError(f"{len(b)} coefficients for a model of {self.ncomp} modes")
        K = len(b)
        return self.mean + np.tensordot(b * np.sqrt(self.variance[:K]), self.basis[:K], 1)

    def coefficients(self, positions):
        """Coefficients b (K,) of positions (V, 3) in standard deviations:
        the projection on the modes (statismo's ComputeCoefficients without
        noise)."""
        d = (np.asarray(positions, dtype=np.float64) - self.mean).reshape(-1)
        U = self.basis.reshape(self.ncomp, -1)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.variance > 0, (U @ d) / np.sqrt(self.variance), 0.0)

    def lengths(self, edges, b=None):
        """Edge lengths (E,) of instance(b) over edges (E, 2) (a Store's
        .edges): a point to Store.embed or PCA.project."""
        X = self.instance(b)
        e = np.asarray(edges, dtype=np.int64)
        return np.linalg.norm(X[e[:, 0]] - X[e[:, 1]], axis=1)

    def __repr__(self):
        return (f"<edgespace.StatismoModel {self.dataset_type} {self.version[0]}."
                f"{self.version[1]} V={len(self.mean)} K={self.ncomp}>")


def read_statismo(path, ctx=None):
    """A statismo model file as a StatismoModel (es_statismo_read)."""
    return StatismoModel(path, ctx)
