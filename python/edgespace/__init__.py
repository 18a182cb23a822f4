"""edgespace — statistical shape analysis in edge-length shape space, from Python.

A numpy-native binding of libedgespace (the C library of this repository)
through cffi: the same functions the `edgespace` command calls, on arrays and
on HDF5 shape stores. Nothing is computed in Python that the library
computes; arrays cross the boundary without copies where the layouts agree
(python/edgespace/_arrays.py says which).

    import edgespace as es
    es.ingest("faces.h5", manifest="faces/manifest.csv")
    with es.Store("faces.h5", write=True) as s:
        L = s.lengths()                         # (N, E) float64
        pca = s.pca("faces", components=10)     # stored as /analysis/pca/faces
        s.diff("smile", pair_by="subject", column="expression", from_="neutral", to="happy")
        V, F, report = s.embed("mean[expression=neutral] + diff:smile")
    es.render((V, F))                            # PNG bytes, inline in Jupyter

Errors raise edgespace.Error subclasses (also ValueError, LookupError, OSError,
... by kind) carrying the library's message. Progress of long work reaches
Context(progress=...) (a tqdm bar when tqdm is installed). python/README.md
describes the package; datasets-spec/ the files.
"""
import numpy as _np

from . import _arrays as _A
from ._context import Context, EdgespaceWarning, default_context
from ._errors import (CancelledError, ConvergenceError, Error, ExistsError, FormatError,
                      InvalidError, IOFailure, MismatchError, NoMemoryError, NotFoundError,
                      NumericError, RangeError, TopologyError)
from ._names import renamed
from ._native import INCLUDE_DIR, LIBRARY_PATH, LoadError, ffi, lib
from .mesh import (Embedder, Embedding, Mesh, embed, embed_opts, normalize_lengths,
                   read_mesh)
from .render import FiguresUnavailable, Image, auto_view, plot_scatter, plot_scree, render
from .session import StudyEmbedder
from .colour_files import scalar_colors, write_vtp
from .statismo import StatismoModel, read_statismo
from .store import PCA, Store, ingest

__all__ = [
    "Context", "EdgespaceWarning", "default_context", "Error", "NoMemoryError",
    "InvalidError", "RangeError", "IOFailure", "FormatError", "NumericError",
    "ConvergenceError", "NotFoundError", "ExistsError", "MismatchError", "TopologyError",
    "CancelledError",
    "LoadError", "Mesh", "Embedder", "Embedding", "embed", "embed_opts",
    "normalize_lengths", "read_mesh", "render", "plot_scatter", "plot_scree", "auto_view",
    "Image", "FiguresUnavailable", "Store", "StudyEmbedder", "PCA", "ingest", "synth", "pca",
    "version", "StatismoModel", "read_statismo", "scalar_colors", "write_vtp",
    "has_figures", "LIBRARY_PATH", "INCLUDE_DIR", "ffi", "lib",
]


def version():
    """The library's version string (es_version)."""
    return _A.string(lib.es_version())


__version__ = version()


def has_figures():
    """True if the library was built with figures (cairo)."""
    from ._native import has
    return has("es_render")


def pca(X, components=None, method="auto", oversample=10, power_iters=4, ctx=None, ncomp=None):
    """PCA of the rows of an (N, E) array of length vectors (es_pca_fit on
    es_source_matrix: the array is the library's E x N matrix, not copied)."""
    from ._context import ctx_of
    from .store import _pca_method
    ctx = ctx_of(ctx)
    X = _A.f64(X, (None, None), "X")
    m, keep = _A.mat(X)
    src = lib.es_source_matrix(m[0], ffi.NULL, X.shape[0])
    srcp = ffi.new("es_source *", src)
    o = ffi.new("es_pca_opts *")
    lib.es_pca_opts_init(o)
    components = renamed("edgespace.pca", "components", components, "ncomp", ncomp) or 0
    o.ncomp, o.method = _A.index(components, "components"), _pca_method(method)
    o.oversample = _A.index(oversample, "oversample")
    o.power_iters = _A.index(power_iters, "power_iters")
    out = ffi.new("es_pca **")
    ctx.call(lib.es_pca_fit, srcp, o, out)
    return PCA(ctx, out[0])


def synth(family="face", n=0, resolution=0, noise=-1.0, directory=None, ctx=None):
    """A synthetic family (es_synth: "barbell", "tube", "tube_closed", "face";
    datasets-spec/synthetic.md) from the context's seed: a dict with vertices
    (n, V, 3), faces (F, 3), names and labels {column: values}; directory
    also writes the meshes and a manifest there (es_synth_write)."""
    from ._context import ctx_of
    ctx = ctx_of(ctx)
    fam = ffi.new("es_synth_family *")
    ctx.call(lib.es_synth_family_from_name, _A.cbytes(family, "family"), fam)
    o = ffi.new("es_synth_opts *")
    lib.es_synth_opts_init(o)
    o.n, o.resolution = _A.index(n, "n"), _A.index(resolution, "resolution")
    o.noise = float(noise)
    st = ffi.new("es_synth_set *")
    ctx.call(lib.es_synth_generate, fam[0], o, st)
    try:
        if directory is not None:
            ctx.call(lib.es_synth_write, st, _A.cbytes(directory, "directory"))
        V, F, N, L = int(st.nverts), int(st.nfaces), int(st.nmembers), int(st.nlabels)
        cols = [_A.string(st.label_names[j]) for j in range(L)]
        return {
            "vertices": _np.array(_np.frombuffer(ffi.buffer(st.xyz, 8 * 3 * V * N),
                                                 dtype=_np.float64)).reshape(N, V, 3),
            "faces": _np.array(_np.frombuffer(ffi.buffer(st.faces, 8 * 3 * F),
                                              dtype=_np.int64)).reshape(F, 3),
            "names": [_A.string(st.names[i]) for i in range(N)],
            "labels": {c: _np.array([_A.string(st.labels[i * L + j]) for i in range(N)],
                                    dtype=object) for j, c in enumerate(cols)},
        }
    finally:
        lib.es_synth_set_clear(ctx.ptr, st)
