"""model --figure: each significant edge coloured by its F on a log scale,
the others grey. Oracles: the exported per-edge table counted and its
percentiles taken by numpy, the PDF's text read by pdf_text (ToUnicode
maps), the PNG's pixels decoded by png_pixels (zlib)."""
import io
import re

import numpy as np
import pytest

import edgespace as es
from pdf_text import pdf_strings
from png_pixels import png_pixels

pytestmark = pytest.mark.skipif(not es.has_figures(), reason="library built without figures")


def edges_table(cli, store, name):
    csv = cli("export", store, "--result", f"model/{name}", "--table", "edges", "--output", "-").stdout
    return np.genfromtxt(io.StringIO(csv), delimiter=",", names=True)


def test_edge_figure_shows_f_on_a_log_scale(store_path, tmp_path, cli):
    cli("model", store_path, "~ expression + subject", "--block", "subject", "-p", "99",
        "--edges", "expression", "-n", "m", "--figure", tmp_path / "e.pdf")
    t = edges_table(cli, store_path, "m")
    sig = t["q"] < 0.05
    assert 0 < sig.sum() < len(t)
    text = pdf_strings(tmp_path / "e.pdf")
    assert f"{sig.sum()} of {len(t)} edges with FDR q < 0.05" in text
    assert "per-edge F (log)" in text and "q \u2265 0.05" in text
    # the colour bar's ticks are F values (1, 2, 5 x 10^k) inside the robust
    # range: numpy's 2nd and 98th percentiles of the coloured edges' F
    lo, hi = np.percentile(t["f"][sig], [2, 98])
    ticks = [float(s) for s in text if re.fullmatch(r"[0-9.]+", s)]
    assert len(ticks) >= 3
    for v in ticks:
        assert lo * (1 - 1e-9) <= v <= hi * (1 + 1e-9)
        assert round(v / 10 ** np.floor(np.log10(v)), 9) in (1, 2, 5)


def test_edge_figure_is_grey_where_nothing_is_significant(store_path, tmp_path, cli):
    # subject has no effect on the synthetic faces: no edge is significant
    cli("model", store_path, "~ expression + subject", "--block", "subject", "-p", "99",
        "--edges", "subject", "-n", "s", "--figure", tmp_path / "s.png")
    assert (edges_table(cli, store_path, "s")["q"] >= 0.05).all()
    px = png_pixels(tmp_path / "s.png")[:, :480, :3].astype(int)   # the mesh's panel
    mesh = (px.min(axis=2) < 250) & (px.min(axis=2) > 40)            # not white, not text
    assert mesh.sum() > 10000
    spread = px.max(axis=2) - px.min(axis=2)
    assert (spread[mesh] <= 2).all()                                  # grey, no colour
    # the significant model of the same faces is coloured where its edges are
    cli("model", store_path, "~ expression + subject", "--block", "subject", "-p", "99",
        "--edges", "expression", "-n", "e", "--figure", tmp_path / "e.png")
    px = png_pixels(tmp_path / "e.png")[:, :480, :3].astype(int)
    assert ((px.max(axis=2) - px.min(axis=2)) > 30).sum() > 5000
