"""python/edgespace/mpl.py — the package's figures as matplotlib Axes: a PCA
scatter, a scree plot and a mesh view that a notebook user restyles,
combines in subplots and saves in any format matplotlib writes (text stays
text in PDF and SVG).

    import edgespace.mpl as esm
    ax = esm.plot_pca(store, pca="faces", column="expression", pcs=(1, 2))
    esm.plot_scree(store, pca="faces")
    esm.plot_mesh(embedding, scalars=t, scalar_kind="edge", edges=store.edges)

The same figures as edgespace.render's PNGs (es.render, es.plot_scatter,
es.plot_scree), drawn by matplotlib instead of the library's cairo
renderer, with that module's keywords; every number comes from the
library's results. matplotlib (Debian's python3-matplotlib) is imported
when a figure is drawn, so `import edgespace` works without it. Each
function draws into ax= (a new figure's Axes by default: pyplot, shown
inline by Jupyter) and returns the Axes.
"""
import sys

import numpy as np

from ._mesh_view import (BASE_RGB, MPL_CMAPS, NAN_GREY, colour_range, eye_direction,
                         face_values, headlight, view_angles)
from ._native import has
from .render import _mesh_arrays, auto_view
from .store import PCA, Store

DEBIAN_PACKAGE = "python3-matplotlib"
ZOOM = 1.5


def _matplotlib():
    """matplotlib, or an ImportError that says which package to install."""
    try:
        import matplotlib
    except ImportError as e:
        raise ModuleNotFoundError(
            f"edgespace.mpl draws with matplotlib, which {sys.executable} lacks: install "
            f"Debian's {DEBIAN_PACKAGE} (apt-get install {DEBIAN_PACKAGE}; "
            "bash tools/setup.sh installs it)", name="matplotlib") from e
    return matplotlib


def _axes(ax, projection=None, what="plot"):
    """ax, or the Axes of a new pyplot figure."""
    _matplotlib()
    if ax is None:
        import matplotlib.pyplot as plt
        # constrained: room for long axis labels, a legend or colour bar beside
        return plt.figure(layout="constrained").add_subplot(projection=projection)
    if projection == "3d" and getattr(ax, "name", None) != "3d":
        raise ValueError(f"{what}: ax is a 2D Axes; a mesh needs a 3D one "
                         "(fig.add_subplot(projection='3d'))")
    return ax


# -- scatter and PCA -------------------------------------------------------------

def plot_scatter(x, y, labels=None, title=None, xlabel=None, ylabel=None, legend_title=None,
                 ax=None, **scatter_kw):
    """Points coloured by category, as es.plot_scatter: one ax.scatter per
    group (in order of first appearance, the colours of the Axes' cycle),
    and a legend of the groups. scatter_kw go to every ax.scatter."""
    x = np.asarray(x, dtype=np.float64).ravel()
    y = np.asarray(y, dtype=np.float64).ravel()
    if len(x) != len(y):
        raise ValueError(f"plot_scatter: {len(x)} x for {len(y)} y")
    ax = _axes(ax, what="plot_scatter")
    if labels is None:
        ax.scatter(x, y, **scatter_kw)
    else:
        lab = np.array([str(v) for v in labels], dtype=object)
        if len(lab) != len(x):
            raise ValueError(f"plot_scatter: {len(lab)} labels for {len(x)} points")
        _, first = np.unique(lab, return_index=True)
        for group in lab[np.sort(first)]:
            at = lab == group
            ax.scatter(x[at], y[at], label=group, **scatter_kw)
        ax.legend(title=legend_title, loc="upper left", bbox_to_anchor=(1.02, 1),
                  borderaxespad=0)   # beside the points, as es.plot_scatter's
    _label(ax, title=title, xlabel=xlabel, ylabel=ylabel)
    return ax


def _label(ax, **text):
    """Set the texts given; those not given stay as the Axes has them."""
    ax.set(**{k: v for k, v in text.items() if v is not None})


def _fitted(source, pca, what):
    """(PCA or None, Store or None) of plot_pca's and plot_scree's first argument."""
    if isinstance(source, Store):
        return source.load_pca(pca), source
    if pca is not None:
        raise TypeError(f"{what}: pca= names a stored PCA: give the Store as the first argument")
    return (source, None) if isinstance(source, PCA) else (None, None)


def _pc_numbers(pcs, K):
    """Two 1-based component numbers, checked against K."""
    try:
        a, b = pcs
    except (TypeError, ValueError):
        raise TypeError(f"pcs={pcs!r}: want two 1-based component numbers, as (1, 2)") from None
    for k in (a, b):
        if isinstance(k, (bool, np.bool_)) or not isinstance(k, (int, np.integer)):
            raise TypeError(f"pcs={pcs!r}: component numbers are integers")
        if not 1 <= k <= K:
            raise ValueError(f"pcs={pcs!r}: the PCA has {K} components (PC1..PC{K})")
    return int(a), int(b)


def plot_pca(source, pcs=(1, 2), pca=None, column=None, labels=None, where=None,
             explained=None, title=None, legend_title=None, ax=None, **scatter_kw):
    """Scores on two principal components, coloured by a label.

    source   a Store (pca= names its stored PCA; None: the only one, as
             Store.load_pca), a PCA (Store.pca, Store.load_pca, es.pca), or
             an (n, K) array of scores (explained= their fractions (K,))
    pcs      the components, 1-based: (1, 2) is PC1 across, PC2 up
    column   a label column of the store (source a Store): the colours, and
             the legend's title; or labels= one per point
    where    a row filter (Store.select's): only those rows of the PCA

    The axes read "PC1 (54.9 %)": the share of the total variance
    (PCA.explained). Returns the Axes."""
    fit, store = _fitted(source, pca, "plot_pca")
    if fit is not None:
        scores, rows = np.asarray(fit.scores), fit.rows
        if explained is not None:
            raise TypeError("plot_pca: explained= is for an array of scores; a PCA has its own")
        explained = fit.explained
    else:
        scores, rows = np.asarray(source, dtype=np.float64), None
        if scores.ndim != 2:
            raise ValueError(f"plot_pca: scores have shape {scores.shape}, want (n, K)")
    i, j = _pc_numbers(pcs, scores.shape[1])
    if (column is not None or where is not None) and (store is None or rows is None):
        raise ValueError("plot_pca: column= and where= read the store: give the Store "
                         "(plot_pca(store, pca=NAME, ...)); labels= labels the points of a PCA")
    if column is not None:
        if labels is not None:
            raise TypeError("plot_pca: give column= or labels=, not both")
        labels = store.label(column)[rows]
        legend_title = column if legend_title is None else legend_title
    keep = np.ones(len(scores), dtype=bool)
    if where is not None:
        keep = np.isin(rows, store.select(where))
        if not keep.any():
            raise ValueError(f"plot_pca: no row of the PCA matches where={where!r}")
    if labels is not None:
        if len(labels) != len(scores):
            raise ValueError(f"plot_pca: {len(labels)} labels for {len(scores)} scores")
        labels = np.asarray(labels, dtype=object)[keep]
    if explained is not None:
        explained = np.asarray(explained, dtype=np.float64).ravel()
        if len(explained) != scores.shape[1]:
            raise ValueError(f"plot_pca: {len(explained)} explained fractions for "
                             f"{scores.shape[1]} components")
    axis = [f"PC{k}" + (f" ({100 * explained[k - 1]:.1f} %)" if explained is not None else "")
            for k in (i, j)]
    ax = plot_scatter(scores[keep, i - 1], scores[keep, j - 1], labels=labels, title=title,
                      xlabel=axis[0], ylabel=axis[1], legend_title=legend_title, ax=ax,
                      **scatter_kw)
    # scores of lengths that sum to 1 are small (1e-3): a power of ten at the
    # axis's end, not five digits on every tick
    try:
        ax.ticklabel_format(style="sci", scilimits=(-2, 3), useMathText=True)
    except AttributeError:   # ax= came with another tick formatter: kept
        pass
    return ax


def plot_scree(source, total=0.0, pca=None, components=None, title=None, ax=None):
    """Explained variance per component (bars) and cumulative (a line), in
    percent of the total, as es.plot_scree.

    source      a Store (pca= names its stored PCA), a PCA (its eigenvalues
                over its total variance, so the components not kept count),
                or variances (K,) (total: their sum when 0)
    components  how many to show (None: all)
    Returns the Axes."""
    fit, _ = _fitted(source, pca, "plot_scree")
    if fit is not None:
        variance, total = np.asarray(fit.eigenvalues), fit.total_variance
    else:
        variance = np.asarray(source, dtype=np.float64).ravel()
    if variance.size == 0 or not np.all(np.isfinite(variance)) or np.any(variance < 0):
        raise ValueError(f"plot_scree: variances must be finite and >= 0, at least one "
                         f"(got {variance.size})")
    total = float(total) if total else float(variance.sum())
    if not total > 0 or total < variance.sum() * (1 - 1e-12):
        raise ValueError(f"plot_scree: total variance {total:g} is below the sum of the "
                         f"variances {variance.sum():g}")
    if components is not None:
        if isinstance(components, bool) or not isinstance(components, (int, np.integer)) \
                or not 1 <= components <= len(variance):
            raise ValueError(f"plot_scree: components={components!r}: 1..{len(variance)}")
        variance = variance[:components]
    ax = _axes(ax, what="plot_scree")
    from matplotlib.ticker import MaxNLocator
    k = np.arange(1, len(variance) + 1)
    percent = 100 * variance / total
    bars = ax.bar(k, percent, width=0.7, label="per component")
    line, = ax.plot(k, np.cumsum(percent), marker="o", label="cumulative")
    ax.set(xlim=(0.4, len(k) + 0.6), ylim=(0, 100), xlabel="component",
           ylabel="explained variance (%)")
    _label(ax, title=title)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.legend(handles=[bars, line])
    return ax


# -- mesh view -------------------------------------------------------------------

def plot_mesh(mesh, scalars=None, scalar_kind="vertex", edges=None, cmap="viridis", vmin=None,
              vmax=None, percentiles=(2, 98), colorbar_label=None, nan_label="n/a", title=None,
              view=None, up=None, elev=None, azim=None, shade=True, orthographic=False, ax=None,
              **poly_kw):
    """A triangle mesh in a 3D Axes (a Poly3DCollection of its faces), with
    equal scales on its three axes and the coordinate axes hidden
    (ax.set_axis_on() shows them).

    mesh         an Embedding, a Mesh with positions, or a (V, F) pair
    scalars      values per vertex, edge (in the order of `edges`: a Mesh's own
                 edges by default, or edges=store.edges) or face (scalar_kind),
                 coloured by `cmap` (viridis; "rdbu" and "greys" are the
                 library's maps; any matplotlib colour map) with a labelled
                 colour bar. A polygon has one colour: a face shows its value,
                 the mean of its vertices' or of its edges' (es.render
                 interpolates vertex values across a face). Non-finite values
                 are grey, keyed `nan_label`.
    vmin, vmax   the colour range; else the `percentiles` (2nd to 98th by
                 default, `render --percentiles 2,98`: a few extreme values do
                 not leave the rest one colour; None: the full range) of the
                 finite scalars, symmetric about 0 for "rdbu"
    view, up     the camera as es.render takes it (default: es.auto_view's)
    elev, azim   matplotlib's angles (degrees) about the vertical axis, the
                 coordinate axis nearest `up`; given, they replace the camera's
    shade        Lambert shading under a headlight, as es.render's (False:
                 the colour map's colours exactly)
    poly_kw      for the Poly3DCollection (rasterized=True by default: in a
                 PDF or SVG the surface is an image, the text stays text)
    Returns the Axes; the surface is ax.collections[-1]."""
    matplotlib = _matplotlib()
    from matplotlib.colors import Normalize
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    V, F = _mesh_arrays(mesh)
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3 or not np.all(np.isfinite(V)):
        raise ValueError(f"plot_mesh: vertices of shape {V.shape}, want finite (V, 3)")
    if F.ndim != 2 or F.shape[1] != 3 or not np.issubdtype(F.dtype, np.integer):
        raise ValueError(f"plot_mesh: faces of shape {F.shape} ({F.dtype}), want integer (F, 3)")
    if F.size and (F.min() < 0 or F.max() >= len(V)):
        bad = int(np.argwhere((F < 0) | (F >= len(V)))[0, 0])
        raise ValueError(f"plot_mesh: face {bad} {F[bad].tolist()} names a vertex outside "
                         f"0..{len(V) - 1}")
    axis, e, a, roll = _camera(V, F, view, up)
    if elev is not None or azim is not None:
        e, a, roll = e if elev is None else float(elev), a if azim is None else float(azim), 0.0
    ax = _axes(ax, "3d", "plot_mesh")

    if scalars is None:
        rgba = np.tile([*BASE_RGB, 1.0], (len(F), 1))
    else:
        values = face_values(F, scalars, scalar_kind, len(V),
                             edges if edges is not None else getattr(mesh, "edges", None))
        lo, hi = colour_range(scalars, cmap, vmin, vmax, percentiles)
        colours = matplotlib.colormaps[MPL_CMAPS.get(cmap, cmap)] if isinstance(cmap, str) \
            else cmap
        norm = Normalize(lo, hi)
        rgba = colours(norm(np.where(np.isfinite(values), values, lo)))
        rgba[~np.isfinite(values)] = [NAN_GREY, NAN_GREY, NAN_GREY, 1.0]
    if shade:
        rgba[:, :3] *= headlight(V, F, -eye_direction(axis, e, a))[:, None]
    poly_kw.setdefault("rasterized", True)
    poly_kw.setdefault("edgecolors", rgba)     # the polygons' own colour: no seams between them
    poly_kw.setdefault("linewidths", 0.3)
    surface = Poly3DCollection(V[F], facecolors=rgba, **poly_kw)
    ax.add_collection3d(surface)

    # a cube around the mesh's bounding sphere: the mesh stays inside the
    # Axes however it is turned (by elev/azim or by dragging)
    centre = (V.min(0) + V.max(0)) / 2
    half = np.linalg.norm(V - centre, axis=1).max() or 1.0
    ax.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half),
           zlim=(centre[2] - half, centre[2] + half))
    # drawn larger than matplotlib's box, which leaves room for the axes'
    # tick labels (hidden here): the sphere then fills most of the Axes
    ax.set_box_aspect((1, 1, 1), zoom=ZOOM)
    ax.view_init(elev=e, azim=a, roll=roll, vertical_axis=axis)
    if orthographic:
        ax.set_proj_type("ortho")
    ax.set_axis_off()
    _label(ax, title=title)
    if scalars is not None:
        _colour_bar(ax, colours, norm, scalars, values, scalar_kind, colorbar_label, nan_label)
    return ax


def _camera(V, F, view, up):
    """(vertical_axis, elev, azim, roll) of view/up, filled from the
    library's automatic camera (es.auto_view); matplotlib's default where
    the library has no figures."""
    if view is None or up is None:
        if not has("es_render_auto_view"):
            if view is not None or up is not None:
                raise ValueError("plot_mesh: this libedgespace has no figures: give both view= "
                                 "and up=, or elev= and azim=")
            return "z", 30.0, -60.0, 0.0
        auto = auto_view(V, F)
        view = auto[0] if view is None else view
        up = auto[1] if up is None else up
    return view_angles(view, up)


def _colour_bar(ax, colours, norm, scalars, values, kind, label, nan_label):
    """The colour bar beside ax, its ends extended where values lie beyond
    the range, and a key for the grey of non-finite values."""
    from matplotlib.cm import ScalarMappable
    from matplotlib.patches import Patch
    s = np.asarray(scalars, dtype=np.float64).ravel()
    fin = s[np.isfinite(s)]
    low, high = bool(np.any(fin < norm.vmin)), bool(np.any(fin > norm.vmax))
    extend = {(False, False): "neither", (True, False): "min", (False, True): "max",
              (True, True): "both"}[(low, high)]
    mappable = ScalarMappable(norm=norm, cmap=colours)
    mappable.set_array(s)
    if label is None:
        label = {"vertex": "value per vertex", "edge": "value per edge",
                 "face": "value per face"}[kind]
    bar = ax.figure.colorbar(mappable, ax=ax, shrink=0.7, extend=extend, label=label)
    if not np.all(np.isfinite(values)):   # the key under the bar, as es.render draws it
        bar.ax.legend(handles=[Patch(color=(NAN_GREY,) * 3, label=nan_label)],
                      loc="upper left", bbox_to_anchor=(0, -0.06), frameon=False,
                      handlelength=1, handleheight=1)
