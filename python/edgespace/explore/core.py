"""python/edgespace/explore/core.py — what an exploration of a store knows and
computes, shared by the browser page's server (server.py) and the Jupyter
widget (edgespace.widgets): the sliders, the point of a slider position, its
embedding with the heat maps, a row's own mesh, and saving a shape.

A slider position is the point

    mean + sum_k t_k * d_k

over directions d_k: the PCA's components (`pc:K`, t in standard deviations,
as the point syntax reads it), stored paired differences (`diff:NAME`) and
the coefficients of stored linear models in edge-length space
(`coef:MODEL:COEF`). Every point is a combination of stored rows, and so is
each direction: the mean's and each direction's lengths and row weights are
evaluated once, by the library (es_study_point of "MEAN", and of "ROW" and
"ROW + 1*TERM" for one row, the direction being their difference, so that
a direction is what the point syntax means by its leaf to the last bits of
the row's lengths), and a position's
lengths and weights are then sums of arrays, solved directly
(es_study_embedder_solve) without parsing an expression per position. The
expression shown for a position (point_expression) is the same point
written out: `edgespace embed STORE --point EXPR` embeds it, and with the
same options (cold: each position from its own prior; fast: the slider
accuracy, es_embed_opts_fast) to the same vertices (python/tests/
test_explore.py checks it to 1e-9 of the bounding box).

The store is opened read-only; save() opens it for writing only to store
the named point, and commits at once. One thread at a time computes (a lock
serializes callers: the embedding session is single-threaded).
"""
import difflib
import math
import os
import re
import threading
import time
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from .._context import Context
from .._errors import Error, ExistsError
from .._names import renamed
from .._native import has as _has_symbol
from ..render import auto_view
from ..store import Store

# A slider may be moved, or typed, this many times past its range (a PC: +-3
# sd, so +-30 sd); anything beyond is refused as a request, not embedded:
# lengths that far out are not positive and no mesh realizes them.
RANGE_FACTOR = 10.0
NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")
MESH_FORMATS = ("ply", "obj", "off")
# the point syntax's bare words (ID, NAME, VALUE); anything else is quoted
_BARE = re.compile(r"^[A-Za-z0-9_.-]+$")


def has_figures():
    return _has_symbol("es_render")


class RequestError(ValueError):
    """A request the explorer refuses: its message is shown to the user."""


@dataclass
class Direction:
    """One slider: point-syntax term `term` times t, t in [lo, hi]."""
    key: str            # what requests name it by: "pc1", "diff:smile", "coef:m:age"
    term: str           # the point-syntax leaf: "pc:1", "diff:smile", "coef:m:age"
    kind: str           # "pc", "diff" or "coef"
    label: str          # what the page shows: "PC 1 (41.2 %)"
    lo: float
    hi: float
    step: float
    unit: str           # what t counts: "sd", "x difference", ...
    dL: np.ndarray = field(repr=False, default=None)   # (E,) lengths per unit of t
    dw: np.ndarray = field(repr=False, default=None)   # (N,) row weights per unit of t

    def describe(self):
        return {"key": self.key, "term": self.term, "kind": self.kind, "label": self.label,
                "lo": self.lo, "hi": self.hi, "step": self.step, "unit": self.unit}


@dataclass
class Shape:
    """A mesh the explorer shows: positions V (V, 3), the point expression,
    the embedding report (None for a row's own mesh), per-vertex heat maps
    {name: (V,) array}, and the seconds the computation took on the clock
    and of the computing thread's CPU (on a busy machine the first is the
    larger)."""
    V: np.ndarray
    expr: str
    t: dict
    report: dict
    heat: dict
    seconds: float
    row: str = None
    cpu_seconds: float = 0.0

    def realizability(self):
        """None, or the warning the page shows: the point's lengths break the
        triangle inequality on some faces (es_embed_report's n_bad_faces),
        so the embedding realized the nearest lengths that do not
        (n_projected, projection_rms/max)."""
        r = self.report
        if not r or not r.get("n_bad_faces"):
            return None
        n = r["n_bad_faces"]
        msg = (f"not realizable: {n} face{'s break' if n != 1 else ' breaks'} the triangle "
               "inequality")
        if r.get("n_projected"):
            msg += (f"; {r['n_projected']} lengths moved to the nearest realizable ones "
                    f"(RMS {100 * r['projection_rms']:.2g} %, at most "
                    f"{100 * r['projection_max']:.2g} %)")
        return msg


HEAT_MAPS = {
    "displacement": "distance from the mean shape (store units)",
    "deviation": "distance from the prior (% of the bounding-box diagonal)",
}


def quote_word(s):
    """s as an ID, NAME or VALUE of the point syntax (quoted unless bare)."""
    if _BARE.match(s):
        return s
    if '"' in s:
        raise RequestError(f"'{s}' holds a double quote, which the point syntax cannot quote")
    return f'"{s}"'


def mean_expression(store_filter):
    """The point syntax's mean of the rows a store filter ("col=value,...",
    values with ',' quoted) selects: "mean" or "mean[col=value,...]"."""
    if not store_filter:
        return "mean"
    parts, cur, quoted = [], "", False
    for ch in store_filter:
        if ch == '"':
            quoted = not quoted
        elif ch == "," and not quoted:
            parts.append(cur)
            cur = ""
            continue
        cur += ch
    parts.append(cur)
    out = []
    for p in parts:
        col, _, val = p.partition("=")
        out.append(f"{quote_word(col.strip())}={quote_word(val.strip().strip(chr(34)))}")
    return f"mean[{','.join(out)}]"


def format_number(x):
    """The shortest decimal that reads back as x (repr), as the point syntax
    takes it: no sign (the caller writes '+' or '-')."""
    r = repr(abs(float(x)))
    return r[:-2] if r.endswith(".0") else r


def shell_quote(s):
    return "'" + s.replace("'", "'\\''") + "'"


class Explorer:
    """An exploration of the store at `path` (read-only): see the module's
    text. pca: the PCA whose components are sliders (None: the only one, else
    the one named 'default'); pcs: how many of them, the first (0: all; a
    PCA keeps N - 1 by default). warm: each position starts from the last
    one's correction of its prior (a slider's speed); cold (warm=False): each
    from its own prior, as `edgespace embed` does. fast: es_embed_opts_fast
    (the slider accuracy), else the default options."""

    def __init__(self, path, pca=None, warm=True, fast=True, cache=True, pcs=20, log=None,
                 ctx=None):
        self.path = os.path.abspath(str(path))
        self.folder = os.path.dirname(self.path)
        self.warm, self.fast = bool(warm), bool(fast)
        self.ctx = ctx if ctx is not None else Context(progress=None)
        self._log = log or (lambda msg: None)
        self._lock = threading.Lock()
        self.saved = {}      # file name -> path, of the files saved in this session
        self._rows_info = None
        self.store = Store(self.path, ctx=self.ctx)
        try:
            self._load(pca, cache, int(pcs))
        except BaseException:
            self.store.abort()
            raise

    # -- set-up ------------------------------------------------------------
    def _load(self, pca_name, cache, pcs):
        s = self.store
        if s.topology_kind != "mesh":
            raise RequestError(f"'{self.path}' holds {s.topology_kind} data: exploring needs "
                               "a mesh topology (faces) to embed")
        pcas = s.results("pca")
        if not pcas:
            raise RequestError(f"'{self.path}' has no PCA: run `edgespace pca "
                               f"{shell_quote(self.path)} --name NAME` first")
        pca = s.load_pca(pca_name)
        # copies: the fit's memory is the library's, freed here with its context
        # alive, not by a collection at exit in whatever order the objects go
        self.pca = SimpleNamespace(
            ncomp=int(pca.ncomp), eigenvalues=np.array(pca.eigenvalues),
            explained=np.array(pca.explained), scores=np.array(pca.scores),
            rows=None if pca.rows is None else np.array(pca.rows))
        del pca
        self.pca_name = pca_name if pca_name else (pcas[0] if len(pcas) == 1 else "default")
        self.mean_expr = mean_expression(s.get_attr(f"pca/{self.pca_name}", "filter"))
        self.ids = list(s.ids)
        self.row_index = {r: i for i, r in enumerate(self.ids)}
        self.columns = list(s.columns)
        self.labels = {c: list(s.label(c)) for c in self.columns}
        self._log("evaluating the mean and the directions")
        # es_study_point (Store.point, not stored) rather than _weights: it
        # evaluates "mean + 1*TERM" even where a large direction (a subject's
        # coefficient) makes lengths negative, which a point to embed may not
        base = s.point(self.mean_expr, pca=self.pca_name)
        self.L0, self.w0, self.scale0 = base.lengths, base.weights, base.scale
        self.directions = self._pc_directions(pcs) + self._diff_directions() + \
            self._coef_directions()
        # a direction is (ROW + 1*TERM) - ROW: one row is read, where the mean
        # reads them all (on face-study 10 ms a direction rather than 60)
        row = f"row:{quote_word(self.ids[0])}"
        r0 = s.point(row, pca=self.pca_name)
        for d in self.directions:
            p = s.point(f"{row} + 1*{d.term}", pca=self.pca_name)
            d.dL, d.dw = p.lengths - r0.lengths, p.weights - r0.weights
        self.by_key = {d.key: d for d in self.directions}
        self._log("opening the embedding session")
        self.session = s.embedder(cache)
        self.faces = s.faces
        self._log("embedding the mean")
        self.mean_V = None
        self.mean_shape = self._solve({}, warm=False)
        self.mean_V = self.mean_shape.V.copy()
        lo, hi = self.mean_V.min(axis=0), self.mean_V.max(axis=0)
        self.bbox_diagonal = float(np.linalg.norm(hi - lo))
        self.view = None      # the camera the library's renders use, where it has them
        if has_figures():
            d, u = auto_view(self.mean_V, self.faces, ctx=self.ctx)
            self.view = {"dir": [float(x) for x in d], "up": [float(x) for x in u]}

    def _pc_directions(self, pcs):
        p = self.pca
        out = []
        for k in range(p.ncomp if pcs <= 0 else min(pcs, p.ncomp)):
            if not p.eigenvalues[k] > 0:
                continue
            out.append(Direction(f"pc{k + 1}", f"pc:{k + 1}", "pc",
                                 f"PC {k + 1} ({100 * p.explained[k]:.1f} %)", -3.0, 3.0, 0.01,
                                 "sd"))
        return out

    def _diff_directions(self):
        return [Direction(f"diff:{n}", f"diff:{quote_word(n)}", "diff", f"difference {n}",
                          -2.0, 2.0, 0.01, "x the mean difference")
                for n in self.store.results("diff")]

    def _coef_directions(self):
        """Each coefficient of each stored model of the lengths, the intercept
        aside (a shape, not a direction); t in the units of its design column,
        the range +-3 of its standard deviation over the modelled rows (a
        factor level's 0/1 column: about +-1.4, so 1, the level's effect, is
        on the slider)."""
        out = []
        for m in self.store.results("model"):
            g = f"model/{m}"
            try:
                if self.store.get_attr(g, "space") != "lengths":
                    continue
                names = self.store.get_strings(g + "/coef_names")
                design = np.asarray(self.store.get_matrix(g + "/design"))
            except Error:
                continue   # a model stored without them cannot be a slider
            for c, name in enumerate(names):
                if c >= design.shape[0] or name.lower() in ("intercept", "(intercept)"):
                    continue
                sd = float(np.std(design[c], ddof=1)) if design.shape[1] > 1 else 0.0
                r = 3 * sd if sd > 0 and math.isfinite(sd) else 1.0
                step = 10.0 ** math.floor(math.log10(r / 300)) if r > 0 else 0.01
                out.append(Direction(f"coef:{m}:{name}", f"coef:{quote_word(m)}:{name}", "coef",
                                     f"{m}: {name}", -r, r, step, "design units"))
        return out

    # -- what the page shows ---------------------------------------------
    def describe_rows(self):
        """The scatter's data: the PCA's rows (ids), their scores in standard
        deviations (one list per row) and their labels (per column)."""
        if self._rows_info is None:
            p = self.pca
            sd = np.sqrt(np.maximum(p.eigenvalues, 0))
            scores = np.asarray(p.scores)
            rows = p.rows if p.rows is not None else np.arange(scores.shape[0])
            z = scores / np.where(sd > 0, sd, 1.0)
            self._rows_info = {
                "ids": [self.ids[int(i)] for i in rows],
                "scores": [[float(v) for v in r] for r in z],
                "labels": {c: [self.labels[c][int(i)] for i in rows] for c in self.columns}}
        return self._rows_info

    def describe(self):
        """Everything the page or the widget needs once, as JSON-ready data."""
        p = self.pca
        return {
            "store": os.path.basename(self.path), "path": self.path,
            "nrows": len(self.ids), "nverts": int(self.mean_V.shape[0]),
            "nfaces": int(self.faces.shape[0]), "pca": self.pca_name,
            "mean_expr": self.mean_expr, "warm": self.warm, "fast": self.fast,
            "explained": [float(x) for x in p.explained],
            "directions": [d.describe() for d in self.directions],
            "heat_maps": HEAT_MAPS, "columns": self.columns,
            "color_by": self.default_color_column(),
            "rows": self.describe_rows(),
            "bbox_diagonal": self.bbox_diagonal, "formats": list(MESH_FORMATS),
            "view": self.view,
        }

    def default_color_column(self):
        """The label column that colours the scatter first: the one with the
        fewest distinct values but two or more (expression rather than
        subject), else None."""
        counts = [(len(set(self.labels[c])), k, c) for k, c in enumerate(self.columns)]
        counts = [x for x in counts if x[0] >= 2]
        return min(counts)[2] if counts else None

    # -- positions -----------------------------------------------------------
    def coordinates(self, coords):
        """{key: t} of a request, checked: every key a slider, every value a
        finite number within RANGE_FACTOR x its range; RequestError naming
        the first that is not."""
        if coords is None:
            coords = {}
        if not isinstance(coords, dict):
            raise RequestError("coordinates must be an object of slider: number")
        if len(coords) > len(self.directions):
            raise RequestError(f"{len(coords)} coordinates for {len(self.directions)} sliders")
        out = {}
        for key, t in coords.items():
            d = self.by_key.get(key)
            if d is None:
                near = difflib.get_close_matches(str(key), list(self.by_key), n=3)
                hint = f" (did you mean {' or '.join(near)}?)" if near else ""
                raise RequestError(f"no slider '{str(key)[:80]}'{hint}: this store has "
                                   f"{', '.join(list(self.by_key)[:12])}"
                                   f"{' ...' if len(self.by_key) > 12 else ''}")
            if isinstance(t, bool) or not isinstance(t, (int, float)):
                raise RequestError(f"{key}: '{str(t)[:40]}' is not a number")
            t = float(t)
            lim = RANGE_FACTOR * max(abs(d.lo), abs(d.hi))
            if not math.isfinite(t) or abs(t) > lim:
                raise RequestError(f"{key} = {t:g} is outside what can be explored "
                                   f"(|t| <= {lim:g} {d.unit})")
            if t != 0:
                out[key] = t
        return out

    def point_expression(self, coords):
        """The point of checked coordinates in the point syntax."""
        expr = self.mean_expr
        for d in self.directions:
            t = coords.get(d.key, 0.0)
            if t:
                expr += f" {'-' if t < 0 else '+'} {format_number(t)}*{d.term}"
        return expr

    def command_line(self, expr, output="shape.ply"):
        """`edgespace embed` of the point with this explorer's options."""
        cmd = (f"edgespace embed {shell_quote(self.path)} --pca {shell_quote(self.pca_name)} "
               f"--point {shell_quote(expr)} -o {output}")
        return cmd + (" --fast" if self.fast else "")

    def _lengths(self, coords):
        L, w = self.L0.copy(), self.w0.copy()
        for key, t in coords.items():
            d = self.by_key[key]
            L += t * d.dL
            w += t * d.dw
        return L, w

    # -- shapes ----------------------------------------------------------------
    def _solve(self, coords, warm):
        t0, c0 = time.perf_counter(), time.thread_time()
        L, w = self._lengths(coords)
        bad = np.flatnonzero(~(L > 0))
        if bad.size:
            raise RequestError(f"this position has {bad.size} edge length"
                               f"{'s' if bad.size > 1 else ''} <= 0 (edge {bad[0]}): no mesh "
                               "realizes it; move the sliders back")
        emb = self.session.solve(L, self.scale0, w, warm=warm, fast=self.fast)
        heat = {"deviation": 100 * self.session.vertex_deviation(),
                "displacement": np.zeros(emb.V.shape[0]) if self.mean_V is None else
                np.linalg.norm(emb.V - self.mean_V, axis=1)}
        return Shape(emb.V, self.point_expression(coords), dict(coords), emb.report, heat,
                     time.perf_counter() - t0, cpu_seconds=time.thread_time() - c0)

    def embed(self, coords):
        """The Shape of a slider position (coordinates as coordinates() takes
        them), embedded near its prior: warm or cold as the explorer was made."""
        c = self.coordinates(coords)
        with self._lock:
            try:
                return self._solve(c, self.warm)
            except Error as e:
                raise RequestError(f"{self.point_expression(c)}: {e}") from e

    def row_shape(self, row_id):
        """A stored row's own mesh, GPA-aligned into the store's frame (the
        prior of that row alone: its positions as ingested, moved rigidly),
        with its PCA scores as the slider position."""
        if not isinstance(row_id, str) or row_id not in self.row_index:
            near = difflib.get_close_matches(str(row_id), self.ids, n=3)
            hint = f" (did you mean {' or '.join(near)}?)" if near else ""
            raise RequestError(f"no row '{str(row_id)[:80]}'{hint}")
        i = self.row_index[row_id]
        with self._lock:
            t0, c0 = time.perf_counter(), time.thread_time()
            w = np.zeros(len(self.ids))
            w[i] = 1.0
            V = self.session.prior_positions(w)
        t = {}
        rows = list(self.pca.rows) if self.pca.rows is not None else []
        if i in rows:
            j = rows.index(i)
            sd = np.sqrt(np.maximum(self.pca.eigenvalues, 0))
            for d in self.directions:
                k = int(d.term[3:]) - 1 if d.kind == "pc" else -1
                if k >= 0 and sd[k] > 0:
                    t[d.key] = float(self.pca.scores[j, k] / sd[k])
        heat = {"displacement": np.linalg.norm(V - self.mean_V, axis=1)}
        return Shape(V, f"row:{quote_word(row_id)}", t, None, heat,
                     time.perf_counter() - t0, row=row_id, cpu_seconds=time.thread_time() - c0)

    # -- saving ----------------------------------------------------------------
    def save(self, name, shape, format=None, fmt=None):
        """Write shape's mesh to NAME.FORMAT (ply by default; fmt= is the old
        spelling) in the store's folder and store its
        point as /analysis/point/NAME (the store opened for writing only for
        this, and committed). Refused, with nothing written, when the name is
        not a plain file name, the file exists or the store has a point of
        that name; a failed store write removes the mesh it wrote."""
        fmt = renamed("Explorer.save", "format", format, "fmt", fmt) or "ply"
        if fmt not in MESH_FORMATS:
            raise RequestError(f"format '{str(fmt)[:16]}': one of {', '.join(MESH_FORMATS)}")
        path = self._new_file(name, fmt)
        fname = os.path.basename(path)
        with self._lock:
            w = Store(self.path, write=True, ctx=self.ctx)
            try:
                try:
                    self.ctx.call(_result_check, w.ptr, b"point", name.encode())
                except ExistsError as e:
                    raise RequestError(str(e)) from e
                self.store.mesh.write(path, shape.V)
                w.point(shape.expr, name=name, pca=self.pca_name)
                w.close()
            except BaseException:
                w.abort()
                if os.path.exists(path) and fname not in self.saved:
                    os.remove(path)
                raise
        self.saved[fname] = path
        return {"name": name, "file": fname, "path": path, "point": f"point/{name}",
                "expr": shape.expr}

    def _new_file(self, name, ext):
        """The path NAME.EXT in the store's folder, for a name that is a plain
        file name and a file that does not exist yet."""
        if not isinstance(name, str) or not NAME_RE.match(name):
            raise RequestError("a name is 1-64 letters, digits, '_', '-' or '.', starting "
                               "with a letter or digit")
        path = os.path.join(self.folder, f"{name}.{ext}")
        if os.path.lexists(path):
            raise RequestError(f"'{path}' exists: choose another name")
        return path

    def save_png(self, name, png):
        """Write PNG bytes (a view) to NAME.png in the store's folder; refused
        when the file exists."""
        path = self._new_file(name, "png")
        with open(path, "xb") as f:
            f.write(png)
        self.saved[os.path.basename(path)] = path
        return path

    def close(self):
        with self._lock:
            self.store.close()


def _result_check(ctx, store, kind, name):
    from .._native import lib
    return lib.es_store_result_check(ctx, store, kind, name)
