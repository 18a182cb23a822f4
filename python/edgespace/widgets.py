"""python/edgespace/widgets.py — explore a store in Jupyter:

    import edgespace.widgets
    w = edgespace.widgets.explore("faces.h5", pca="faces")   # shows itself in a cell

the controls of `edgespace explore`'s page as ipywidgets (Debian's
python3-ipywidgets; any version from 6 on), over the same Explorer
(edgespace/explore/core.py): a slider per PC (+-3 sd), stored difference and
model coefficient; the point expression and its `edgespace embed` command,
copyable; the PCA scatter by a label column with the current position
marked; a row's own mesh; the heat maps with a colour bar; the
realizability warning; "save this shape" (mesh file + stored point) and the
view as PNG.

The 3D view is drawn by the library's renderer (es_render, cairo) into an
Image widget and turned with azimuth and elevation sliders: a widget that
needs no JavaScript of its own works in JupyterLab, the classic notebook
and Voila alike, with no extension to install and no internet (three.js in
a notebook would need a front-end extension built for each of them). The
embeddings run in a thread of their own, newest position first: a slider
dragged faster than the embeddings answer skips the positions it passed.
"""
import html
import threading

import ipywidgets as W
import numpy as np

from ._errors import Error
from .explore.core import HEAT_MAPS, MESH_FORMATS, Explorer, RequestError
from .render import auto_view, plot_scatter, render
from .store import Store

CURRENT = "(slider position)"


def explore(store, pca=None, pcs=20, warm=True, fast=True, size=480):
    """An ExplorerWidget on `store` (a path, or an open Store whose path is
    opened again read-only: the widget computes in a thread of its own).
    pca: the PCA whose components are sliders, pcs how many; warm/fast: as
    edgespace.explore.Explorer; size: the view's width and height in pixels."""
    path = store.path if isinstance(store, Store) else store
    return ExplorerWidget(Explorer(path, pca=pca, pcs=pcs, warm=warm, fast=fast), size)


def _rotate(v, axis, degrees):
    """v rotated about the unit axis (Rodrigues)."""
    a = np.radians(degrees)
    return v * np.cos(a) + np.cross(axis, v) * np.sin(a) + axis * np.dot(axis, v) * (1 - np.cos(a))


class ExplorerWidget(W.HBox):
    """The explorer as a widget; see the module's text. shape: the Shape on
    view; set(**coords) moves sliders; wait() returns once the newest
    request is drawn; close() ends the thread and the store."""

    def __init__(self, explorer, size=480):
        self.explorer = ex = explorer
        self.size = int(size)
        self.shape = ex.mean_shape
        self._quiet = False             # set while the widget moves its own sliders
        self._cv = threading.Condition()
        self._pending, self._busy, self._closed = None, False, False
        self.sliders = {}
        for d in ex.directions:
            s = W.FloatSlider(value=0.0, min=d.lo, max=d.hi, step=d.step, description=d.label,
                              continuous_update=True, readout_format=".2f",
                              layout=W.Layout(width="440px"))
            s.observe(self._on_slider, names="value")
            self.sliders[d.key] = s
        info = ex.describe()
        pcs = [d for d in ex.directions if d.kind == "pc"]
        self._pcs = pcs
        self.scatter = W.Image(format="png", layout=W.Layout(width="360px"))
        self.sx = W.Dropdown(options=[(d.label, i) for i, d in enumerate(pcs)], value=0,
                             description="x", layout=W.Layout(width="220px"))
        self.sy = W.Dropdown(options=[(d.label, i) for i, d in enumerate(pcs)],
                             value=min(1, len(pcs) - 1), description="y",
                             layout=W.Layout(width="220px"))
        self.color = W.Dropdown(options=[("none", "")] + [(c, c) for c in ex.columns],
                                value=info["color_by"] or "", description="colour")
        self.row = W.Dropdown(options=[CURRENT] + list(ex.ids), value=CURRENT,
                              description="row")
        self.view = W.Image(format="png", width=self.size, height=self.size)
        self.heat = W.Dropdown(options=[("none", "")] + [(v, k) for k, v in HEAT_MAPS.items()],
                               value="", description="heat map")
        self.azimuth = W.FloatSlider(value=0, min=-180, max=180, step=5, description="azimuth",
                                     continuous_update=False)
        self.elevation = W.FloatSlider(value=0, min=-85, max=85, step=5,
                                       description="elevation", continuous_update=False)
        self.expr = W.Text(value=self.shape.expr, description="point",
                           layout=W.Layout(width="100%"))
        self.command = W.Textarea(value=ex.command_line(self.shape.expr),
                                  layout=W.Layout(width="100%", height="48px"))
        self.warning, self.error, self.status = W.HTML(), W.HTML(), W.HTML()
        self.name = W.Text(value="", placeholder="name", description="save as")
        self.format = W.Dropdown(options=list(MESH_FORMATS), value="ply",
                                 layout=W.Layout(width="80px"))
        self.save_button = W.Button(description="save this shape")
        self.png_button = W.Button(description="PNG of the view")
        reset = W.Button(description="back to the mean")
        for w in (self.sx, self.sy, self.color):
            w.observe(lambda ch: self._draw_scatter(), names="value")
        for w in (self.heat, self.azimuth, self.elevation):
            w.observe(lambda ch: self._draw_view(), names="value")
        self.row.observe(self._on_row, names="value")
        self.save_button.on_click(lambda b: self._save())
        self.png_button.on_click(lambda b: self._save_png())
        reset.on_click(lambda b: self.set(**{k: 0.0 for k in self.sliders}))
        self._view0 = None
        if ex.view is not None:
            self._view0 = (np.array(ex.view["dir"]), np.array(ex.view["up"]))
        left = W.VBox([W.HBox([self.sx, self.sy]), self.color, self.scatter, self.row, reset,
                       W.VBox(list(self.sliders.values()))])
        right = W.VBox([self.expr, self.command, self.warning, self.error, self.view,
                        W.HBox([self.heat, self.png_button]),
                        W.HBox([self.azimuth, self.elevation]),
                        W.HBox([self.name, self.format, self.save_button]), self.status],
                       # as wide as the view: the point's box would fill the notebook's
                       # width and run past a classic notebook's cell
                       layout=W.Layout(width=f"{self.size + 40}px"))
        super().__init__([left, right])
        self._thread = threading.Thread(target=self._work, name="edgespace-explore",
                                        daemon=True)
        self._thread.start()
        self._show(self.shape)

    # -- requests ------------------------------------------------------------
    def coordinates(self):
        return {k: s.value for k, s in self.sliders.items() if s.value != 0}

    def set(self, **coords):
        """Move sliders (keys as Explorer.directions' keys: pc1, diff:NAME,
        ...) and embed the position; a value outside a slider's range is
        embedded as asked, or refused with the error shown."""
        c = self.coordinates()
        c.update(coords)
        self._quiet = True
        try:
            for k, v in coords.items():
                s = self.sliders.get(k)
                if s is not None and isinstance(v, (int, float)) and s.min <= v <= s.max:
                    s.value = v
        finally:
            self._quiet = False
        self._request("embed", c)

    def _on_slider(self, change):
        if not self._quiet:
            self._request("embed", self.coordinates())

    def _on_row(self, change):
        if not self._quiet and change["new"] != CURRENT:
            self._request("row", change["new"])

    def _request(self, kind, arg):
        with self._cv:
            self._pending = (kind, arg)
            self._cv.notify_all()

    def wait(self, timeout=60.0):
        """True once no request is pending or running (False on timeout)."""
        with self._cv:
            return self._cv.wait_for(lambda: self._pending is None and not self._busy, timeout)

    def _work(self):
        while True:
            with self._cv:
                self._cv.wait_for(lambda: self._pending is not None or self._closed)
                if self._closed:
                    return
                (kind, arg), self._pending = self._pending, None
                self._busy = True
            try:
                if kind == "row":
                    shape = self.explorer.row_shape(arg)
                else:
                    shape = self.explorer.embed(arg)
                self._show(shape)
            except (RequestError, Error) as e:
                self.error.value = (f'<div style="color:#8a1c12;background:#fdecea;'
                                    f'padding:4px">{html.escape(str(e))}</div>')
            except Exception as e:    # noqa: BLE001 (shown, never the end of the widget)
                self.error.value = f"<pre>{html.escape(type(e).__name__ + ': ' + str(e))}</pre>"
            finally:
                with self._cv:
                    self._busy = False
                    self._cv.notify_all()

    # -- what is shown -----------------------------------------------------------
    def _show(self, shape):
        self.shape = shape
        self.error.value = ""
        if shape.row is not None:
            self._quiet = True
            try:
                for k, s in self.sliders.items():
                    s.value = float(np.clip(shape.t.get(k, 0.0), s.min, s.max))
            finally:
                self._quiet = False
        else:
            self.row.value = CURRENT      # (_on_row asks nothing for it)
        self.expr.value = shape.expr
        self.command.value = self.explorer.command_line(shape.expr)
        w = shape.realizability()
        self.warning.value = (f'<div style="color:#7a4b00;background:#fff4e0;padding:4px">'
                              f'&#9888; {html.escape(w)}</div>' if w else "")
        r = shape.report
        self.status.value = html.escape(
            f"edge lengths: RMS {100 * r['rms_ratio']:.3g} %, max {100 * r['max_rel']:.3g} %, "
            f"{r['lg_iters']} iterations, bending {r['bend_ratio']:.3g} x the prior's, "
            f"{1000 * shape.seconds:.0f} ms" if r else
            f"row {shape.row} as ingested, aligned into the store's frame")
        self._draw_view()
        self._draw_scatter()

    def _camera(self):
        if self._view0 is None:
            d, u = auto_view(self.explorer.mean_V, self.explorer.faces, ctx=self.explorer.ctx)
            self._view0 = (d, u)
        d, u = self._view0
        d = _rotate(d, u, self.azimuth.value)
        right = np.cross(d, u)
        right /= np.linalg.norm(right)
        return _rotate(d, right, self.elevation.value), _rotate(u, right, self.elevation.value)

    def render_png(self):
        """The view as PNG bytes (es_render): the mesh, its heat map and colour bar."""
        s, name = self.shape, self.heat.value
        view, up = self._camera()
        heat = s.heat.get(name) if name else None
        return render((s.V, self.explorer.faces), scalars=heat, view=view, up=up,
                      width=self.size, height=self.size, title=s.expr,
                      colorbar_label=HEAT_MAPS[name] if heat is not None else None,
                      ctx=self.explorer.ctx)

    def _draw_view(self):
        self.view.value = bytes(self.render_png())

    def _draw_scatter(self):
        ex, info = self.explorer, self.explorer.describe_rows()
        if not self._pcs:
            return
        i, j = self._pcs[self.sx.value], self._pcs[self.sy.value]
        x = [r[int(i.term[3:]) - 1] for r in info["scores"]] + [self.shape.t.get(i.key, 0.0)]
        y = [r[int(j.term[3:]) - 1] for r in info["scores"]] + [self.shape.t.get(j.key, 0.0)]
        col = self.color.value
        labels = (list(info["labels"][col]) if col else ["row"] * len(info["ids"])) + [CURRENT]
        self.scatter.value = bytes(plot_scatter(
            np.array(x), np.array(y), labels=labels, xlabel=f"{i.label} (sd)",
            ylabel=f"{j.label} (sd)", legend_title=col or None, ctx=ex.ctx))

    # -- saving ------------------------------------------------------------------------
    def _save(self):
        try:
            out = self.explorer.save(self.name.value, self.shape, self.format.value)
        except (RequestError, Error) as e:
            self.error.value = (f'<div style="color:#8a1c12;background:#fdecea;'
                                f'padding:4px">{html.escape(str(e))}</div>')
            return None
        self.status.value = html.escape(f"saved {out['path']} and /analysis/{out['point']}")
        return out

    def _save_png(self):
        name = self.name.value or "edgespace-explore"
        try:
            path = self.explorer.save_png(name, bytes(self.render_png()))
        except RequestError as e:
            self.error.value = f'<div style="color:#8a1c12">{html.escape(str(e))}</div>'
            return None
        self.status.value = html.escape(f"saved {path}")
        return path

    def close(self):
        with self._cv:
            self._closed = True
            self._cv.notify_all()
        self._thread.join()
        self.explorer.close()
        super().close()
