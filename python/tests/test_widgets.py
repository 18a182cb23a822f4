"""edgespace.widgets.explore: the Jupyter explorer's backend, driven as a
notebook's front end drives it (setting widget values), without a browser.

Oracles: `edgespace embed` of the point the widget shows, with its options,
to 1e-9 of the bounding-box diagonal; the PNG signature and size of the
view; the store and the files a save leaves (the command's reader)."""
import html
import os
import shutil
import subprocess

import numpy as np
import pytest

import edgespace as es

pytest.importorskip("ipywidgets")
from conftest import cli_path   # noqa: E402

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def widget(store_path):
    if not es.has_figures():
        pytest.skip("the widget's view needs a library with figures (cairo)")
    import edgespace.widgets as ew
    with es.Store(store_path, write=True, ctx=es.Context(progress=None)) as s:
        s.pca("p", ncomp=3)
        s.diff("smile", key="subject", column="expression", from_="neutral", to="happy")
    w = ew.explore(store_path, pca="p", warm=False)
    yield w
    w.close()


def test_a_slider_moved_in_the_widget_embeds_as_edgespace_embed(widget, store_path, tmp_path):
    assert set(widget.sliders) == {"pc1", "pc2", "pc3", "diff:smile"}
    assert widget.view.value[:8] == PNG and widget.scatter.value[:8] == PNG
    widget.sliders["pc2"].value = -1.25           # what the front end sends on a drag
    widget.sliders["diff:smile"].value = 0.5
    assert widget.wait(60)
    s = widget.shape
    assert s.expr == "mean - 1.25*pc:2 + 0.5*diff:smile" == widget.expr.value
    assert widget.command.value == widget.explorer.command_line(s.expr)
    out = tmp_path / "cli.ply"
    r = subprocess.run([cli_path(), "embed", str(store_path), "--pca", "p", "--point", s.expr,
                        "-o", str(out), "--fast", "--no-store"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with es.Store(store_path) as st:
        V = st.mesh.read_positions(out)
    diag = np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    assert np.max(np.abs(s.V - V)) <= 1e-9 * diag
    # the view with a heat map and turned: a new picture each time
    before = widget.view.value
    widget.heat.value = "displacement"
    with_heat = widget.view.value
    widget.azimuth.value = 40
    assert with_heat[:8] == PNG and len({before, with_heat, widget.view.value}) == 3
    shots = os.environ.get("EDGESPACE_SCREENSHOTS")
    if shots:
        os.makedirs(shots, exist_ok=True)
        with open(os.path.join(shots, "widget_view.png"), "wb") as f:
            f.write(widget.view.value)
        with open(os.path.join(shots, "widget_scatter.png"), "wb") as f:
            f.write(widget.scatter.value)


def test_the_widget_shows_errors_and_goes_on(widget):
    for coords, message in (({"pc1": "abc"}, "not a number"), ({"pc1": 1e300}, "outside"),
                            ({"pc9": 1.0}, "no slider 'pc9'"), ({"diff:smile": 15}, "<= 0")):
        widget.set(**coords)
        assert widget.wait(60)
        assert message in html.unescape(widget.error.value), widget.error.value
    widget.set(pc1=3.0)         # not realizable on these faces: the warning
    assert widget.wait(60)
    assert widget.error.value == "" and "triangle inequality" in widget.warning.value


def test_a_row_and_saving_from_the_widget(widget, store_path):
    widget.row.value = "face_s04_happy"
    assert widget.wait(60)
    assert widget.shape.expr == "row:face_s04_happy" == widget.expr.value
    assert widget.sliders["pc1"].value != 0        # its scores
    widget.name.value = "s04h"
    out = widget._save()
    assert out and os.path.exists(out["path"])
    png = widget._save_png()
    with open(png, "rb") as f:
        assert f.read(8) == PNG
    with es.Store(store_path) as s:
        assert "s04h" in s.results("point")
        assert np.array_equal(s.mesh.read_positions(out["path"]), widget.shape.V)
    assert widget._save() is None and "exists" in widget.error.value
    shutil.rmtree(os.path.dirname(out["path"]), ignore_errors=True)
