"""python/edgespace/_mesh_view.py — the numbers behind a matplotlib mesh view
(edgespace.mpl.plot_mesh), kept apart from the drawing and free of
matplotlib: the camera of es.render as matplotlib's view angles, the value
each face shows, the colour range, and the headlight shading. Each follows
the library's renderer (lib/figure/render.c) so that the two routes agree.
"""
import numpy as np

# es_plot.h's ES_NAN_GREY: the grey of non-finite scalars in every figure;
# es_render_spec_init's base_rgb: a surface without scalars (render.c)
NAN_GREY = 0.6
BASE_RGB = (0.80, 0.76, 0.70)

# the library's colour maps by matplotlib's names: RdBu reversed so that low
# is blue, and greys from black (low) to white (lib/figure/plot_canvas.c)
MPL_CMAPS = {"viridis": "viridis", "rdbu": "RdBu_r", "greys": "gray"}


def view_angles(view, up):
    """matplotlib's (vertical_axis, elev, azim, roll), in degrees, of the
    camera that looks along `view` with `up` upward on the screen (the
    vectors of es.auto_view and es.render's view=, up=).

    The vertical axis is the coordinate axis nearest `up`, so that turning
    the view by elev/azim (or by dragging) turns about the mesh's own up.
    matplotlib puts the eye at the direction p = (cos e cos a, cos e sin a,
    sin e), rolled so that its third entry lies on the vertical axis, and
    screen up at the vertical axis turned by -roll about the eye direction
    (mpl_toolkits.mplot3d Axes3D.get_proj, proj3d.view_transformation);
    those are solved for here. Needs equal data spans on all axes (the mesh
    view's cube), where directions are not distorted."""
    view = np.asarray(view, dtype=np.float64)
    up = np.asarray(up, dtype=np.float64)
    if not (np.all(np.isfinite(view)) and np.all(np.isfinite(up))):
        raise ValueError(f"view {view.tolist()} and up {up.tolist()} must be finite")
    if not (np.linalg.norm(view) > 0 and np.linalg.norm(up) > 0):
        raise ValueError(f"view {view.tolist()} and up {up.tolist()}: want non-zero vectors")
    n = -view / np.linalg.norm(view)              # from the centre towards the eye
    up_screen = up - (up @ n) * n
    if not np.linalg.norm(up_screen) > 1e-9 * np.linalg.norm(up):
        raise ValueError(f"view {view.tolist()} and up {up.tolist()} are parallel")
    up_screen /= np.linalg.norm(up_screen)
    axis = int(np.argmax(np.abs(up_screen)))
    p = np.roll(n, 2 - axis)                      # the eye direction in matplotlib's frame
    elev = np.degrees(np.arcsin(np.clip(p[2], -1.0, 1.0)))
    azim = np.degrees(np.arctan2(p[1], p[0]))
    vertical = np.zeros(3)
    vertical[axis] = 1.0
    u = np.cross(vertical, n)
    v0 = np.cross(n, u / np.linalg.norm(u))       # screen up at roll 0
    turn = np.arctan2(n @ np.cross(v0, up_screen), v0 @ up_screen)
    return "xyz"[axis], float(elev), float(azim), float(-np.degrees(turn))


def eye_direction(vertical_axis, elev, azim):
    """The unit vector from the centre towards matplotlib's eye for view
    angles in degrees about the vertical axis ("x", "y" or "z")."""
    e, a = np.radians(elev), np.radians(azim)
    p = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    return np.roll(p, "xyz".index(vertical_axis) - 2)


def face_values(faces, scalars, kind, nverts, edges=None):
    """The value each face shows: its own (kind "face"), the mean of its
    three vertices' ("vertex": matplotlib colours a polygon with one colour,
    where es.render interpolates across it) or of its three edges' ("edge",
    as es.render). A face with a non-finite value among them gets NaN."""
    F = np.asarray(faces, dtype=np.int64)
    s = np.asarray(scalars, dtype=np.float64).ravel()
    if kind == "face":
        want = len(F)
    elif kind == "vertex":
        want = nverts
    elif kind == "edge":
        if edges is None:
            raise ValueError("plot_mesh: edge scalars need the edge list (edges=)")
        edges = np.asarray(edges, dtype=np.int64)
        if edges.ndim != 2 or edges.shape[1] != 2:
            raise ValueError(f"plot_mesh: edges has shape {edges.shape}, want (E, 2)")
        want = len(edges)
    else:
        raise ValueError(f"plot_mesh: scalar_kind {kind!r}: one of vertex, edge, face")
    if len(s) != want:
        plural = {"vertex": "vertices", "edge": "edges", "face": "faces"}[kind]
        raise ValueError(f"plot_mesh: {len(s)} scalars for {want} {plural}")
    if kind == "face":
        return s.copy()
    if kind == "vertex":
        return s[F].mean(axis=1)
    # each face edge found in the edge list by its (min, max) key
    key = np.sort(edges, axis=1) @ np.array([nverts, 1])
    order = np.argsort(key)
    pairs = np.stack([F, np.roll(F, -1, axis=1)], axis=2)      # (F, 3, 2): a->b, b->c, c->a
    want_key = np.sort(pairs, axis=2) @ np.array([nverts, 1])
    at = np.minimum(np.searchsorted(key[order], want_key), len(key) - 1)
    found = key[order][at] == want_key
    if not found.all():
        f, k = np.argwhere(~found)[0]
        a, b = sorted(pairs[f, k])
        raise ValueError(f"plot_mesh: edge ({a}, {b}) of face {f} is not in the edge list")
    return s[order[at]].mean(axis=1)


def colour_range(values, cmap, vmin=None, vmax=None, percentiles=(2, 98)):
    """(lo, hi) of the colour map, as es.render chooses it (render.c
    es__render_range, plot_canvas.c es__color_range): vmin/vmax where given;
    otherwise the percentiles (lo, hi) of the finite values (numpy's linear
    percentiles; None: their full range), symmetric about 0 for "rdbu"; a
    degenerate range is widened by half its value (or 0.5)."""
    v = np.asarray(values, dtype=np.float64).ravel()
    fin = v[np.isfinite(v)]
    if percentiles is not None:
        p = tuple(float(x) for x in percentiles)
        if len(p) != 2 or not 0 <= p[0] < p[1] <= 100:
            raise ValueError(f"percentiles {percentiles}: want (lo, hi) with 0 <= lo < hi <= 100")
    if fin.size == 0:
        lo = hi = 0.0
    elif percentiles is not None:
        lo, hi = (float(x) for x in np.percentile(fin, p))
    else:
        lo, hi = float(fin.min()), float(fin.max())
    if cmap == "rdbu":
        lo, hi = -max(abs(lo), abs(hi)), max(abs(lo), abs(hi))
    lo = lo if vmin is None else float(vmin)
    hi = hi if vmax is None else float(vmax)
    if lo > hi:
        lo, hi = hi, lo
    if lo == hi:
        d = 0.5 * abs(lo) if lo != 0 else 0.5
        lo, hi = lo - d, hi + d
    return lo, hi


def headlight(vertices, faces, view):
    """Brightness of each face under a light at the camera, as es.render
    shades (render.c shade(), without its small highlight): 0.25 + 0.75 *
    cos(angle to the light), times 0.55 for a face seen from behind."""
    V = np.asarray(vertices, dtype=np.float64)
    F = np.asarray(faces, dtype=np.int64)
    light = -np.asarray(view, dtype=np.float64)
    light /= np.linalg.norm(light)
    normal = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    length = np.linalg.norm(normal, axis=1)
    cos = np.where(length > 0, normal @ light / np.where(length > 0, length, 1.0), 1.0)
    return np.where(cos >= 0, 0.25 + 0.75 * cos, 0.55 * (0.25 + 0.75 * -cos))
