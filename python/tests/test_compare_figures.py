"""The comparison study's heat maps as a reader sees them: the PDF's text
(read through its ToUnicode maps by pdf_text, not by the library) names every
row and column, the groups and the colour bar's quantity and units, and the
rows stand in group order. The pixels of that order are checked in C
(tests/figure/test_plot.c, test_compare_heatmap_order)."""
import itertools

import pytest

import edgespace as es
from pdf_text import pdf_strings

pytestmark = pytest.mark.skipif(not es.has_figures(), reason="library built without figures")


def test_compare_heatmaps_label_rows_groups_and_units(store_path, tmp_path, cli):
    cli("gpa", store_path, "--name", "g")
    out = tmp_path / "cmp"
    cli("compare", store_path, "--gpa", "g", "--by", "expression", "-p", "9", "-o", out,
        "--figures", "pdf")
    ids = [line.split(",")[0] for line in
           (out / "distances_lengths.csv").read_text().splitlines()[1:]]
    assert len(ids) == 18
    text = pdf_strings(out / "heatmap_lengths.pdf")
    assert "distance between unit-sum length vectors" in text
    for group in ("neutral", "happy", "angry"):
        assert text.count(group) == 2          # beside the rows and above the columns
    labels = [s for s in text if s in ids]
    assert sorted(labels) == sorted(ids + ids)  # every row and every column
    rows = labels[:18]
    # the synthetic ids end in their expression: rows form one run per group,
    # and within a group they are in id order
    runs = [(k, list(g)) for k, g in itertools.groupby(rows, key=lambda s: s.rsplit("_", 1)[1])]
    assert len(runs) == 3 and all(g == sorted(g) for _, g in runs)
    proc = pdf_strings(out / "heatmap_procrustes.pdf")
    assert "Procrustes distance (data units, GPA-aligned)" in proc
    # rho, the distance geomorph and shapes users read: its own map, labelled
    rho = pdf_strings(out / "heatmap_rho.pdf")
    assert "ρ (radians, as shapes::riemdist)" in rho
    assert "Riemannian shape distances ρ (unit centroid size)" in rho
    assert sorted(s for s in rho if s in ids) == sorted(ids + ids)
    # PNG by the same option; an unknown format is a usage error naming it
    cli("compare", store_path, "--gpa", "g", "--by", "expression", "-p", "9", "-o", out,
        "--figures", "png", "--replace")
    assert (out / "heatmap_lengths.png").read_bytes()[:4] == b"\x89PNG"
    r = cli("compare", store_path, "--gpa", "g", "-o", out, "--figures", "bmp", check=False)
    assert r.returncode == 2 and "bad --figures 'bmp'" in r.stderr
