"""python/edgespace/store.py — a shape store (es_store.h) and the analyses on
it (es_study.h): the same calls the `edgespace` command makes, so a result
made here is the result the command would make, stored with its provenance.

Lengths come back as (N, E) float64 arrays written by the library straight
into numpy memory (the E x N column-major matrix of es_store_read_lengths is
that array), positions as (V, 3), labels as arrays of str. Results the
library allocates (a PCA, a comparison) are read-only views that keep their
owner alive.

Linear models (Store.model) come back as a ModelResult whose tables view the
library's arrays, with the summary text the command prints.
"""
import contextlib
import os
import tempfile

import numpy as np

from . import _arrays as A
from ._context import ctx_of
from ._names import renamed
from ._native import ffi, lib
from .mesh import Embedding, Mesh, report_dict, set_embed_opts, study_embedding

_PCA_METHODS = {"auto": "ES_PCA_AUTO", "gram": "ES_PCA_GRAM",
                "covariance": "ES_PCA_COVARIANCE", "randomized": "ES_PCA_RANDOMIZED"}


def _pca_method(method):
    """es_pca_method of a name; a ValueError naming the choices otherwise."""
    if method not in _PCA_METHODS:
        raise ValueError(f"PCA method {method!r}: one of {', '.join(_PCA_METHODS)}")
    return getattr(lib, _PCA_METHODS[method])


def _s(x, name="string"):
    """A str argument as bytes for C (None stays None); NUL refused."""
    return A.cbytes(x, name)


def _c(x):
    """str -> char[] kept by the caller; None -> NULL."""
    return A.cstr(x)


class PCA:
    """A fitted PCA (es_pca): mean (E,), components (K, E) (row k = unit
    component k), eigenvalues (K,), explained (K,), total_variance, scores
    (N, K) of the fitted rows, rows (store rows of the scores, or None)."""

    def __init__(self, ctx, ptr, rows=None):
        self.ctx = ctx
        self._ptr = A.owned(ctx, ptr, lib.es_pca_free)
        p = self._ptr
        E, K, N = int(p.nedges), int(p.ncomp), int(p.nrows)
        self.nedges, self.ncomp, self.nrows = E, K, N
        self.method = ffi.string(ffi.cast("es_pca_method", p.method)).replace("ES_PCA_", "").lower()
        self.total_variance = float(p.total_variance)
        self.mean = A.view(p.mean, (E,), self)
        self.components = A.view(p.components, (K, E), self)
        self.eigenvalues = A.view(p.eigenvalues, (K,), self)
        self.explained = A.view(p.explained, (K,), self)
        # scores are N x K column-major (ld N): the (K, N) C-order array, transposed
        self.scores = A.view(p.scores, (K, N), self).T if N else np.zeros((0, K))
        self.rows = rows

    @property
    def ptr(self):
        return self._ptr

    def project(self, X):
        """Scores (n, K) and residual norms (n,) of length vectors X (n, E)."""
        X = A.f64(np.atleast_2d(X), (None, self.nedges), "X")
        m, keep = A.mat(X)
        scores = np.empty((X.shape[0], self.ncomp))   # K x n column-major
        res = np.empty(X.shape[0])
        self.ctx.call(lib.es_pca_project, self._ptr, m[0], A.dptr(scores), A.dptr(res))
        return scores, res

    def row_weights(self, x=None, ridge_rel=1e-3):
        """Weights (N,) on the fitted rows that reproduce x (es_pca_row_weights)."""
        w = np.empty(self.nrows)
        xp = None if x is None else A.f64(x, (self.nedges,), "x")
        self.ctx.call(lib.es_pca_row_weights, self._ptr, A.dptr(xp), float(ridge_rel),
                      A.dptr(w))
        return w

    def __repr__(self):
        return f"<edgespace.PCA {self.method} E={self.nedges} K={self.ncomp} N={self.nrows}>"


class Result:
    """Plain result holder: attributes named as in es_study.h."""

    def __init__(self, **kw):
        self.__dict__.update(kw)

    def __repr__(self):
        keys = ", ".join(k for k in self.__dict__ if not k.startswith("_"))
        return f"<edgespace.{type(self).__name__} {keys}>"


class MeanResult(Result):
    """groups (list of str), means (G, E), counts (G,), scales (G,)."""


class Diff(Result):
    """mean, sd, se, t (E,), pair_from, pair_to (P,) store rows, unpaired."""


class Point(Result):
    """lengths (E,), scale, weights (N,) row weights, info (dict)."""


class GPAResult(Result):
    """aligned (n, k, d), mean (k, d), size/rho/scale (n,), rotation (n, d, d),
    centroid (n, d), pc_sdev, pc_percent (npc,), pc_scores (n, npc),
    pc_loadings (npc, k, d), report (dict)."""


class CompareResult(Result):
    """Distances in the two spaces and their agreement (es_compare_result)."""


class ModelResult(Result):
    """A linear model with permutation tests (es_study_model): terms (T,),
    df, ss, ms, r2, f, z, p (T,) the ANOVA table (z: RRPP's effect size; p
    and z NaN where untestable), error (T,) each F's error term, dropped
    {term: why} the terms left out as aliased, df_resid, rss, tss,
    coef_names (q,), coef (q, P), coef_weights (q, N), mean (P,), rows (N,)
    store rows; with pairwise= a PairwiseResult `pairwise`; with null= the
    comparison (dict: df, ss, ms, r2, f, z, p); with edges= edge_f/edge_p/
    edge_q (E edges, or k landmarks with gpa=); with log(size) a term cac
    (P,) and cac_scores (N,); summary, the table as `edgespace model`
    prints it (also repr in a notebook); anova() the table as a pandas
    DataFrame (or a dict without pandas)."""

    def anova(self):
        cols = {"term": list(self.terms), "df": self.df, "ss": self.ss, "ms": self.ms,
                "r2": self.r2, "f": self.f, "z": self.z, "p": self.p, "error": self.error}
        return _frame(cols, "term")

    def _repr_pretty_(self, p, cycle):
        p.text(self.summary)


class PairwiseResult(Result):
    """Pairwise comparisons (es_model_pairwise): levels (L,), slopes (bool),
    lsmeans (L, P) the LS means or slopes, weights (L, N), at {variable:
    value} the numeric values of the LS means, confidence; L x L matrices
    d, ucl, z, p, and for slopes r, angle (degrees), angle_ucl, angle_z,
    angle_p, dlength, dlength_ucl, dlength_z, dlength_p; table() a row per
    pair as a DataFrame (or dict), the layout of `model -o`'s pairwise CSV."""

    def table(self):
        L = len(self.levels)
        pairs = [(a, b) for a in range(L) for b in range(a + 1, L)]
        names = ["d", "ucl", "z", "p"] + (["r", "angle", "angle_ucl", "angle_z", "angle_p",
                                           "dlength", "dlength_ucl", "dlength_z", "dlength_p"]
                                          if self.slopes else [])
        cols = {"level_a": [self.levels[a] for a, _ in pairs],
                "level_b": [self.levels[b] for _, b in pairs]}
        for k in names:
            cols[k] = [getattr(self, k)[a, b] for a, b in pairs]
        return _frame(cols, None)


def _frame(cols, index):
    """A pandas DataFrame of the columns (pandas installed), else the dict."""
    try:
        import pandas as pd
    except ImportError:
        return cols
    df = pd.DataFrame(cols)
    return df.set_index(index) if index else df


def ingest(store_path, manifest=None, files=None, create=True, threads=0, ctx=None):
    """Ingest meshes into a store (es_ingest_manifest / es_ingest_files):
    all-or-nothing; returns the report as a dict."""
    ctx = ctx_of(ctx)
    if (manifest is None) == (files is None):
        raise ValueError("ingest: give manifest= or files=")
    o = ffi.new("es_ingest_opts *")
    lib.es_ingest_opts_init(o)
    o.create, o.threads = int(create), A.index(threads, "threads")
    rep = ffi.new("es_ingest_report *")
    if manifest is not None:
        ctx.call(lib.es_ingest_manifest, _s(store_path), _s(manifest), o, rep)
    else:
        fs = A.CStrings([str(f) for f in files])
        ctx.call(lib.es_ingest_files, _s(store_path), len(fs), fs.ptr, o, rep)
    return A.struct_dict(rep, "es_ingest_report")


class Store:
    """An open shape store. Store(path) or Store.open(path, write=False);
    Store.create(path, faces, ...) for a new one. Use as a context manager or
    close(); a write handle publishes its writes at commit() and close()
    (es_store.h: all-or-nothing)."""

    def __init__(self, path, write=False, ctx=None, _ptr=None):
        self.ctx = ctx_of(ctx)
        if _ptr is None:
            p = ffi.new("es_store **")
            mode = lib.ES_STORE_WRITE if write else lib.ES_STORE_READ
            self.ctx.call(lib.es_store_open, _s(path), mode, p)
            _ptr = p[0]
        self._ptr = A.owned(self.ctx, _ptr, lib.es_store_close)
        self.writable = bool(write)
        self._mesh = None
        self._sessions = []   # StudyEmbedder sessions, closed before the store

    open = classmethod(lambda cls, path, write=False, ctx=None: cls(path, write, ctx))

    @classmethod
    def create(cls, path, faces=None, nverts=None, vertices=None, edges=None, ctx=None):
        """A new, empty store: for a mesh topology (faces (F, 3) and nverts or
        reference vertices (V, 3)), or without faces (edges (E, 2) pairs: a
        truss; neither: landmarks only, nverts required). Open for writing;
        appears at path on commit()/close()."""
        ctx = ctx_of(ctx)
        p = ffi.new("es_store **")
        if faces is not None:
            m = Mesh(faces, vertices, nverts, ctx=ctx)
            ctx.call(lib.es_store_create, _s(path), m.ptr, p)
        else:
            if nverts is None:
                raise ValueError("Store.create: nverts is needed without faces")
            ed = A.i64(edges if edges is not None else np.zeros((0, 2)), (None, 2), "edges")
            ctx.call(lib.es_store_create_edges, _s(path), A.index(nverts, "nverts"),
                     ed.shape[0],
                     A.iptr(ed), p)
        return cls(path, True, ctx, _ptr=p[0])

    # -- handle -----------------------------------------------------------
    # Every use of the handle holds the context's lock (Context.hold): a
    # close() from another thread waits for a running call instead of
    # freeing the store under it, and a close() from a callback of a call
    # on it is refused. A call that fails (or whose callback raised) after
    # writing discards what it wrote, unless writes were pending before it.
    def _get(self, fn, *args):
        with self.ctx.hold():
            if self._ptr is None:
                raise ValueError("the store is closed")
            return fn(self._ptr, *args)

    def _get_str(self, fn, *args):
        """A string the store owns, copied while the lock is held (a close
        from another thread frees it)."""
        with self.ctx.hold():
            return A.string(self._get(fn, *args))

    def _call(self, fn, *args):
        with self.ctx.hold():
            if self._ptr is None:
                raise ValueError("the store is closed")
            p = self._ptr
            pending = self.writable and bool(lib.es_store_pending(p))
            try:
                return self.ctx.call(fn, p, *args)
            except BaseException:
                if self.writable and not pending and lib.es_store_pending(p):
                    lib.es_store_rollback(self.ctx.ptr, p)
                raise

    def commit(self):
        """Publish what was written so far (es_store_commit)."""
        self._call(lib.es_store_commit)

    def rollback(self):
        """Discard what was written since the last commit (es_store_rollback)."""
        self._call(lib.es_store_rollback)

    def close(self):
        """Commit (raising its error) and close. Idempotent. Waits for a call
        running in another thread; refused from a callback of a call on it."""
        with self.ctx.closing():
            if self._ptr is None:
                return
            self._close_sessions()
            self._mesh = None     # freed now, while its context lives
            try:
                if self.writable:
                    self.commit()
            finally:
                ffi.release(self._ptr)
                self._ptr = None

    def abort(self):
        """Close, discarding uncommitted writes."""
        with self.ctx.closing():
            if self._ptr is not None:
                self._close_sessions()
                self._mesh = None
                ffi.gc(self._ptr, None)   # no es_store_close at collection
                lib.es_store_abort(self._ptr)
                self._ptr = None

    def __enter__(self):
        return self

    def __exit__(self, et, ev, tb):
        if et is None:
            self.close()
        else:
            self.abort()

    @property
    def ptr(self):
        if self._ptr is None:
            raise ValueError("the store is closed")
        return self._ptr

    # -- shape of the data ------------------------------------------------
    nrows = property(lambda self: int(self._get(lib.es_store_nrows)))
    nedges = property(lambda self: int(self._get(lib.es_store_nedges)))
    nverts = property(lambda self: int(self._get(lib.es_store_nverts)))
    nfaces = property(lambda self: int(self._get(lib.es_store_nfaces)))
    path = property(lambda self: self._get_str(lib.es_store_path))
    fingerprint = property(lambda self: self._get_str(lib.es_store_fingerprint))

    @property
    def topology_kind(self):
        return A.string(lib.es_topology_kind_name(self._get(lib.es_store_topology_kind)))

    @property
    def faces(self):
        """(F, 3) int64 face list."""
        out = np.empty((self.nfaces, 3), dtype=np.int64)
        self._call(lib.es_store_read_faces, A.iptr(out))
        return out

    @property
    def edges(self):
        """(E, 2) int64 edge list (min, max), sorted: column e of the lengths."""
        out = np.empty((self.nedges, 2), dtype=np.int64)
        self._call(lib.es_store_read_edges, A.iptr(out))
        return out

    @property
    def mesh(self):
        """The topology with row 0's positions (a Mesh; cached)."""
        if self._mesh is None:
            p = ffi.new("es_mesh **")
            self._call(lib.es_store_mesh, p)
            self._mesh = Mesh._adopt(self.ctx, p[0])
        return self._mesh

    # -- rows and labels --------------------------------------------------
    @property
    def ids(self):
        """Row ids, an array of str (N,)."""
        return np.array([self._get_str(lib.es_store_row_id, i) for i in range(self.nrows)],
                        dtype=object)

    @property
    def columns(self):
        """Label column names."""
        return [self._get_str(lib.es_store_column_name, c)
                for c in range(self._get(lib.es_store_ncolumns))]

    def label(self, column):
        """The labels of one column, an array of str (N,)."""
        c = self._get(lib.es_store_find_column, _s(column))
        if c < 0:
            from ._errors import NotFoundError
            raise NotFoundError(f"no label column '{column}' in '{self.path}'",
                                lib.ES_ENOTFOUND)
        return np.array([self._get_str(lib.es_store_label, i, c) for i in range(self.nrows)],
                        dtype=object)

    def labels(self):
        """The label table as a dict of arrays: "id", then every column."""
        out = {"id": self.ids}
        for c in self.columns:
            out[c] = self.label(c)
        return out

    def table(self):
        """The label table as a pandas DataFrame (pandas installed) or a dict."""
        t = self.labels()
        try:
            import pandas as pd
        except ImportError:
            return t
        return pd.DataFrame(t)

    def find_row(self, id):
        """Row of an id, or -1."""
        return int(self._get(lib.es_store_find_row, _s(id)))

    def select(self, where=None, filter=None):
        """Rows matching "col=value[,col=value...]" (None: all), int64 array."""
        where = renamed("Store.select", "where", where, "filter", filter)
        rows, n = ffi.new("int64_t **"), ffi.new("int64_t *")
        self._call(lib.es_store_select, _s(where) or ffi.NULL, rows, n)
        return np.array(A.view(rows[0], (n[0],), A.Freed(self.ctx, rows[0]), "i8"))

    def source_path(self, row):
        return self._get_str(lib.es_store_source_path, A.index(row, "row"))

    def content_hash(self, row):
        return self._get_str(lib.es_store_content_hash, A.index(row, "row"))

    # -- data -------------------------------------------------------------
    def _rows(self, rows):
        """rows as (row0, n) for a contiguous range, else an int64 array;
        integers only (a float is refused, not truncated)."""
        N = self.nrows
        if rows is None:
            return (0, N)
        if isinstance(rows, slice):
            start, stop, step = rows.indices(N)
            if step == 1:
                return (start, max(stop - start, 0))
            rows = np.arange(start, stop, step)
        if np.ndim(rows) == 0:
            return (A.index(rows, "row"), 1)
        return A.indices(rows, (None,), "rows")

    def lengths(self, rows=None, out=None):
        """Normalized lengths (n, E) of rows (None: all; a slice, a list of
        rows or one row). out: an (n, E) float64 C-order writable array to
        fill (a read-only array or memory map, bytes, are refused)."""
        r = self._rows(rows)
        n = r[1] if isinstance(r, tuple) else len(r)
        if out is None:
            out = np.empty((n, self.nedges))
        else:
            A.out_array(out, (n, self.nedges))
        m, keep = A.mat(out, writable=True)
        if isinstance(r, tuple):
            self._call(lib.es_store_read_lengths, r[0], r[1], m[0])
        else:
            self._call(lib.es_store_read_lengths_rows, A.iptr(r), len(r), m[0])
        return out

    def scales(self):
        """(N,) scales (sum of raw edge lengths) of all rows."""
        out = np.empty(self.nrows)
        self._call(lib.es_store_read_scales, A.dptr(out))
        return out

    def positions(self, rows=None):
        """Vertex positions as ingested: (V, 3) for one row, (n, V, 3) for
        several (None: all)."""
        if rows is not None and not isinstance(rows, slice) and np.ndim(rows) == 0:
            out = np.empty((self.nverts, 3))
            self._call(lib.es_store_read_positions, A.index(rows, "row"), A.dptr(out))
            return out
        r = self._rows(rows)
        rows = np.arange(r[0], r[0] + r[1]) if isinstance(r, tuple) else r
        out = np.empty((len(rows), self.nverts, 3))
        for j, i in enumerate(rows):
            self._call(lib.es_store_read_positions, int(i), A.dptr(out[j]))
        return out

    def append(self, ids, vertices, labels=None, source_paths=None):
        """Append shapes given as arrays: ids (n str), vertices (n, V, 3) in
        the store's topology, labels {column: n values}. Lengths and scales
        are computed by the library (es_edge_lengths, es_lengths_normalize);
        nothing is written if any row fails (es_store_append). Commit (or
        close) publishes them."""
        X = A.f64(vertices, (None, self.nverts, 3), "vertices")
        n, E = X.shape[0], self.nedges
        if len(ids) != n:
            raise ValueError(f"append: {len(ids)} ids for {n} shapes")
        L, sc = np.empty((n, E)), np.empty(n)
        if E:
            if self.topology_kind == "mesh":
                mesh = self.mesh
                for j in range(n):
                    self.ctx.call(lib.es_edge_lengths, mesh.ptr, A.dptr(X[j]), A.dptr(L[j]))
            else:   # a truss: the stored edge list
                ed = self.edges
                L[:] = np.linalg.norm(X[:, ed[:, 0]] - X[:, ed[:, 1]], axis=2)
            for j in range(n):
                s = ffi.new("double *")
                self.ctx.call(lib.es_lengths_normalize, E, A.dptr(L[j]), A.dptr(L[j]), s)
                sc[j] = s[0]
        cols = list(labels) if labels else []
        cells = [str(labels[c][i]) for i in range(n) for c in cols]
        rows = ffi.new("es_store_rows *")
        cid, ccol, ccell = A.CStrings([str(i) for i in ids]), A.CStrings(cols), \
            A.CStrings(cells)
        csrc = A.CStrings([str(p) for p in source_paths]) if source_paths else None
        pl, ps, px = A.dptr(L), A.dptr(sc), A.dptr(X)
        rows.n, rows.ids, rows.lengths, rows.scales, rows.xyz = n, cid.ptr, pl, ps, px
        rows.ncols, rows.colnames, rows.labels = len(cols), ccol.ptr, ccell.ptr
        if csrc is not None:
            rows.source_paths = csrc.ptr
        self._call(lib.es_store_append, rows)
        self._mesh = None

    # -- stored results ---------------------------------------------------
    def results(self, kind=None):
        """Names of stored results of a kind (None: the kinds present)."""
        names, n = ffi.new("char ***"), ffi.new("int64_t *")
        self._call(lib.es_store_list_results, _s(kind) or ffi.NULL, names, n)
        out = []
        for i in range(n[0]):
            out.append(A.string(names[0][i]))
            lib.es_free(self.ctx.ptr, names[0][i])
        lib.es_free(self.ctx.ptr, names[0])
        return out

    def has(self, path):
        """True if /analysis/<path> exists (a result or one of its datasets)."""
        return bool(self._get(lib.es_store_has, _s(path)))

    def get_matrix(self, path):
        """A stored matrix "<kind>/<name>/<dataset>" as an array of the
        dataset's shape (read-only view of the library's buffer)."""
        m = ffi.new("es_mat *")
        self._call(lib.es_store_get_matrix, _s(path), m)
        return A.view(m.data, (m.cols, m.rows), A.Freed(self.ctx, m.data))

    def get_vector(self, path):
        v, n = ffi.new("double **"), ffi.new("int64_t *")
        self._call(lib.es_store_get_vector, _s(path), v, n)
        return A.view(v[0], (n[0],), A.Freed(self.ctx, v[0]))

    def get_ints(self, path):
        v, n = ffi.new("int64_t **"), ffi.new("int64_t *")
        self._call(lib.es_store_get_ints, _s(path), v, n)
        return A.view(v[0], (n[0],), A.Freed(self.ctx, v[0]), "i8")

    def get_strings(self, path):
        """A stored 1-D string dataset "<kind>/<name>/<dataset>" as a list of str."""
        v, n = ffi.new("char ***"), ffi.new("int64_t *")
        self._call(lib.es_store_get_strings, _s(path), v, n)
        out = []
        for i in range(n[0]):
            out.append(A.string(v[0][i]))
            lib.es_free(self.ctx.ptr, v[0][i])
        lib.es_free(self.ctx.ptr, v[0])
        return out

    def get_attr(self, path, key):
        buf = ffi.new("char[]", 4096)
        self._call(lib.es_store_get_attr, _s(path), _s(key), buf, 4096)
        return ffi.string(buf).decode("utf-8", "replace")

    def delete_result(self, kind, name=None):
        """Delete a stored result: delete_result("pca", "faces") or
        delete_result("pca/faces") (es_store_delete_result), committed.
        NotFoundError naming the results of that kind when there is none."""
        if name is None:
            kind, _, name = str(kind).partition("/")
        self._call(lib.es_store_delete_result, _s(kind), _s(name))
        self.commit()

    @contextlib.contextmanager
    def _replacing(self, replace):
        """With replace, the results written inside may replace those of the
        same name (es_store_set_replace), as the commands' --replace; the
        handle's own mode is restored after."""
        if not replace:
            yield
            return
        with self.ctx.hold():   # another thread's call does not see the mode
            self._call(lib.es_store_set_replace, 1)
            try:
                yield
            finally:
                lib.es_store_set_replace(self.ctx.ptr, self.ptr, 0)

    # -- analyses (es_study.h) ---------------------------------------------
    def _command(self, what):
        return _c(f"python: edgespace.Store.{what}")

    def mean(self, by=None, where=None, name=None, replace=False, filter=None):
        """Means of the rows matching `where`, one per value of label column
        `by` (es_study_mean); stored as mean/<name> when name is given
        (replace=True: over one of that name, as every storing call)."""
        where = renamed("Store.mean", "where", where, "filter", filter)
        o = ffi.new("es_study_mean_opts *")
        lib.es_study_mean_opts_init(o)
        keep = [_c(name or None), _c(where or None), _c(by or None), self._command("mean")]
        o.name, o.where, o.by, o.command = keep
        out = ffi.new("es_group_result **")
        with self._replacing(replace):
            self._call(lib.es_study_mean, o, out)
        r = A.owned(self.ctx, out[0], lib.es_study_group_result_free)
        G, E = int(r.ngroups), int(r.nedges)
        res = MeanResult(groups=[A.string(r.names[g]) for g in range(G)],
                         means=A.view(r.means, (G, E), r),
                         counts=A.view(r.counts, (G,), r, "i8"),
                         scales=A.view(r.scales, (G,), r))
        self._committed(name)
        return res

    def pca(self, name=None, where=None, components=None, method="auto", oversample=10,
            power_iters=4, replace=False, filter=None, ncomp=None):
        """Fit a PCA of the rows matching `where` (es_study_pca), keeping
        `components` (None or 0: all); stored as pca/<name> when name is
        given. Returns a PCA with .rows."""
        where = renamed("Store.pca", "where", where, "filter", filter)
        components = renamed("Store.pca", "components", components, "ncomp", ncomp) or 0
        o = ffi.new("es_study_pca_opts *")
        lib.es_study_pca_opts_init(o)
        keep = [_c(name or None), _c(where or None), self._command("pca")]
        o.name, o.where, o.command = keep
        o.pca.ncomp, o.pca.method = A.index(components, "components"), _pca_method(method)
        o.pca.oversample = A.index(oversample, "oversample")
        o.pca.power_iters = A.index(power_iters, "power_iters")
        out, rows, n = ffi.new("es_pca **"), ffi.new("int64_t **"), ffi.new("int64_t *")
        with self._replacing(replace):
            self._call(lib.es_study_pca, o, out, rows, n)
        r = np.array(A.view(rows[0], (n[0],), A.Freed(self.ctx, rows[0]), "i8"))
        self._committed(name)
        return PCA(self.ctx, out[0], r)

    def load_pca(self, name=None):
        """A stored PCA (es_study_pca_load; None: the only one, else 'default')."""
        out, rows, n = ffi.new("es_pca **"), ffi.new("int64_t **"), ffi.new("int64_t *")
        self._call(lib.es_study_pca_load, _s(name) or ffi.NULL, out, rows, n)
        r = np.array(A.view(rows[0], (n[0],), A.Freed(self.ctx, rows[0]), "i8"))
        return PCA(self.ctx, out[0], r)

    def diff(self, name, pair_by=None, column=None, from_=None, to=None, where=None,
             replace=False, key=None, filter=None):
        """Paired difference to - from of label `column`, rows paired by
        label `pair_by` (es_study_diff; the CLI's --pair-by, --column,
        --from, --to, --where); stored as diff/<name> when name is given."""
        pair_by = renamed("Store.diff", "pair_by", pair_by, "key", key)
        where = renamed("Store.diff", "where", where, "filter", filter)
        o = ffi.new("es_study_diff_opts *")
        lib.es_study_diff_opts_init(o)
        keep = [_c(name or None), _c(where or None), _c(pair_by), _c(column), _c(from_), _c(to),
                self._command("diff")]
        o.name, o.where, o.key, o.column = keep[:4]
        setattr(o, "from", keep[4])   # a Python keyword
        o.to, o.command = keep[5:]
        out = ffi.new("es_diff **")
        with self._replacing(replace):
            self._call(lib.es_study_diff, o, out)
        d = A.owned(self.ctx, out[0], lib.es_diff_free)
        E, P, U = int(d.nedges), int(d.npairs), int(d.nunpaired)
        res = Diff(mean=A.view(d.mean, (E,), d), sd=A.view(d.sd, (E,), d),
                   se=A.view(d.se, (E,), d), t=A.view(d.t, (E,), d),
                   pair_from=A.view(d.pair_from, (P,), d, "i8"),
                   pair_to=A.view(d.pair_to, (P,), d, "i8"),
                   unpaired=A.view(d.unpaired, (U,), d, "i8"), npairs=P)
        self._committed(name)
        return res

    def point(self, expr, name=None, pca=None, scale=0.0, replace=False):
        """Evaluate a point expression (datasets-spec/point-syntax.md) with its
        row weights (es_study_point); stored as point/<name> when name is given.
        Returns a Point: lengths (E,), weights (N,), scale, info (validity)."""
        vec = ffi.new("double **")
        w = np.empty(self.nrows)
        info = ffi.new("es_point_info *")
        o = ffi.new("es_study_point_opts *")
        lib.es_study_point_opts_init(o)
        keep = [_c(name or None), _c(expr), _c(pca or None), self._command("point")]
        o.name, o.expr, o.pca_name, o.command = keep
        o.scale = float(scale)
        with self._replacing(replace):
            self._call(lib.es_study_point, o, vec, A.dptr(w), info)
        lengths = np.array(A.view(vec[0], (self.nedges,), A.Freed(self.ctx, vec[0])))
        inf = A.struct_dict(info, "es_point_info")
        inf["validity"] = A.struct_dict(info.validity, "es_validity")
        self._committed(name)
        return Point(lengths=lengths, weights=w, scale=inf["scale"], info=inf, expr=expr)

    def point_weights(self, spec, pca=None):
        """A point as a command names it ("row:ID", a stored point's name, or
        an expression): lengths, scale and row weights (es_study_point_weights)."""
        L, w, sc = np.empty(self.nedges), np.empty(self.nrows), ffi.new("double *")
        self._call(lib.es_study_point_weights, _s(spec), _s(pca) or ffi.NULL,
                      A.dptr(L), sc, A.dptr(w))
        return Point(lengths=L, weights=w, scale=sc[0], info=None, expr=spec)

    def prior(self, weights):
        """The prior of row weights (N,): dict xyz (V, 3) in the store's frame,
        alpha and sd (E,) (es_study_rows_load + es_study_prior), as
        Embedder.solve(prior=...) takes it."""
        w = A.f64(weights, (self.nrows,), "weights")
        rows = ffi.new("es_study_rows **")
        self._call(lib.es_study_rows_load, self.mesh.ptr, rows)
        r = A.owned(self.ctx, rows[0], lib.es_study_rows_free)
        xyz, alpha, sd = np.empty((self.nverts, 3)), np.empty(self.nedges), np.empty(self.nedges)
        self.ctx.call(lib.es_study_prior, r, A.dptr(w), A.dptr(xyz), A.dptr(alpha), A.dptr(sd))
        return {"xyz": xyz, "alpha": alpha, "sd": sd}

    def nearest_row(self, lengths, rows=None):
        """(row, distance) of the stored row nearest in edge-length distance."""
        L = A.f64(lengths, (self.nedges,), "lengths")
        r = None if rows is None else A.indices(rows, (None,), "rows")
        row, dist = ffi.new("int64_t *"), ffi.new("double *")
        self._call(lib.es_study_nearest_row, A.dptr(L), A.iptr(r),
                      0 if r is None else len(r), row, dist)
        return int(row[0]), float(dist[0])

    def _close_sessions(self):
        for s in self._sessions:
            s.close()
        self._sessions = []

    def embedder(self, cache=True):
        """An embedding session (StudyEmbedder): embed(point, warm=True, fast=...)
        costs only the solve; the mesh, embedder and rows for priors are made
        once (from STORE.es-cache when it is current; cache=False neither
        reads nor writes it). Closed with the store."""
        from .session import StudyEmbedder
        s = StudyEmbedder(self, cache)
        self._sessions.append(s)
        return s

    def embed(self, point, pca=None, init=None, scale=0.0, name=None, output=None,
              residuals=None, warm=False, replace=False, **opts):
        """Embed a point of the store's space (es_study_embed: near the prior
        of its row weights, in the store's frame, unless init names an explicit
        start). Returns Embedding(V, F, report) with report["scale"] and
        report["init"]. name stores /analysis/embed/<name> (write handle);
        output/residuals write the mesh and per-vertex CSV. opts: es_embed_opts.
        The store keeps one embedding session for these calls (made on the
        first, from STORE.es-cache when current), so the next one costs only
        its solve; warm=True starts from the last call's correction of its
        prior (default: from the point's own prior, the same mesh whatever
        came before).

        point may also be an array of E edge lengths (a model's prediction,
        a PCA reconstruction): embedded near the prior of its row weights
        (ridge regression on every row, as a file: point's), at scale (0:
        the lengths' own sum, or for lengths that sum to 1 the rows' mean
        scale); init, name and residuals need a point expression."""
        if not isinstance(point, str):
            if init is not None or name is not None or residuals is not None:
                raise ValueError("embed: init=, name= and residuals= need a point expression; "
                                 "an array of lengths is embedded near its prior only")
            emb = self._embed_lengths(point, scale, warm, opts)
            if output is not None:
                emb.write(output, self.mesh)
            return emb
        o = ffi.new("es_study_embed_opts *")
        lib.es_study_embed_opts_init(o)
        keep = [_c(point), _c(pca), _c(init), _c(name), _c(output), _c(residuals),
                self._command("embed")]
        o.point, o.pca_name = keep[0], keep[1]
        if init is not None:
            o.init = keep[2]
        o.name, o.output, o.residuals, o.command = keep[3], keep[4], keep[5], keep[6]
        o.scale = float(scale)
        if init is None or init == "prior":
            o.session = self._session().ptr   # made again when rows were added
            o.warm = 1 if warm else 0
        set_embed_opts(o.embed, opts)
        xyz = np.empty((self.nverts, 3))
        res = ffi.new("es_study_embed_result *")
        with self._replacing(replace):
            self._call(lib.es_study_embed, o, A.dptr(xyz), res)
        self._committed(name)   # the mesh and residual files appear with it
        return study_embedding(xyz, self.mesh.faces, res)

    def _session(self):
        """The store's embedding session, made again when rows were added."""
        s = getattr(self, "_embed_session", None)
        if s is None or s._ptr is None or s.nrows != self.nrows:
            if s is not None:
                s.close()
            self._embed_session = self.embedder()
        return self._embed_session

    def _embed_lengths(self, lengths, scale, warm, opts):
        L = A.f64(np.ravel(np.asarray(lengths, dtype=np.float64)), (self.nedges,), "lengths")
        if not np.all(np.isfinite(L)) or np.any(L <= 0):
            bad = int(np.flatnonzero(~(np.isfinite(L) & (L > 0)))[0])
            raise ValueError(f"embed: length {bad} (edge {tuple(self.edges[bad])}) is "
                             f"{L[bad]!r}: no mesh realizes lengths that are not positive")
        unit, sc = np.empty_like(L), ffi.new("double *")   # normalized as the library does
        self.ctx.call(lib.es_lengths_normalize, len(L), A.dptr(L), A.dptr(unit), sc)
        total = float(sc[0])
        if scale <= 0:
            scale = float(np.mean(self.scales())) if abs(total - 1) < 1e-9 else total
        w = self._all_rows_pca().row_weights(unit)
        eo = ffi.new("es_embed_opts *")
        lib.es_embed_opts_init(eo)
        set_embed_opts(eo, opts)
        xyz = np.empty((self.nverts, 3))
        res = ffi.new("es_study_embed_result *")
        with self.ctx.hold():   # the store and its session not closed meanwhile
            self.ctx.call(lib.es_study_embedder_solve, self._session().ptr, A.dptr(unit),
                          float(scale), A.dptr(w), eo, 1 if warm else 0, 0, A.dptr(xyz), res)
        return study_embedding(xyz, self.mesh.faces, res)

    def _all_rows_pca(self):
        """A PCA of every row (not stored), for the row weights of lengths."""
        p = getattr(self, "_weights_pca", None)
        if p is None or p.nrows != self.nrows:
            p = self._weights_pca = self.pca()
        return p

    def interp(self, from_=None, to=None, steps=9, t0=0.0, t1=1.0, weights=None, pca=None,
               name=None, output=None, cold=False, replace=False, method="edge-length",
               knn=None, sigma=None, seed=None, tries=None, **opts):
        """A walk from `from_` (t = t0) to `to` (t = t1) in `steps` frames, or one
        weighted combination of rows (weights="0.3*row:a + 0.7*row:b"), each
        frame embedded as es_study_interp embeds it: from the last frame's
        correction of its prior (a warm start), or with cold=True from its own
        prior, as embed() does. Returns a list of Embedding (report["t_heading"]
        says which t). output: a mesh file pattern ("walk_%02d.obj") to keep the
        frames; name stores them.

        method: as `edgespace interp --method`: "edge-length" (the above),
        "multiscale" (Winkler et al. 2010; tries hierarchies from seed on),
        "shape-space" (Wuhrer et al. 2010), "data-driven" and
        "data-driven-el" (Gao et al. 2017; knn neighbours per row, sigma the
        examples' fall-off), "paper" (the published pipeline) or
        "conformal" (from_ mapped to the sphere, t its k; no `to`). The
        other methods join two rows: from_="row:A", to="row:B"."""
        o = ffi.new("es_study_interp_opts *")
        lib.es_study_interp_opts_init(o)
        m = ffi.new("es_morph_method *")
        self.ctx.call(lib.es_morph_method_from_name, _s(str(method)), m)
        o.method = m[0]
        if knn is not None:
            o.path.knn = A.index(knn, "knn")
            if o.path.knn < 1:
                raise ValueError(f"interp: knn={knn!r}; it wants a count >= 1")
        if sigma is not None:
            if not float(sigma) > 0:
                raise ValueError(f"interp: sigma={sigma!r}; it wants a positive number")
            o.path.sigma = float(sigma)
        if tries is not None:
            if not 1 <= int(tries) <= 64:
                raise ValueError(f"interp: tries={tries!r}; it wants 1 .. 64")
            o.multiscale.tries = int(tries)
        frames = []

        def on_frame(ud, i, n, path, heading, report):
            frames.append((int(i), A.string(path), A.string(heading), report_dict(report[0])))

        cb = ffi.callback("es_study_frame_fn", on_frame)
        with tempfile.TemporaryDirectory(prefix="edgespace-interp-") as d:
            pattern = output if output is not None else os.path.join(d, "frame_%04d.ply")
            keep = [_c(from_), _c(to), _c(weights), _c(pca), _c(pattern), _c(name or None),
                    self._command("interp")]
            setattr(o, "from", keep[0])   # a Python keyword
            o.to, o.weights, o.pca_name, o.output, o.name, o.command = keep[1:]
            o.t0, o.t1, o.steps = float(t0), float(t1), A.index(steps, "steps")
            o.cold = 1 if cold else 0
            o.frame = cb
            set_embed_opts(o.embed, opts)
            old_seed = self.ctx.seed
            if seed is not None:   # the multiscale hierarchies' seeds, as --seed
                self.ctx.seed = seed
            try:
                with self._replacing(replace):
                    self._call(lib.es_study_interp, o)
                self._committed(name)   # the frame files appear with it
            finally:
                self.ctx.seed = old_seed
            out = []
            F = self.mesh.faces
            for i, path, heading, rep in sorted(frames):
                rep["heading"] = heading
                out.append(Embedding(self.mesh.read_positions(path), F, rep))
        return out

    def project(self, inputs=(), where=None, pca=None):
        """Scores of row ids / mesh files (and rows matching `where`) on a
        stored PCA (es_study_project): dict names, scores (n, K), residuals."""
        ins = A.CStrings([str(x) for x in inputs])
        out = ffi.new("es_study_projection **")
        self._call(lib.es_study_project, _s(pca) or ffi.NULL, len(ins), ins.ptr,
                      _s(where) or ffi.NULL, out)
        p = A.owned(self.ctx, out[0], lib.es_study_projection_free)
        n, K = int(p.n), int(p.ncomp)
        return {"names": [A.string(p.names[i]) for i in range(n)],
                "scores": np.array(A.view(p.scores, (K, n), p).T),
                "residuals": np.array(A.view(p.residuals, (n,), p))}

    def gpa(self, name, rows=None, scale=True, allow_reflection=False, tol=1e-10,
            max_iter=1000, components=None, replace=False, npc=None):
        """GPA of the rows' positions with the PCA of the tangent coordinates
        (es_study_gpa), stored as gpa/<name> and committed; the stored arrays
        come back in (specimen, landmark, dimension) order."""
        components = renamed("Store.gpa", "components", components, "npc", npc) or 0
        o = ffi.new("es_study_gpa_opts *")
        lib.es_study_gpa_opts_init(o)
        o.gpa.scale, o.gpa.allow_reflection, o.gpa.tol, o.gpa.max_iter = \
            int(scale), int(allow_reflection), float(tol), A.index(max_iter, "max_iter")
        r = None if rows is None else A.indices(rows, (None,), "rows")
        keep = [_c(name if name is not None else ""), self._command("gpa")]   # required
        o.name, o.command = keep
        rp = A.iptr(r)   # kept alive through the call
        o.rows, o.nrows = rp, -1 if r is None else len(r)
        o.npc = A.index(components, "components")
        rep = ffi.new("es_gpa_report *")
        with self._replacing(replace):
            self._call(lib.es_study_gpa, o, rep)
        self.commit()
        return self.load_gpa(name, A.struct_dict(rep, "es_gpa_report"))

    def load_gpa(self, name, report=None):
        """A stored GPA result (see gpa)."""
        g = f"gpa/{name}"
        d, k = int(self.get_attr(g, "dim")), int(self.get_attr(g, "k"))
        n = self.get_matrix(g + "/aligned").shape[0]

        def blocks(a):   # rows of x-block, y-block[, z-block] -> (rows, k, d)
            return np.ascontiguousarray(np.asarray(a).reshape(-1, d, k).transpose(0, 2, 1))
        res = GPAResult(dim=d, k=k, n=n, report=report)
        res.aligned = blocks(self.get_matrix(g + "/aligned"))
        res.mean = blocks(self.get_vector(g + "/mean"))[0]
        for v in ("size", "rho", "scale", "pc_sdev", "pc_percent"):
            setattr(res, v, np.array(self.get_vector(f"{g}/{v}")))
        res.rotation = np.array(self.get_matrix(g + "/rotation")).reshape(n, d, d).transpose(0, 2, 1)
        res.centroid = np.array(self.get_matrix(g + "/centroid"))
        res.pc_scores = np.array(self.get_matrix(g + "/pc_scores"))
        res.pc_loadings = blocks(self.get_matrix(g + "/pc_loadings"))
        return res

    def compare(self, gpa, by=None, permutations=999, top_pairs=20, normalize_lengths=True,
                name=None, out_dir=None, replace=False):
        """Edge-length space against Procrustes space on a stored GPA's rows
        (es_study_compare); stored as compare/<name> (None: not stored) and
        committed; out_dir gets the CSV tables."""
        o = ffi.new("es_study_compare_opts *")
        lib.es_study_compare_opts_init(o)
        o.compare.permutations = A.index(permutations, "permutations")
        o.compare.top_pairs = A.index(top_pairs, "top_pairs")
        o.compare.normalize_lengths = int(normalize_lengths)
        keep = [_c(gpa), _c(by or None), _c(name or None), _c(out_dir or None),
                self._command("compare")]
        o.gpa_name, o.by, o.name, o.out_dir, o.command = keep
        out = ffi.new("es_compare_result **")
        with self._replacing(replace):
            self._call(lib.es_study_compare, o, out)
        r = A.owned(self.ctx, out[0], lib.es_compare_result_free)
        if name:
            self.commit()
        n, T, G = int(r.n), int(r.ntop), int(r.ngroups)
        res = CompareResult(
            n=n, d_len=A.view(r.d_len, (n, n), r).T, d_proc=A.view(r.d_proc, (n, n), r).T,
            mantel_rho=r.mantel_rho, mantel_p=r.mantel_p, nn_agreement=r.nn_agreement,
            nn_len=A.view(r.nn_len, (n,), r, "i8"), nn_proc=A.view(r.nn_proc, (n,), r, "i8"),
            top_pairs=A.view(r.top_pairs, (T, 2), r, "i8"), top_diff=A.view(r.top_diff, (T,), r),
            ids=[A.string(r.ids[i]) for i in range(n)] if r.ids != ffi.NULL else None,
            group=A.view(r.group, (n,), r, "i8") if r.group != ffi.NULL else None,
            group_names=[A.string(r.group_names[g]) for g in range(G)]
            if r.group_names != ffi.NULL else [],
            groups_len=A.struct_dict(r.groups_len, "es_group_stats"),
            groups_proc=A.struct_dict(r.groups_proc, "es_group_stats"))
        # Kendall's rho (unit centroid size) beside the data-unit d_proc
        res.d_rho = A.view(r.d_rho, (n, n), r).T if r.d_rho != ffi.NULL else None
        if G:
            res.mean_len = A.view(r.mean_len, (G, G), r).T
            res.mean_proc = A.view(r.mean_proc, (G, G), r).T
            res.p_len = A.view(r.p_len, (G, G), r).T
            res.p_proc = A.view(r.p_proc, (G, G), r).T
        return res

    def model(self, formula, gpa=None, where=None, block=None, ss_type=1, permute="rrpp",
              permutations=999, contrasts="treatment", pairwise=None, edges=None,
              edge_permutations=-1, name=None, reference=None, slopes=None, at=None,
              errors=None, null=None, seed=None, replace=False):
        """A linear model of the shapes on label columns with permutation
        tests (es_study_model): in edge-length space, or on GPA result
        `gpa`'s aligned coordinates; stored as model/<name> (None: not
        stored) and committed. reference: "LEVEL" or "FACTOR=LEVEL,..."
        baselines; pairwise: a factor whose LS means (or with slopes=VAR its
        slopes on VAR) are compared; at: "NAME=VALUE|mean,..." the LS means'
        covariate values; errors: {"TERM": "ERROR_TERM"} for nested designs;
        null: a nested formula the model is compared with (RRPP's
        anova(null, full)); edges: a term tested per edge (per landmark with
        gpa); seed: of the permutations (None: the context's; the result's
        seed says which). The options are the command's (edgespace model
        --help)."""
        schemes = {"rrpp": lib.ES_PERM_RRPP, "raw": lib.ES_PERM_RAW}
        codings = {"treatment": lib.ES_CONTRASTS_TREATMENT, "sum": lib.ES_CONTRASTS_SUM}
        if permute not in schemes or contrasts not in codings or ss_type not in (1, 2, 3):
            raise ValueError(f"model: permute in {sorted(schemes)}, contrasts in "
                             f"{sorted(codings)}, ss_type in 1, 2, 3")
        keep = [_c(formula), _c(gpa), _c(where), _c(block), _c(pairwise), _c(edges), _c(name),
                self._command("model"), _c(reference), _c(slopes), _c(at), _c(null)]
        o = ffi.new("es_study_model_opts *")
        lib.es_study_model_opts_init(o)
        (o.formula, o.gpa, o.where, o.block, o.pairwise, o.edge_term, o.name,
         o.command, o.reference, o.slopes, o.at, o.null_formula) = keep
        errs = A.CStrings([f"{t}={e}" for t, e in (errors or {}).items()])
        o.errors, o.nerrors = errs.ptr, len(errs)
        o.ss_type, o.scheme, o.contrasts = ss_type, schemes[permute], codings[contrasts]
        o.permutations = A.index(permutations, "permutations")
        o.edge_permutations = A.index(edge_permutations, "edge_permutations")
        out = ffi.new("es_study_model_result **")
        old_seed = self.ctx.seed
        if seed is not None:
            if int(seed) < 1:
                raise ValueError(f"model: seed {seed!r} must be >= 1")
            self.ctx.seed = seed
        try:
            with self._replacing(replace):
                self._call(lib.es_study_model, o, out)
        finally:
            self.ctx.seed = old_seed
        r = A.owned(self.ctx, out[0], lib.es_study_model_free)
        if name:
            self.commit()
        m, d = r.model, r.design
        T, q, P, N = int(m.nterms), int(m.ncoef), int(m.p), int(r.nrows)
        text = ffi.new("char **")
        self.ctx.call(lib.es_study_model_summary, r, text)
        summary = A.string(text[0])
        lib.es_free(self.ctx.ptr, text[0])
        terms = [A.string(d.terms[j]) for j in range(T)]
        res = ModelResult(
            terms=terms, summary=summary,
            error=["Residual" if m.error[j] < 0 else terms[m.error[j]] for j in range(T)],
            dropped={A.string(d.dropped[k]): A.string(d.dropped_why[k])
                     for k in range(int(d.ndropped))},
            df=A.view(m.df, (T,), r, "i8"), ss=A.view(m.ss, (T,), r), ms=A.view(m.ms, (T,), r),
            r2=A.view(m.r2, (T,), r), f=A.view(m.f, (T,), r), p=A.view(m.pval, (T,), r),
            z=A.view(m.z, (T,), r),
            df_resid=int(m.df_resid), rss=m.rss, tss=m.tss, seed=int(m.seed),
            permutations=int(m.permutations),
            coef_names=[A.string(d.colnames[c]) for c in range(q)],
            coef=A.view(m.coef, (P, q), r).T, coef_weights=A.view(m.coef_weights, (q, N), r),
            mean=A.view(m.mean, (P,), r), rows=A.view(r.rows, (N,), r, "i8"))
        if r.edge_f != ffi.NULL:
            K = int(r.ntests)
            res.edge_f, res.edge_p, res.edge_q = (A.view(v, (K,), r)
                                                  for v in (r.edge_f, r.edge_p, r.edge_q))
        if r.pairwise != ffi.NULL:
            res.pairwise = _pairwise(r.pairwise, d, r)
        if r.comparison != ffi.NULL:
            c = r.comparison
            res.comparison = {"null": null, "df": int(c.df), "ss": c.ss, "ms": c.ms, "r2": c.r2,
                              "f": c.f, "z": c.z, "p": c.pval}
        if r.cac != ffi.NULL:
            res.cac, res.cac_scores = A.view(r.cac, (P,), r), A.view(r.cac_scores, (N,), r)
        return res

    # -- files --------------------------------------------------------------
    def export_lengths_csv(self, path, rows=None, raw=False):
        """Rows' lengths as CSV (es_export_lengths_csv; %.17g)."""
        r = None if rows is None else A.indices(rows, (None,), "rows")
        self._call(lib.es_export_lengths_csv, A.iptr(r), -1 if r is None else len(r),
                      int(raw), _s(path))

    def export_meshes(self, directory, rows=None, format=None, fmt=None):
        """Rows' positions as mesh files DIR/<id>.<ext> (es_export_meshes) in
        `format` (the CLI's --format: obj, the default, ply, ply-ascii, off, stl, glb)."""
        format = renamed("Store.export_meshes", "format", format, "fmt", fmt) or "obj"
        r = None if rows is None else A.indices(rows, (None,), "rows")
        f = getattr(lib, "ES_FORMAT_" + format.upper().replace("-", "_"))
        self._call(lib.es_export_meshes, A.iptr(r), -1 if r is None else len(r),
                      _s(directory), f)

    def export_statismo(self, path, pca=None, gpa=None, components=None, sd=1.0,
                        noise_variance=None, ncomp=None, **opts):
        """A statismo shape model of a stored PCA or GPA
        (es_study_export_statismo; datasets-spec/statismo.md; a landmark GPA
        as a POINT_SET model). Returns the report as a dict: kind, and for
        a GPA None where the edge-length linearization's figures (worst
        RMS and bending ratio, nonlinearity) do not apply."""
        o = ffi.new("es_study_statismo_opts *")
        lib.es_study_statismo_opts_init(o)
        keep = [_c(pca), _c(gpa), self._command("export_statismo")]
        o.pca_name, o.gpa_name, o.command = keep
        components = renamed("Store.export_statismo", "components", components, "ncomp",
                             ncomp) or 0
        o.ncomp, o.sd = A.index(components, "components"), float(sd)
        if noise_variance is not None:
            o.noise_variance = float(noise_variance)
        set_embed_opts(o.embed, opts)
        rep = ffi.new("es_study_statismo_report *")
        self._call(lib.es_study_export_statismo, o, _s(path), rep)
        out = A.struct_dict(rep, "es_study_statismo_report")
        out["kind"] = "POLYGON_MESH" if out["nfaces"] else "POINT_SET"
        if gpa is not None:   # the linearization's figures do not apply to a GPA model
            for k in ("worst_rms_ratio", "worst_bend_ratio", "nonlinearity"):
                out[k] = None
        return out

    def _committed(self, name):
        if name:
            self.commit()

    def __repr__(self):
        if self._ptr is None:
            return "<edgespace.Store (closed)>"
        return (f"<edgespace.Store {self.path!r} {self.topology_kind} N={self.nrows} "
                f"V={self.nverts} E={self.nedges}>")


def _pairwise(pw, d, owner):
    """A PairwiseResult viewing es_model_pairwise pw (owned by owner)."""
    L, P, N, V = int(pw.nlevels), int(pw.p), int(pw.n), int(pw.nvars)
    deg = 180.0 / np.pi
    out = PairwiseResult(
        levels=[A.string(pw.levels[k]) for k in range(L)], slopes=bool(pw.slopes),
        confidence=pw.confidence, lsmeans=A.view(pw.lsmeans, (P, L), owner).T,
        weights=A.view(pw.weights, (L, N), owner),
        at={A.string(d.vars[v]): pw.at[v] for v in range(V) if not np.isnan(pw.at[v])})
    for k, ptr in (("d", pw.dist), ("p", pw.pval), ("z", pw.z), ("ucl", pw.ucl)):
        setattr(out, k, A.view(ptr, (L, L), owner))
    if pw.slopes:
        for k in ("vcor", "angle_p", "angle_z", "dlength", "dlength_p", "dlength_z",
                  "dlength_ucl"):
            setattr(out, "r" if k == "vcor" else k, A.view(getattr(pw, k), (L, L), owner))
        out.angle = A.view(pw.angle, (L, L), owner) * deg
        out.angle_ucl = A.view(pw.angle_ucl, (L, L), owner) * deg
    return out
