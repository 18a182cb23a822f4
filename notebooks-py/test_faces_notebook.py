"""notebooks-py/test_faces_notebook.py — the Python face study
(01_faces.ipynb) runs as a Jupyter notebook, passes its self-check, and finds
what its C twin notebooks-c/01_faces.c finds on the same data with the same
seed: the same PCA (eigenvalues, explained variance, scores), the same
embedded points (scale, RMS and largest edge errors, bending and distance
from the prior), to the digits the C notebook prints, and the same figures
byte for byte. Both run small
(EDGESPACE_NOTEBOOK_SMALL=1, --small: the test suite's sizes) into a
temporary folder."""
import csv
import json
import os
import subprocess
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def close(a, b, digits):
    """Equal to the `digits` significant digits both sides printed."""
    a, b = float(a), float(b)
    return abs(a - b) <= 1.01 * 10.0 ** (1 - digits) * max(abs(a), abs(b)) or a == b


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    c_exe = os.environ.get("EDGESPACE_NOTEBOOK_01")
    nbconvert = os.environ.get("JUPYTER_NBCONVERT", "jupyter-nbconvert")
    if not c_exe or not os.access(c_exe, os.X_OK):
        pytest.skip("the C notebook 01_faces is not built (EDGESPACE_NOTEBOOK_01)")
    out = tmp_path_factory.mktemp("nb")
    env = dict(os.environ, EDGESPACE_NOTEBOOK_SMALL="1", EDGESPACE_NOTEBOOK_OUT=str(out),
               OPENBLAS_NUM_THREADS="1")
    c = subprocess.run([c_exe, "--small", "--out", str(out / "c")], env=env,
                       capture_output=True, text=True)
    assert c.returncode == 0, c.stdout + c.stderr
    # the kernel is Debian's python3 (its kernelspec); it inherits PYTHONPATH and
    # EDGESPACE_LIBRARY from this environment, and runs in notebooks-py/
    py = subprocess.run([nbconvert, "--to", "notebook", "--execute", "--output-dir", str(out),
                         "--ExecutePreprocessor.timeout=900",
                         os.path.join(HERE, "01_faces.ipynb")],
                        env=env, capture_output=True, text=True)
    assert py.returncode == 0, py.stderr[-4000:]
    return out / "c", out / "01_faces_py", out / "01_faces.ipynb", c.stdout


def test_the_notebook_ran_and_its_checks_passed(runs):
    _, py, executed, _ = runs
    nb = json.load(open(executed))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert 10 <= len(code) <= 14                                      # about a dozen cells
    for c in code:
        assert all(o["output_type"] != "error" for o in c["outputs"])
    text = "".join("".join(o.get("text", "")) for c in code for o in c["outputs"])
    assert text.count("ok   ") == 5 and "FAIL" not in text
    images = sum("image/png" in o.get("data", {}) for c in code for o in c["outputs"])
    assert images >= 5                # scree, scatter, the scatters by matplotlib, faces, heat map
    for f in ("expressions.png", "happy_t_heatmap.png", "pc1_pc2.png", "mean_neutral.obj",
              "pc_scores.pdf"):
        assert (py / f).stat().st_size > 1000


def test_same_figures_as_the_c_notebook(runs):
    """The pictures are drawn by the same library calls from the same numbers:
    byte for byte the C notebook's PNGs."""
    c, py, _, _ = runs
    for f in ("pc1_pc2.png", "pc1_pc3.png", "expressions.png", "happy_t_heatmap.png"):
        assert (py / f).read_bytes() == (c / f).read_bytes(), f


def test_same_pca_as_the_c_notebook(runs):
    c, py, _, _ = runs
    cs, ps = read(c / "scree.csv"), read(py / "scree.csv")
    assert len(cs) == len(ps) >= 3
    for a, b in zip(cs, ps):
        for k in ("eigenvalue", "explained", "cumulative"):
            assert close(a[k], b[k], 10), (k, a, b)
    cs, ps = read(c / "scores.csv"), read(py / "scores.csv")
    assert [r["id"] for r in cs] == [r["id"] for r in ps]
    assert [(r["subject"], r["expression"]) for r in cs] == \
        [(r["subject"], r["expression"]) for r in ps]
    for k in ("pc1", "pc2", "pc3"):
        # 10 significant digits printed: scores near 0 are compared on the PC's scale
        a = np.array([float(r[k]) for r in cs])
        b = np.array([float(r[k]) for r in ps])
        assert np.abs(a - b).max() <= 1e-9 * np.abs(a).max(), k


def test_same_embeddings_as_the_c_notebook(runs):
    c, py, _, c_stdout = runs
    cq = {r["point"]: r for r in read(c / "embedding_quality.csv")}
    pq = {r["point"]: r for r in read(py / "embedding_quality.csv")}
    assert list(pq) == ["mean_neutral", "mean_plus_happy", "mean_plus_angry"] == list(cq)
    for n in pq:
        assert close(cq[n]["scale"], pq[n]["scale"], 8)
        for k in ("rms_ratio", "rms_ratio_linear", "max_rel", "p99_rel", "bend_ratio",
                  "prior_rms", "prior_max"):
            assert close(cq[n][k], pq[n][k], 6), (n, k, cq[n][k], pq[n][k])
    # and the meshes themselves: the same OBJ coordinates to 1e-9 of the face's size
    for n in pq:
        a, b = (np.array([[float(x) for x in line.split()[1:4]]
                          for line in open(d / f"{n}.obj") if line.startswith("v ")])
                for d in (c, py))
        assert a.shape == b.shape
        assert np.abs(a - b).max() <= 1e-9 * np.abs(a).max()


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))


def test_without_face_study_the_notebook_names_the_path_it_tried(tmp_path, monkeypatch, capsys):
    """Its first two cells (settings, data) with EDGESPACE_SHARED pointing
    nowhere: it falls back to synthetic faces and says where it looked."""
    display = pytest.importorskip("IPython.display")
    with open(os.path.join(HERE, "01_faces.ipynb"), encoding="utf-8") as f:
        cells = [c for c in json.load(f)["cells"] if c["cell_type"] == "code"][:2]
    nowhere = tmp_path / "nowhere"
    monkeypatch.setenv("EDGESPACE_SHARED", str(nowhere))
    monkeypatch.setenv("EDGESPACE_NOTEBOOK_SMALL", "1")
    monkeypatch.setenv("EDGESPACE_NOTEBOOK_OUT", str(tmp_path / "out"))
    monkeypatch.delenv("EDGESPACE_NOTEBOOK_SYNTHETIC", raising=False)
    shown = []
    monkeypatch.setattr(display, "display", lambda *a, **k: shown.extend(a))
    scope = {}
    for c in cells:
        exec("".join(c["source"]), scope)
    tried = str(nowhere / "data" / "face-study")
    assert any(tried in getattr(m, "data", "") for m in shown)
    assert f"face-study was not found at {tried}" in capsys.readouterr().out
    assert scope["report"]["rows_added"] == 30   # 10 synthetic subjects x 3 expressions
