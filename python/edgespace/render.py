"""python/edgespace/render.py — pictures as PNG bytes: mesh renders (es_render)
and the library's plots (es_plot_scatter, es_plot_scree).

The library draws to a file (the format from the extension); these write a
temporary .png and return its bytes as an Image, which Jupyter shows inline
(_repr_png_). Figures need a library built with cairo (es_config.h
ES_HAVE_FIGURES); without them the calls raise FiguresUnavailable.
"""
import os
import tempfile

import numpy as np

from . import _arrays as A
from ._context import ctx_of
from ._native import ffi, has, lib


class FiguresUnavailable(RuntimeError):
    """libedgespace was built without figures (-Dfigures=disabled: no cairo)."""


class Image(bytes):
    """PNG bytes; displayed inline by Jupyter (_repr_png_). Its repr (a
    notebook's text/plain) is a short description, not the bytes, so an
    executed notebook does not carry every image twice."""

    def __repr__(self):
        w, h = self.size
        return f"<edgespace.Image PNG {w}x{h}, {len(self)} bytes>"

    @property
    def size(self):
        """(width, height) from the PNG's IHDR chunk (0, 0 if not a PNG)."""
        if len(self) >= 24 and self[:8] == b"\x89PNG\r\n\x1a\n":
            return int.from_bytes(self[16:20], "big"), int.from_bytes(self[20:24], "big")
        return 0, 0

    def _repr_png_(self):
        return bytes(self)

    def save(self, path):
        with open(path, "wb") as f:
            f.write(self)


def _need_figures():
    if not has("es_render"):
        raise FiguresUnavailable("this libedgespace has no figures (built without cairo)")


def _draw(ctx, fn, spec, info=ffi.NULL):
    """Run a drawing call into a temporary PNG and return its bytes."""
    with tempfile.TemporaryDirectory(prefix="edgespace-") as d:
        path = os.path.join(d, "figure.png")
        ctx.call(fn, spec, A.cbytes(path, "path"), info)
        with open(path, "rb") as f:
            return Image(f.read())


_CMAPS = {"viridis": "ES_CMAP_VIRIDIS", "rdbu": "ES_CMAP_RDBU", "greys": "ES_CMAP_GREYS"}
_KINDS = {"vertex": "ES_SCALARS_VERTEX", "edge": "ES_SCALARS_EDGE", "face": "ES_SCALARS_FACE"}


def _mesh_arrays(m):
    """(V, F) from an Embedding, a Mesh with positions, or a (V, F) pair."""
    if hasattr(m, "V") and hasattr(m, "F"):
        return m.V, m.F
    if hasattr(m, "vertices") and hasattr(m, "faces"):
        if m.vertices is None:
            raise ValueError("render: the mesh has no positions")
        return m.vertices, m.faces
    V, F = m
    return V, F


def _is_one_mesh(m):
    """An Embedding, a Mesh, or a (V, F) pair of arrays (not a list of meshes)."""
    if hasattr(m, "V") or hasattr(m, "vertices"):
        return True
    if isinstance(m, (list, tuple)) and len(m) == 2 and \
            all(isinstance(x, np.ndarray) for x in m):
        V, F = m
        return V.ndim == 2 and V.shape[-1] == 3 and F.ndim == 2 and \
            np.issubdtype(F.dtype, np.integer)
    return False


def render(meshes, labels=None, scalars=None, scalar_kind="vertex", edges=None, title=None,
           width=480, height=480, ncols=0, view=None, up=None, same_view=False,
           fit_each=False, cmap="viridis", vmin=None, vmax=None, colorbar_label=None,
           orthographic=False, ctx=None):
    """Render one mesh or a list side by side (es_render) and return PNG bytes.

    meshes   an Embedding, a Mesh with positions, a (V, F) pair, or a list of them
    labels   one caption per mesh
    scalars  one array per mesh (or one array for a single mesh): per vertex,
             edge (in the edge order of `edges`, (E, 2); es_mesh_edges order when
             the mesh is an Embedding or Mesh) or face, coloured with `cmap`
             ("viridis", "rdbu", "greys") over vmin..vmax (default: data range)
    view/up  camera direction and screen up (default: es_render_auto_view)
    """
    _need_figures()
    ctx = ctx_of(ctx)
    single = _is_one_mesh(meshes)
    items = [meshes] if single else list(meshes)
    if scalars is not None and single:
        scalars = [scalars]
    n = len(items)
    keep = []
    rm = ffi.new("es_render_mesh[]", n)
    for i, m in enumerate(items):
        V, F = _mesh_arrays(m)
        V = A.f64(V, (None, 3), "vertices")
        F = A.i64(F, (None, 3), "faces")
        keep += [V, F]
        rm[i].nverts, rm[i].nfaces = V.shape[0], F.shape[0]
        pv, pf = A.dptr(V), A.iptr(F)   # the buffers, kept alive: the struct only points
        rm[i].xyz, rm[i].faces = pv, pf
        keep += [pv, pf]
        if labels is not None:
            s = A.cstr(labels[i])
            keep.append(s)
            rm[i].label = s
        if scalars is not None and scalars[i] is not None:
            sc = A.f64(scalars[i], (None,), "scalars")
            rm[i].scalar_kind = getattr(lib, _KINDS[scalar_kind])
            ps = A.dptr(sc)
            rm[i].scalars = ps
            keep += [sc, ps]
            if scalar_kind == "edge":
                ed = edges if edges is not None else getattr(m, "edges", None)
                if ed is None:
                    raise ValueError("render: edge scalars need the edge list (edges=)")
                ed = A.i64(ed, (None, 2), "edges")
                pe = A.iptr(ed)
                rm[i].nedges, rm[i].edges = ed.shape[0], pe
                keep += [ed, pe]
    spec = ffi.new("es_render_spec *")
    lib.es_render_spec_init(spec)
    spec.nmeshes, spec.meshes, spec.ncols = n, rm, ncols
    spec.width, spec.height = width, height
    spec.same_view, spec.fit_each = int(same_view), int(fit_each)
    if orthographic:
        spec.projection = lib.ES_PROJ_ORTHOGRAPHIC
    if view is not None:
        spec.has_view = 1
        spec.view = list(map(float, view))
    if up is not None:
        spec.has_up = 1
        spec.up = list(map(float, up))
    spec.cmap = getattr(lib, _CMAPS[cmap])
    if vmin is not None and vmax is not None:
        spec.vmin, spec.vmax = vmin, vmax
    t = A.cstr(title)
    cl = A.cstr(colorbar_label)
    spec.title, spec.colorbar_label = t, cl
    return _draw(ctx, lib.es_render, spec)


def auto_view(vertices, faces=None, ctx=None):
    """The camera es_render would choose for a mesh: (view, up) unit vectors."""
    ctx = ctx_of(ctx)
    V = A.f64(vertices, (None, 3), "vertices")
    F = A.i64(faces if faces is not None else np.zeros((0, 3)), (None, 3), "faces")
    view, up = ffi.new("double[3]"), ffi.new("double[3]")
    ctx.call(lib.es_render_auto_view, V.shape[0], A.dptr(V), F.shape[0], A.iptr(F), view, up)
    return np.array(list(view)), np.array(list(up))


def _frame(spec, title, xlabel, ylabel, keep):
    for field, text in (("title", title), ("xlabel", xlabel), ("ylabel", ylabel)):
        if text is not None:
            s = A.cstr(text)
            keep.append(s)
            setattr(spec.frame, field, s)


def plot_scatter(x, y, labels=None, title=None, xlabel=None, ylabel=None, legend_title=None,
                 ctx=None):
    """Scatter plot of points coloured by category (es_plot_scatter): PNG bytes."""
    _need_figures()
    ctx = ctx_of(ctx)
    x, y = A.f64(x, (None,), "x"), A.f64(y, (len(x),), "y")
    spec = ffi.new("es_scatter_spec *")
    lib.es_scatter_spec_init(spec)
    keep = []
    _frame(spec, title, xlabel, ylabel, keep)
    px, py = A.dptr(x), A.dptr(y)
    spec.n, spec.x, spec.y = len(x), px, py
    if labels is not None:
        cs = A.CStrings([str(v) for v in labels])
        keep.append(cs)
        spec.labels = cs.ptr
    if legend_title is not None:
        lt = A.cstr(legend_title)
        keep.append(lt)
        spec.legend_title = lt
    return _draw(ctx, lib.es_plot_scatter, spec)


def plot_scree(variance, total=0.0, title=None, ctx=None):
    """Scree plot (es_plot_scree): percent of `total` per component, cumulative
    line; total 0: the sum of those shown. PNG bytes."""
    _need_figures()
    ctx = ctx_of(ctx)
    v = A.f64(variance, (None,), "variance")
    spec = ffi.new("es_scree_spec *")
    lib.es_scree_spec_init(spec)
    keep = []
    _frame(spec, title, None, None, keep)
    pv = A.dptr(v)
    spec.n, spec.variance, spec.total = len(v), pv, float(total)
    return _draw(ctx, lib.es_plot_scree, spec)
