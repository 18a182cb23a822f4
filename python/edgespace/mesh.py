"""python/edgespace/mesh.py — topology, edge lengths and embedding on arrays.

Mesh wraps es_mesh (es_mesh.h): faces (F, 3) int64, optional reference
positions (V, 3). Embedder wraps es_embedder (es_embed.h): made once per
topology, it realizes edge-length vectors as meshes (es_embed_solve, or
es_embed_prior_solve near a prior), and reuses its factorizations across
solves. An Embedding is the result: V (V, 3), F (F, 3) and the report as a
dict; `V, F, report = ...` unpacks it and Jupyter draws it (_repr_png_).
"""
from typing import NamedTuple

import numpy as np

from . import _arrays as A
from ._context import ctx_of
from ._names import renamed
from ._native import ffi, lib

_DIHEDRAL = {"auto": "ES_EMBED_DIHEDRAL_AUTO", "on": "ES_EMBED_DIHEDRAL_ON",
             "off": "ES_EMBED_DIHEDRAL_OFF"}
EMBED_OPTIONS = tuple(name for name, _ in ffi.typeof("es_embed_opts").fields)


def embed_opts(**kw):
    """An es_embed_opts with the library's defaults (es_embed_opts_init) and
    the fields named in kw set (es_embed.h documents each; dihedral_mode may
    be "auto", "on" or "off")."""
    o = ffi.new("es_embed_opts *")
    lib.es_embed_opts_init(o)
    set_embed_opts(o, kw)
    return o


def set_embed_opts(o, kw):
    for k, v in kw.items():
        if k not in EMBED_OPTIONS:
            raise TypeError(f"unknown embedding option {k!r} (es_embed_opts has: "
                            f"{', '.join(EMBED_OPTIONS)})")
        if k == "dihedral_mode" and isinstance(v, str):
            v = getattr(lib, _DIHEDRAL[v])
        setattr(o, k, v)


def report_dict(rep):
    """An es_embed_report as a dict of its fields (es_embed.h)."""
    return A.struct_dict(rep, "es_embed_report")


class Embedding(NamedTuple):
    """An embedded mesh: V (V, 3) positions, F (F, 3) faces, report (dict of
    es_embed_report's fields, plus scale and init for store points)."""
    V: np.ndarray
    F: np.ndarray
    report: dict

    def __repr__(self):   # a notebook's text/plain: not every coordinate
        r = self.report
        rms = r.get("rms_ratio")
        return (f"<edgespace.Embedding V={self.V.shape[0]} F={self.F.shape[0]}"
                + (f" rms_ratio={rms:.3g}" if isinstance(rms, float) else "") + ">")

    def render(self, **kw):
        """PNG bytes of this mesh (edgespace.render)."""
        from .render import render
        return render(self, **kw)

    def _repr_png_(self):
        from ._native import has
        return bytes(self.render(width=360, height=360)) if has("es_render") else None

    def write(self, path, mesh=None, ctx=None):
        """Write the mesh file (OBJ/PLY/OFF by extension; es_meshio_write)."""
        m = mesh if mesh is not None else Mesh(self.F, ctx=ctx)
        m.write(path, self.V)


def study_embedding(xyz, faces, res):
    """Embedding of an es_study_embed_result: its report with scale and init."""
    rep = report_dict(res.report)
    rep["scale"] = float(res.scale)
    rep["init"] = ffi.string(res.init).decode("utf-8", "replace")
    return Embedding(xyz, faces, rep)


# es_meshio_write's formats (es_io.h's es_format), as the CLI's --format names them
FORMATS = ("auto", "obj", "ply", "ply-ascii", "off", "stl", "glb")


class Mesh:
    """A triangle mesh topology (es_mesh_new): faces (F, 3) int64, 0-based,
    counter-clockwise; vertices (V, 3) reference positions or None.
    nverts defaults to 1 + the largest index (or the rows of vertices)."""

    def __init__(self, faces, vertices=None, nverts=None, ctx=None):
        self.ctx = ctx_of(ctx)
        F = A.i64(faces, (None, 3), "faces")
        V = None if vertices is None else A.f64(vertices, (None, 3), "vertices")
        if nverts is None:
            nverts = V.shape[0] if V is not None else (int(F.max()) + 1 if F.size else 0)
        p = ffi.new("es_mesh **")
        self.ctx.call(lib.es_mesh_new, A.index(nverts, "nverts"), F.shape[0], A.iptr(F),
                      A.dptr(V), p)
        self._ptr = A.owned(self.ctx, p[0], lib.es_mesh_free)

    @classmethod
    def _adopt(cls, ctx, ptr):
        m = cls.__new__(cls)
        m.ctx = ctx
        m._ptr = A.owned(ctx, ptr, lib.es_mesh_free)
        return m

    @property
    def ptr(self):
        return self._ptr

    nverts = property(lambda self: int(lib.es_mesh_nverts(self._ptr)))
    nfaces = property(lambda self: int(lib.es_mesh_nfaces(self._ptr)))
    nedges = property(lambda self: int(lib.es_mesh_nedges(self._ptr)))

    @property
    def faces(self):
        """(F, 3) int64, read-only view of the mesh's face list."""
        return A.view(lib.es_mesh_faces(self._ptr), (self.nfaces, 3), self, "i8")

    @property
    def edges(self):
        """(E, 2) int64: edge e joins edges[e] (min, max), sorted (es_mesh.h)."""
        return A.view(lib.es_mesh_edges(self._ptr), (self.nedges, 2), self, "i8")

    @property
    def vertices(self):
        """(V, 3) reference positions, or None."""
        p = lib.es_mesh_xyz(self._ptr)
        return None if p == ffi.NULL else A.view(p, (self.nverts, 3), self)

    def summary(self):
        """Counts, boundary loops, components, Euler characteristic, genus."""
        s = ffi.new("es_mesh_summary *")
        lib.es_mesh_summarize(self._ptr, s)
        return A.struct_dict(s, "es_mesh_summary")

    def edge_lengths(self, vertices=None):
        """(E,) edge lengths of positions (V, 3) (default: the reference)."""
        V = self._positions(vertices)
        out = np.empty(self.nedges)
        self.ctx.call(lib.es_edge_lengths, self._ptr, A.dptr(V), A.dptr(out))
        return out

    def dihedral_angles(self, vertices=None):
        """(E,) signed bending angles (es_geom.h; 0 flat, 0 on the boundary)."""
        V = self._positions(vertices)
        out = np.empty(self.nedges)
        self.ctx.call(lib.es_dihedral_angles, self._ptr, A.dptr(V), A.dptr(out))
        return out

    def check_lengths(self, lengths, rtol=0.0):
        """Where a length vector leaves the realizable region (es_lengths_check)."""
        L = A.f64(lengths, (self.nedges,), "lengths")
        v = ffi.new("es_validity *")
        self.ctx.call(lib.es_lengths_check, self._ptr, A.dptr(L), float(rtol), v)
        return A.struct_dict(v, "es_validity")

    def length_error(self, vertices, target, normalize=True):
        """(rms_ratio, max_rel, p99_rel) of positions against target lengths."""
        V = self._positions(vertices)
        T = A.f64(target, (self.nedges,), "target")
        out = ffi.new("double[3]")
        self.ctx.call(lib.es_embed_length_error, self._ptr, A.dptr(V), A.dptr(T),
                      int(normalize), out, out + 1, out + 2)
        return tuple(out)

    def write(self, path, vertices=None, format=None, colors=None, fmt=None):
        """Write a mesh file (es_meshio_write: OBJ, PLY, OFF with exact
        coordinates; STL, GLB in float32 for viewers) in `format` (the CLI's
        --format; default "auto": from the extension; fmt= is the old
        spelling). colors: (V, 3)
        per-vertex colours, uint8 or floats in [0, 1] (PLY and GLB; see
        edgespace.scalar_colors for values under a colour map)."""
        fmt = renamed("Mesh.write", "format", format, "fmt", fmt) or "auto"
        V = None if vertices is None else self._positions(vertices)
        f = getattr(lib, "ES_FORMAT_" + str(fmt).upper().replace("-", "_"), None)
        if f is None:
            raise ValueError(f"Mesh.write: format '{str(fmt)[:16]}': one of {', '.join(FORMATS)}")
        rgb = ffi.NULL
        if colors is not None:
            c = np.asarray(colors)
            if c.shape != (self.nverts, 3):
                raise ValueError(f"colors: shape {c.shape}, want ({self.nverts}, 3)")
            if not np.issubdtype(c.dtype, np.integer):
                c = np.round(np.clip(c, 0, 1) * 255)
            c = np.ascontiguousarray(c, dtype=np.uint8)
            rgb = ffi.from_buffer("uint8_t[]", c)
        self.ctx.call(lib.es_meshio_write, A.cbytes(path, "path"), f, self._ptr, A.dptr(V), rgb)

    def read_positions(self, path):
        """(V, 3) positions of a mesh file with this face list."""
        out = np.empty((self.nverts, 3))
        self.ctx.call(lib.es_meshio_read_positions, self._ptr, A.cbytes(path, "path"),
                      A.dptr(out))
        return out

    def _positions(self, vertices):
        if vertices is None:
            V = self.vertices
            if V is None:
                raise ValueError("the mesh has no reference positions: give vertices")
            return np.ascontiguousarray(V)
        return A.f64(vertices, (self.nverts, 3), "vertices")

    def __repr__(self):
        return f"<edgespace.Mesh V={self.nverts} F={self.nfaces} E={self.nedges}>"


def read_mesh(path, ctx=None):
    """A mesh file (OBJ, PLY, OFF) as a Mesh with its positions (es_meshio_read)."""
    ctx = ctx_of(ctx)
    p = ffi.new("es_mesh **")
    ctx.call(lib.es_meshio_read, A.cbytes(path, "path"), p)
    return Mesh._adopt(ctx, p[0])


def normalize_lengths(lengths, ctx=None):
    """(lengths / sum, sum): scale-normalized lengths and the scale."""
    ctx = ctx_of(ctx)
    L = A.f64(lengths, (None,), "lengths")
    out, sc = np.empty_like(L), ffi.new("double *")
    ctx.call(lib.es_lengths_normalize, len(L), A.dptr(L), A.dptr(out), sc)
    return out, sc[0]


class Embedder:
    """An embedder for one topology (es_embedder_new): holds the symbolic
    factorizations and work buffers that every solve reuses. Threads that
    share one take turns (its context's lock); for solves in parallel give
    each thread its own Embedder and Context."""

    def __init__(self, mesh, ctx=None):
        self.mesh = mesh if isinstance(mesh, Mesh) else Mesh(mesh, ctx=ctx)
        self.ctx = ctx_of(ctx) if ctx is not None else self.mesh.ctx
        p = ffi.new("es_embedder **")
        self.ctx.call(lib.es_embedder_new, self.mesh.ptr, p)
        self._ptr = A.owned(self.ctx, p[0], lib.es_embedder_free)

    def solve(self, lengths, scale=0.0, init_vertices=None, init_dihedrals=None, prior=None,
              **opts):
        """Embed target lengths (E,). Without a prior: es_embed_solve from
        init_vertices (V, 3) and/or init_dihedrals (E,), one of which is needed
        (default: the mesh's reference positions). With prior=(xyz, alpha, sd)
        (or a dict with those keys; alpha and sd may be None): es_embed_prior_solve.
        scale > 0 embeds at that sum of lengths (0: the target's own).
        opts: es_embed_opts fields. Returns an Embedding."""
        m = self.mesh
        T = A.f64(lengths, (m.nedges,), "lengths")
        out = np.empty((m.nverts, 3))
        rep = ffi.new("es_embed_report *")
        o = embed_opts(**opts)
        if prior is not None:
            if isinstance(prior, dict):
                prior = (prior["xyz"], prior.get("alpha"), prior.get("sd"))
            xyz, alpha, sd = (tuple(prior) + (None, None))[:3]
            X = A.f64(xyz, (m.nverts, 3), "prior xyz")
            Al = None if alpha is None else A.f64(alpha, (m.nedges,), "prior alpha")
            Sd = None if sd is None else A.f64(sd, (m.nedges,), "prior sd")
            pr = ffi.new("es_embed_prior *")
            bufs = (A.dptr(X), A.dptr(Al), A.dptr(Sd))
            pr.xyz, pr.alpha, pr.sd = bufs
            self.ctx.call(lib.es_embed_prior_solve, self._ptr, A.dptr(T), float(scale), pr, o,
                          A.dptr(out), rep)
        else:
            IV = None if init_vertices is None else A.f64(init_vertices, (m.nverts, 3),
                                                           "init_vertices")
            IA = None if init_dihedrals is None else A.f64(init_dihedrals, (m.nedges,),
                                                            "init_dihedrals")
            if IV is None and IA is None:
                IV = m._positions(None)
            self.ctx.call(lib.es_embed_solve, self._ptr, A.dptr(T), float(scale), A.dptr(IA),
                          A.dptr(IV), o, A.dptr(out), rep)
        return Embedding(out, np.array(m.faces), report_dict(rep[0]))

    def vertex_closure(self):
        """(V,) closure residual per vertex of the last solve (None before)."""
        return self._per_vertex(lib.es_embedder_vertex_closure)

    def vertex_edge_error(self):
        """(V,) mean relative edge error around each vertex, last solve."""
        return self._per_vertex(lib.es_embedder_vertex_edge_error)

    def vertex_deviation(self):
        """(V,) distance from the prior's realization / bbox diagonal (after a
        prior solve; None otherwise)."""
        return self._per_vertex(lib.es_embedder_vertex_deviation)

    def _per_vertex(self, fn):
        with self.ctx.hold():   # not while another thread's solve rewrites it
            p = fn(self._ptr)
            if p == ffi.NULL:
                return None
            return np.array(A.view(p, (self.mesh.nverts,), self))   # copy: valid until next solve


def embed(lengths, mesh, scale=0.0, init_vertices=None, init_dihedrals=None, prior=None,
          ctx=None, **opts):
    """Embed one length vector on `mesh` (a Mesh or faces (F, 3)); see
    Embedder.solve. For many solves on one topology make an Embedder."""
    return Embedder(mesh, ctx=ctx).solve(lengths, scale, init_vertices, init_dihedrals, prior,
                                         **opts)
