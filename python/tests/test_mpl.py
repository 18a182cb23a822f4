"""The matplotlib route (edgespace.mpl) on the Agg backend: the data in the
artists checked against independent reads and computations.

Oracles: the stored PCA and labels read with h5py from the store's files
(not through the binding); numpy for the explained percentages (eigenvalues
over the total variance), cumulative sums, per-face means and percentiles;
the mesh's faces projected with matplotlib's own projection of the drawn
Axes (ax.M, proj3d) against the drawn polygons; the library's automatic
camera (es.auto_view) against where the drawn Axes put the view and up
directions; the glyphs an SVG draws and the codes a PDF shows, decoded by
the font's own tables (SVG glyph ids are code points, the PDF Type 3 font's
/Differences names its glyphs)."""
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
import zlib

import h5py
import numpy as np
import pytest

import edgespace as es

SVG = "{http://www.w3.org/2000/svg}"
XLINK = "{http://www.w3.org/1999/xlink}href"


@pytest.fixture
def plt():
    """pyplot on the Agg backend (skipped without python3-matplotlib);
    figures closed after the test."""
    matplotlib = pytest.importorskip("matplotlib", reason="python3-matplotlib is not installed")
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as pyplot
    yield pyplot
    pyplot.close("all")


@pytest.fixture
def esm(plt):
    import edgespace.mpl
    return edgespace.mpl


@pytest.fixture
def pca_store(store_path, ctx):
    """The synthetic faces with two stored PCAs: all rows (5 components) and
    the happy faces only (3)."""
    with es.Store(store_path, write=True, ctx=ctx) as s:
        s.pca("faces", components=5)
        s.pca("happy", where="expression=happy", components=3)
    return store_path


def stored(store_path, name):
    """A stored PCA's datasets and the store's labels, read with h5py."""
    with h5py.File(f"{store_path}.results/pca/{name}.h5", "r") as f:
        g = f[f"analysis/pca/{name}"]
        out = {k: g[k][()] for k in ("scores", "eigenvalues", "total_variance", "rows")}
    with h5py.File(store_path, "r") as f:
        out["labels"] = {c: np.array([v.decode() for v in f["labels"][c][()]], dtype=object)
                         for c in f["labels"]}
    out["total_variance"] = float(np.ravel(out["total_variance"])[0])
    return out


def percent_label(k, eig, total):
    return f"PC{k} ({100 * eig[k - 1] / total:.1f} %)"


def test_import_without_matplotlib_and_the_error_naming_the_package(tmp_path):
    """`import edgespace` (and edgespace.mpl) work without matplotlib; a
    figure then raises an ImportError naming Debian's package."""
    code = ("import sys; sys.modules['matplotlib'] = None\n"
            "import edgespace, edgespace.mpl\n"
            "try:\n"
            "    edgespace.mpl.plot_scree([1.0, 0.5])\n"
            "except ImportError as e:\n"
            "    print('ERROR', e)\n")
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(es.__file__)),
               EDGESPACE_LIBRARY=es.LIBRARY_PATH)          # this package and library
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                       cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("ERROR edgespace.mpl draws with matplotlib")
    assert "install Debian's python3-matplotlib" in r.stdout


def test_pca_scatter_of_a_stored_pca(esm, pca_store, ctx):
    h = stored(pca_store, "faces")
    expression = h["labels"]["expression"][h["rows"]]
    with es.Store(pca_store, ctx=ctx) as s:
        ax = esm.plot_pca(s, pca="faces", column="expression", pcs=(1, 3))
    groups = list(dict.fromkeys(expression))              # order of first appearance
    assert groups == ["neutral", "happy", "angry"]
    assert len(ax.collections) == len(groups)
    for c, g in zip(ax.collections, groups):
        assert np.array_equal(c.get_offsets(), h["scores"][expression == g][:, [0, 2]])
    legend = ax.get_legend()
    assert [t.get_text() for t in legend.get_texts()] == groups
    assert legend.get_title().get_text() == "expression"
    # the groups' colours differ: the Axes' colour cycle
    assert len({tuple(c.get_facecolor()[0]) for c in ax.collections}) == 3
    eig, total = h["eigenvalues"], h["total_variance"]
    assert ax.get_xlabel() == percent_label(1, eig, total)
    assert ax.get_ylabel() == percent_label(3, eig, total)
    assert re.fullmatch(r"PC1 \(\d+\.\d %\)", ax.get_xlabel())


def test_pca_of_some_rows_where_and_the_other_sources(esm, pca_store, ctx):
    h = stored(pca_store, "happy")                        # fitted on the happy faces only
    subject = h["labels"]["subject"][h["rows"]]
    with es.Store(pca_store, ctx=ctx) as s:
        ax = esm.plot_pca(s, pca="happy", column="subject", pcs=(2, 1))
        offsets = np.concatenate([c.get_offsets() for c in ax.collections])
        assert len(ax.collections) == len(set(subject)) == len(h["rows"])
        assert np.array_equal(offsets, h["scores"][:, [1, 0]])   # one subject a row, in order
        assert [t.get_text() for t in ax.get_legend().get_texts()] == list(subject)
        # where= keeps the PCA's rows that match
        h = stored(pca_store, "faces")
        expression = h["labels"]["expression"][h["rows"]]
        ax = esm.plot_pca(s, pca="faces", column="expression", where="expression=angry")
        assert len(ax.collections) == 1
        assert np.array_equal(ax.collections[0].get_offsets(),
                              h["scores"][expression == "angry"][:, :2])
        with pytest.raises(ValueError, match="no row of the PCA matches"):
            esm.plot_pca(s, pca="happy", where="expression=angry")
        # a PCA object, and arrays: the same points and labels
        fit = s.load_pca("faces")
    ax = esm.plot_pca(fit, labels=expression, pcs=(1, 2))
    assert np.array_equal(ax.collections[1].get_offsets(),
                          h["scores"][expression == "happy"][:, :2])
    assert ax.get_ylabel() == percent_label(2, h["eigenvalues"], h["total_variance"])
    ax = esm.plot_pca(h["scores"], labels=expression)
    assert ax.get_xlabel() == "PC1" and ax.get_legend().get_title().get_text() == ""
    assert np.array_equal(ax.collections[2].get_offsets(),
                          h["scores"][expression == "angry"][:, :2])
    with pytest.raises(ValueError, match=r"has 5 components \(PC1\.\.PC5\)"):
        esm.plot_pca(fit, pcs=(0, 1))
    with pytest.raises(TypeError, match="integers"):
        esm.plot_pca(fit, pcs=(1.0, 2))
    with pytest.raises(ValueError, match="give the Store"):
        esm.plot_pca(fit, column="expression")
    with pytest.raises(ValueError, match="4 explained fractions for 5 components"):
        esm.plot_pca(h["scores"], explained=h["eigenvalues"][:4])
    with pytest.raises(ValueError, match="17 labels for 18 scores"):
        esm.plot_pca(fit, labels=expression[1:])


def test_a_missing_pca_name_lists_those_there(esm, pca_store, ctx):
    with es.Store(pca_store, ctx=ctx) as s:
        for plot in (esm.plot_pca, esm.plot_scree):
            with pytest.raises(es.NotFoundError, match=r"no PCA named 'nope' "
                                                       r"\(pca results: faces, happy\)"):
                plot(s, pca="nope")


def test_scree(esm, pca_store, ctx):
    h = stored(pca_store, "faces")
    percent = 100 * h["eigenvalues"] / h["total_variance"]
    with es.Store(pca_store, ctx=ctx) as s:
        ax = esm.plot_scree(s, pca="faces", title="scree")
    bars, = ax.containers
    assert np.allclose([b.get_height() for b in bars], percent, rtol=1e-14, atol=0)
    assert [b.get_x() + b.get_width() / 2 for b in bars] == [1, 2, 3, 4, 5]
    line, = ax.get_lines()
    assert np.allclose(line.get_ydata(), np.cumsum(percent), rtol=1e-14, atol=0)
    assert line.get_ydata()[-1] < 100          # 5 of 17 components: the rest count in the total
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["per component", "cumulative"]
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_title()) == \
        ("component", "explained variance (%)", "scree")
    # variances without a total: percent of their sum; components= shows the first ones
    ax = esm.plot_scree(h["eigenvalues"], components=3)
    assert np.allclose(ax.get_lines()[0].get_ydata(),
                       np.cumsum(100 * h["eigenvalues"] / h["eigenvalues"].sum())[:3])
    with pytest.raises(ValueError, match="below the sum"):
        esm.plot_scree([1.0, 2.0], total=2.5)
    with pytest.raises(ValueError, match="finite and >= 0"):
        esm.plot_scree([1.0, -2.0])


def drawn_faces(ax, surface, V, F):
    """For each polygon drawn (depth-sorted), the face of F it is: matched
    by projecting the faces with the Axes' projection; checks that the
    polygons are exactly the faces."""
    from mpl_toolkits.mplot3d import proj3d
    ax.figure.canvas.draw()
    x, y, _ = proj3d.proj_transform(V[:, 0], V[:, 1], V[:, 2], ax.M)
    tri = np.stack([x[F], y[F]], axis=2)                  # (F, 3, 2)
    polys = np.array([p.vertices[:3] for p in surface.get_paths()])
    assert polys.shape == tri.shape
    d = np.linalg.norm(polys.mean(1)[:, None] - tri.mean(1)[None], axis=2)
    which = d.argmin(axis=1)
    assert sorted(which) == list(range(len(F)))           # each face drawn once
    scale = np.ptp(tri)
    assert np.abs(polys - tri[which]).max() < 1e-12 * scale
    return which


def test_mesh_polygons_and_colours_by_vertex(esm, store_path, ctx):
    with h5py.File(store_path, "r") as f:
        V, F = f["shapes/positions"][2], f["topology/faces"][()]
    with es.Store(store_path, ctx=ctx) as s:
        mesh = es.Mesh(s.faces, s.positions(2), ctx=ctx)
    values = np.random.default_rng(7).lognormal(sigma=1.5, size=len(V))   # long tail
    ax = esm.plot_mesh(mesh, scalars=values, colorbar_label="log-normal", shade=False)
    surface = ax.collections[-1]
    which = drawn_faces(ax, surface, V, F)
    lo, hi = np.percentile(values, [2, 98])               # the robust range
    cbar_ax = ax.figure.axes[-1]
    assert np.allclose(cbar_ax.get_ylim(), (lo, hi), rtol=1e-14, atol=0)
    assert cbar_ax.get_ylabel() == "log-normal"
    import matplotlib
    expect = matplotlib.colormaps["viridis"]((values[F].mean(1) - lo) / (hi - lo))
    assert np.allclose(surface.get_facecolor(), expect[which], atol=1e-12)
    # equal scales: a cube around the mesh's bounding sphere (about its box's centre)
    spans = [np.ptp(lim) for lim in (ax.get_xlim(), ax.get_ylim(), ax.get_zlim())]
    centre = (V.min(0) + V.max(0)) / 2
    assert np.allclose(spans, 2 * np.linalg.norm(V - centre, axis=1).max())
    # percentiles=None: the full range; vmin/vmax: as given
    ax = esm.plot_mesh(mesh, scalars=values, percentiles=None)
    assert np.allclose(ax.figure.axes[-1].get_ylim(), (values.min(), values.max()))
    ax = esm.plot_mesh(mesh, scalars=values, vmin=0.5, vmax=2)
    assert np.allclose(ax.figure.axes[-1].get_ylim(), (0.5, 2))


def test_mesh_colours_by_edge_and_face_and_non_finite(esm, store_path, ctx):
    with h5py.File(store_path, "r") as f:
        V, F, E = f["shapes/positions"][0], f["topology/faces"][()], f["topology/edges"][()]
    index = {(int(a), int(b)): e for e, (a, b) in enumerate(E)}
    t = np.linspace(-3, 1, len(E))
    t[5] = np.nan
    # each face: the mean of its three edges, found by a dict of the stored pairs
    face_t = np.array([np.mean([t[index[tuple(sorted((int(f[k]), int(f[(k + 1) % 3]))))]]
                                for k in range(3)]) for f in F])
    with es.Store(store_path, ctx=ctx) as s:
        emb = es.Embedding(V, F, {})
        with pytest.raises(ValueError, match="edge scalars need the edge list"):
            esm.plot_mesh(emb, scalars=t, scalar_kind="edge")
        ax = esm.plot_mesh(emb, scalars=t, scalar_kind="edge", edges=s.edges, cmap="rdbu",
                           shade=False, nan_label="no t")
    surface = ax.collections[-1]
    which = drawn_faces(ax, surface, V, F)
    m = np.nanmax(np.abs(np.nanpercentile(t, [2, 98])))    # symmetric about 0 for rdbu
    cbar_ax = ax.figure.axes[-1]
    assert np.allclose(cbar_ax.get_ylim(), (-m, m), rtol=1e-14, atol=0)
    import matplotlib
    expect = matplotlib.colormaps["RdBu_r"]((face_t + m) / (2 * m))
    expect[~np.isfinite(face_t)] = [0.6, 0.6, 0.6, 1]    # ES_NAN_GREY
    assert np.isnan(face_t).sum() == 2                    # the edge's two faces
    assert np.allclose(surface.get_facecolor(), expect[which], atol=1e-12)
    assert [x.get_text() for x in cbar_ax.get_legend().get_texts()] == ["no t"]
    # per face, shaded: the colour map's colour times es.render's headlight
    # (0.25 + 0.75 cos of the angle between the face normal and the eye)
    face = np.arange(len(F), dtype=float)
    ax = esm.plot_mesh((V, F), scalars=face, scalar_kind="face", cmap="greys",
                       percentiles=None, shade=True)
    surface = ax.collections[-1]
    which = drawn_faces(ax, surface, V, F)
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    n /= np.linalg.norm(n, axis=1)[:, None]
    cos = n @ -ax.vvec                                    # towards the eye (get_proj's vvec)
    light = np.where(cos >= 0, 0.25 + 0.75 * cos, 0.55 * (0.25 - 0.75 * cos))
    grey = matplotlib.colormaps["gray"](face / face.max())[:, 0]   # "greys": black to white
    assert np.allclose(np.asarray(surface.get_facecolor())[:, 0], (grey * light)[which], atol=1e-12)
    with pytest.raises(ValueError, match="12 scalars for 1416 faces"):
        esm.plot_mesh((V, F), scalars=face[:12], scalar_kind="face")


def test_mesh_camera_is_the_library_s(esm, plt, ctx):
    """Along the camera's view a point stays put on the screen, and up goes
    straight up: es.auto_view's camera, and view=/up= given (orthographic
    projection, so that directions project without perspective)."""
    if not es.has_figures():
        pytest.skip("library built without figures (no es.auto_view)")
    from mpl_toolkits.mplot3d import proj3d
    syn = es.synth("face", n=1, ctx=ctx)
    V, F = syn["vertices"][0], syn["faces"]
    rng = np.random.default_rng(3)
    cameras = [es.auto_view(V, F, ctx=ctx)]
    for _ in range(6):
        view, up = rng.normal(size=3), rng.normal(size=3)
        cameras.append((view, up - (up @ view) / (view @ view) * view))
    cameras.append(((0.0, 0.0, -1.0), (0.0, 1.0, 0.0)))
    cameras.append(((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    for i, (view, up) in enumerate(cameras):
        ax = esm.plot_mesh((V, F), orthographic=True,
                           **({} if i == 0 else {"view": view, "up": up}))
        ax.figure.canvas.draw()
        c = V.mean(0)
        d = 0.1 * np.ptp(V)
        pts = np.array([c, c + d * np.asarray(view) / np.linalg.norm(view),
                        c + d * np.asarray(up) / np.linalg.norm(up)])
        x, y, _ = proj3d.proj_transform(pts[:, 0], pts[:, 1], pts[:, 2], ax.M)
        assert abs(x[1] - x[0]) < 1e-9 and abs(y[1] - y[0]) < 1e-9, (view, up)
        assert abs(x[2] - x[0]) < 1e-9 and y[2] - y[0] > 0.01, (view, up)
        # equal scales: the coordinate axes project with one scale (P P^T = s^2 I)
        e = c + d * np.eye(3)
        ex, ey, _ = proj3d.proj_transform(e[:, 0], e[:, 1], e[:, 2], ax.M)
        P = np.array([ex - x[0], ey - y[0]])
        PPt = P @ P.T
        assert np.abs(PPt - PPt[0, 0] * np.eye(2)).max() < 1e-9 * PPt[0, 0]
        # the whole mesh inside the Axes
        x, y, _ = proj3d.proj_transform(V[:, 0], V[:, 1], V[:, 2], ax.M)
        px = ax.transData.transform(np.c_[x, y])
        assert (px >= ax.bbox.p0).all() and (px <= ax.bbox.p1).all()
        plt.close(ax.figure)
    # elev/azim replace the camera's angles, about the axis nearest its up:
    # y, which then points straight up (no roll)
    ax = esm.plot_mesh((V, F), elev=10, azim=-30, orthographic=True)
    ax.figure.canvas.draw()
    assert (ax.elev, ax.azim, ax.roll) == (10, -30, 0)
    x, y, _ = proj3d.proj_transform([0, 0], [0, 1], [0, 0], ax.M)
    assert abs(x[1] - x[0]) < 1e-9 and y[1] > y[0]


def test_mesh_input_errors(esm, plt):
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    F = np.array([[0, 1, 2], [0, 1, 4]])
    with pytest.raises(ValueError, match=r"face 1 \[0, 1, 4\] names a vertex outside 0\.\.3"):
        esm.plot_mesh((V, F))
    with pytest.raises(ValueError, match="a mesh needs a 3D one"):
        esm.plot_mesh((V, F[:1]), ax=plt.figure().add_subplot())
    with pytest.raises(ValueError, match="3 scalars for 4 vertices"):
        esm.plot_mesh((V, F[:1]), scalars=[1, 2, 3])


def svg_texts(path):
    """The texts an SVG draws as glyph outlines (matplotlib's svg.fonttype
    "path"): each text group's <use> of glyphs named by font and code point,
    each glyph a <path> outline."""
    root = ET.parse(path).getroot()
    glyphs = {p.get("id"): p.get("d") for p in root.iter(f"{SVG}path") if p.get("id")}
    out = []
    for g in root.iter(f"{SVG}g"):
        if not (g.get("id") or "").startswith("text_"):
            continue
        uses = [u.get(XLINK)[1:] for u in g.iter(f"{SVG}use")]
        assert all(u in glyphs and ((glyphs[u] or "").strip() or u.endswith("-20")) for u in uses)
        out.append("".join(chr(int(u.rsplit("-", 1)[1], 16)) for u in uses))
    return out


GLYPHS = {"space": " ", "percent": "%", "parenleft": "(", "parenright": ")", "period": ".",
          "zero": "0", "one": "1", "two": "2", "three": "3", "four": "4", "five": "5",
          "six": "6", "seven": "7", "eight": "8", "nine": "9", "hyphen": "-", "minus": "\u2212",
          "comma": ",", "equal": "="}


def pdf_texts(path):
    """The strings a matplotlib PDF shows with its Type 3 fonts, decoded by
    each font's /Differences (code -> glyph name, a glyph's drawing in the
    font's /CharProcs); every glyph shown must be drawn by the font."""
    data = open(path, "rb").read()
    names = {}
    for diff in re.findall(rb"/Differences\s*\[(.*?)\]", data, re.S):
        code = 0
        for tok in diff.split():
            if tok[:1] == b"/":
                names[code] = tok[1:].decode()
                code += 1
            else:
                code = int(tok)
    procs = set()
    for obj in re.findall(rb"/CharProcs\s+(\d+)\s+0\s+R", data):    # each font's glyph drawings
        block = re.search(rb"\b" + obj + rb" 0 obj\s*<<(.*?)>>\s*endobj", data, re.S).group(1)
        procs.update(m.decode() for m in re.findall(rb"/([\w.]+)\s+\d+\s+0\s+R", block))
    assert names and procs
    out = []
    for m in re.finditer(rb"stream\r?\n(.*?)\r?\nendstream", data, re.S):
        try:
            content = zlib.decompress(m.group(1))
        except zlib.error:
            continue
        for arr in re.findall(rb"\[((?:\((?:\\.|[^\\)])*\)|[^\]])*)\]\s*TJ", content):
            codes = b"".join(re.sub(rb"\\(.)", rb"\1", s)
                             for s in re.findall(rb"\(((?:\\.|[^\\)])*)\)", arr))
            glyphs = [names[c] for c in codes]
            assert all(g in procs for g in glyphs)
            out.append("".join(GLYPHS.get(g, g) for g in glyphs))
    return out


def test_pdf_and_svg_keep_the_text_as_text(esm, plt, pca_store, tmp_path, ctx):
    h = stored(pca_store, "faces")
    eig, total = h["eigenvalues"], h["total_variance"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
    with es.Store(pca_store, ctx=ctx) as s:
        esm.plot_pca(s, pca="faces", column="expression", ax=left)
        esm.plot_scree(s, pca="faces", ax=right, title="scree")
    fig.savefig(tmp_path / "pca.svg")
    fig.savefig(tmp_path / "pca.pdf")
    want = {percent_label(1, eig, total), percent_label(2, eig, total), "expression",
            "neutral", "happy", "angry", "component", "explained variance (%)",
            "per component", "cumulative", "scree"}
    assert want <= set(svg_texts(tmp_path / "pca.svg"))
    assert {w for w in want if w.isascii()} <= set(pdf_texts(tmp_path / "pca.pdf"))
    # a mesh: the surface an image (rasterized), its colour bar's label text
    syn = es.synth("face", n=1, ctx=ctx)
    ax = esm.plot_mesh((syn["vertices"][0], syn["faces"]), scalars=syn["vertices"][0][:, 2],
                       colorbar_label="depth", title="face")
    ax.figure.savefig(tmp_path / "mesh.svg")
    ax.figure.savefig(tmp_path / "mesh.pdf")
    assert {"depth", "face"} <= set(svg_texts(tmp_path / "mesh.svg"))
    assert {"depth", "face"} <= set(pdf_texts(tmp_path / "mesh.pdf"))
    svg = (tmp_path / "mesh.svg").read_text()
    assert svg.count("<image") >= 1 and "<path" in svg
    assert os.path.getsize(tmp_path / "mesh.pdf") < 400_000
