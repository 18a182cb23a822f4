"""Pictures from Python: PNG bytes from es_render and the plots, the same
bytes the command draws for the same mesh and options, and Jupyter's inline
display (_repr_png_)."""
import struct

import numpy as np
import pytest

import edgespace as es

pytestmark = pytest.mark.skipif(not es.has_figures(), reason="library built without figures")


def png_size(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_render_is_the_commands_picture(tmp_path, cli, ctx):
    syn = es.synth("face", n=1, ctx=ctx)
    m = es.Mesh(syn["faces"], syn["vertices"][0], ctx=ctx)
    m.write(tmp_path / "f.ply")
    cli("render", tmp_path / "f.ply", "-o", tmp_path / "cli.png")
    img = es.render((syn["vertices"][0], syn["faces"]), ctx=ctx)
    assert isinstance(img, bytes) and img == (tmp_path / "cli.png").read_bytes()
    assert png_size(img) == (480, 480)
    assert img._repr_png_() == bytes(img)
    # a notebook's text/plain of an image: a line, not the PNG's bytes again
    assert repr(img) == f"<edgespace.Image PNG 480x480, {len(img)} bytes>"
    assert img.size == png_size(img)
    # with scalars, a title and a colour map: the command's options
    t = np.linspace(-1, 1, m.nedges)
    np.savetxt(tmp_path / "t.csv", t, fmt="%.17g")
    cli("render", tmp_path / "f.ply", "-o", tmp_path / "cli2.png", "--scalars", tmp_path / "t.csv",
        "--cmap", "rdbu", "--title", "t", "--width", "300", "--height", "200")
    img2 = es.render(m, scalars=t, scalar_kind="edge", cmap="rdbu", title="t", width=300,
                     height=200, ctx=ctx)
    assert img2 == (tmp_path / "cli2.png").read_bytes()


def test_several_panels_and_the_auto_view(ctx):
    syn = es.synth("face", n=2, ctx=ctx)
    V, F = syn["vertices"], syn["faces"]
    img = es.render([(V[0], F), (V[3], F)], labels=["a", "b"], width=200, height=150, ctx=ctx)
    w, h = png_size(img)
    assert w >= 400 and h >= 150
    view, up = es.auto_view(V[0], F, ctx=ctx)
    assert np.isclose(np.linalg.norm(view), 1) and abs(view @ up) < 1e-12
    same = es.render([(V[0], F), (V[3], F)], labels=["a", "b"], width=200, height=150,
                     view=view, up=up, ctx=ctx)
    assert png_size(same) == (w, h)


def test_embedding_displays_inline(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        e = s.embed("row:face_s01_neutral")
    png = e._repr_png_()
    assert png_size(png) == (360, 360)
    assert repr(e).startswith(f"<edgespace.Embedding V={e.V.shape[0]} F={e.F.shape[0]} ")
    assert len(repr(e)) < 100


def test_plots(ctx):
    rng = np.random.default_rng(0)
    x, y = rng.normal(size=20), rng.normal(size=20)
    img = es.plot_scatter(x, y, labels=["a", "b"] * 10, title="s", xlabel="x", ylabel="y",
                          legend_title="g", ctx=ctx)
    assert png_size(img)[0] > 100
    img = es.plot_scree([3.0, 2.0, 1.0], total=7.0, title="scree", ctx=ctx)
    assert png_size(img)[0] > 100
    with pytest.raises(ValueError):
        es.plot_scatter(x, y[:5], ctx=ctx)


def test_render_scalars_column_and_percentile_range(tmp_path, cli, ctx):
    """render --column picks a CSV column by name (its header labels the colour
    bar), --percentiles sets the range: against numpy.percentile (linear)."""
    import re
    syn = es.synth("face", n=1, ctx=ctx)
    m = es.Mesh(syn["faces"], syn["vertices"][0], ctx=ctx)
    m.write(tmp_path / "f.ply")
    rng = np.random.default_rng(3)
    a = rng.normal(size=m.nverts)
    b = rng.lognormal(sigma=2.0, size=m.nverts)     # a heavy tail, as residuals have
    with open(tmp_path / "s.csv", "w") as f:
        f.write("a,b\n" + "".join(f"{x!r},{y!r}\n" for x, y in zip(a, b)))

    def colour_range(*args):
        r = cli("render", tmp_path / "f.ply", "--scalars", tmp_path / "s.csv", "-o",
                tmp_path / "r.png", *args)
        lo, hi = re.search(r"colour range (\S+)\.\.(\S+)", r.stdout).groups()
        return float(lo), float(hi)
    assert np.allclose(colour_range("--column", "b"), [b.min(), b.max()], rtol=1e-3)
    assert np.allclose(colour_range("--column", "b", "--percentiles", "5,95"),
                       np.percentile(b, [5, 95]), rtol=1e-3)
    assert np.allclose(colour_range("--column", "1", "--percentiles", "0,50"),
                       [a.min(), np.median(a)], rtol=1e-3)
    assert png_size((tmp_path / "r.png").read_bytes())[1] == 480
    r = cli("render", tmp_path / "f.ply", "--scalars", tmp_path / "s.csv", "--column", "c",
            "-o", tmp_path / "x.png", check=False)
    assert r.returncode == 1 and "no column 'c' (columns: a, b)" in r.stderr
    r = cli("render", tmp_path / "f.ply", "--percentiles", "90,10", "-o", tmp_path / "x.png",
            check=False)
    assert r.returncode == 2


def test_variation_figure_writes_plus_minus_and_minus_signs(store_path, tmp_path, cli):
    """The labels and title say "±" and "−" (U+00B1, U+2212), not "+-" and
    "-": read from the PDF's ToUnicode maps (pdf_text: zlib, not the library)."""
    from pdf_text import pdf_codepoints
    cli("pca", store_path, "--name", "faces")
    cli("variation", store_path, "--pca", "faces", "--pcs", "1", "-o", tmp_path / "v.pdf")
    codes = pdf_codepoints(tmp_path / "v.pdf")
    assert "\u00b1" in codes and "\u2212" in codes


def test_residual_columns_name_their_quantity_on_the_colour_bar(store_path, tmp_path, cli):
    """render --scalars of `embed --residuals`: the colour bar names the
    quantity and its unit, not the CSV's column name (read from the PDF's
    text by pdf_text, not by the library); any other column keeps its name."""
    from pdf_text import pdf_strings
    cli("embed", store_path, "--point", "mean", "-o", tmp_path / "m.ply", "--residuals",
        tmp_path / "r.csv", "--no-store")
    labels = {"closure": "closure energy at the vertex (no unit)",
              "edge_error": "mean relative edge-length error at the vertex",
              "deviation": "distance from the prior / bounding-box diagonal"}
    for column, label in labels.items():
        cli("render", tmp_path / "m.ply", "--scalars", tmp_path / "r.csv", "--column", column,
            "-o", tmp_path / f"{column}.pdf")
        assert label in pdf_strings(tmp_path / f"{column}.pdf"), column
    with open(tmp_path / "o.csv", "w") as f:
        f.write("thickness\n" + "1\n" * len(open(tmp_path / "r.csv").readlines()[1:]))
    cli("render", tmp_path / "m.ply", "--scalars", tmp_path / "o.csv", "-o", tmp_path / "o.pdf")
    assert "thickness" in pdf_strings(tmp_path / "o.pdf")
