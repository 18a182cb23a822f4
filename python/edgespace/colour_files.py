"""python/edgespace/colour_files.py — meshes for other viewers with their
values on them: per-vertex colours for a PLY (es_meshio_write's vertex_rgb,
coloured by the library's colour maps, es_colormap_rgb) and VTK XML
PolyData (.vtp) with named point and cell arrays, which ParaView colours
itself. The .vtp writer is the VTK file format's ASCII PolyData, written
here because Debian's python3 has no VTK writer the project depends on.
"""
from xml.sax.saxutils import quoteattr

import numpy as np

from ._native import ffi, lib


def scalar_colors(values, cmap="viridis", vmin=None, vmax=None, percentiles=None):
    """(n, 3) uint8 colours of values under a colour map ("viridis", "rdbu",
    "greys": es_colormap_rgb). The range: vmin/vmax, else the percentiles
    (lo, hi) of the finite values (numpy's linear percentiles, as render
    --percentiles), else their full range (symmetric about 0 for rdbu).
    Non-finite values get the library's neutral grey."""
    v = np.asarray(values, dtype=np.float64).ravel()
    m = lib.es_colormap_from_name(str(cmap).encode())
    if m < 0:
        raise ValueError(f"colour map {cmap!r}: one of viridis, rdbu, greys")
    fin = v[np.isfinite(v)]
    lo, hi = (np.percentile(fin, percentiles) if percentiles is not None and fin.size else
              (fin.min(), fin.max()) if fin.size else (0.0, 1.0))
    if cmap == "rdbu" and vmin is None and vmax is None and percentiles is None:
        lo, hi = -max(abs(lo), abs(hi)), max(abs(lo), abs(hi))
    lo = float(lo if vmin is None else vmin)
    hi = float(hi if vmax is None else vmax)
    span = hi - lo if hi > lo else 1.0
    out = np.empty((v.size, 3), dtype=np.uint8)
    rgb = ffi.new("double[3]")
    for i, x in enumerate(v):
        lib.es_colormap_rgb(m, (x - lo) / span if np.isfinite(x) else float("nan"), rgb)
        out[i] = [int(round(255 * c)) for c in rgb]
    return out


def _data_array(name, a):
    a = np.asarray(a)
    kind = "Int64" if np.issubdtype(a.dtype, np.integer) else "Float64"
    ncomp = 1 if a.ndim == 1 else a.shape[1]
    fmt = "%d" if kind == "Int64" else "%.17g"
    body = " ".join(fmt % x for x in a.reshape(-1))
    return (f'<DataArray type="{kind}" Name={quoteattr(str(name))} '
            f'NumberOfComponents="{ncomp}" format="ascii">{body}</DataArray>')


def write_vtp(path, vertices, faces, point_data=None, cell_data=None):
    """A triangle mesh as VTK XML PolyData (ASCII): positions (V, 3), faces
    (F, 3), and arrays by name: point_data {name: (V,) or (V, k)}, cell_data
    {name: (F,) or (F, k)} (residuals, displacements, per-face tests)."""
    X = np.asarray(vertices, dtype=np.float64)
    F = np.asarray(faces, dtype=np.int64)
    if X.ndim != 2 or X.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
        raise ValueError("write_vtp: vertices (V, 3) and faces (F, 3)")
    if F.size and (F.min() < 0 or F.max() >= len(X)):
        raise ValueError("write_vtp: a face names a vertex out of range")
    parts = []
    for what, data, n in (("PointData", point_data, len(X)), ("CellData", cell_data, len(F))):
        arrays = []
        for name, a in (data or {}).items():
            if len(np.asarray(a)) != n:
                raise ValueError(f"write_vtp: {what} '{name}' has {len(np.asarray(a))} "
                                 f"values for {n}")
            arrays.append(_data_array(name, a))
        parts.append(f"<{what}>{''.join(arrays)}</{what}>")
    text = ('<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" '
            'byte_order="LittleEndian">\n<PolyData>\n'
            f'<Piece NumberOfPoints="{len(X)}" NumberOfVerts="0" NumberOfLines="0" '
            f'NumberOfStrips="0" NumberOfPolys="{len(F)}">\n' + parts[0] + "\n" + parts[1] +
            "\n<Points>" + _data_array("Points", X) + "</Points>\n<Polys>" +
            _data_array("connectivity", F.reshape(-1)) +
            _data_array("offsets", 3 * np.arange(1, len(F) + 1)) +
            "</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
