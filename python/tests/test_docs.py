"""The snippets of datasets-spec that read our files from other tools run as
written: store-format.md's h5py block (on a store with labels and on one
without: h5py 3.7 refuses a None index and returns h5py.Empty for a null
dataspace), its R blocks (hdf5r, rhdf5) when R and the package are
installed, and statismo.md's h5py block. Their values are checked against
the binding's."""
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

import edgespace as es
from conftest import SOURCE_ROOT


def blocks(doc, lang):
    with open(os.path.join(SOURCE_ROOT, "datasets-spec", doc), encoding="utf-8") as f:
        text = f.read()
    return re.findall(r"```" + lang + r"\n(.*?)```", text, flags=re.S)


@pytest.fixture(scope="module")
def doc_store(tmp_path_factory):
    """A store of 21 rows (the snippets read rows 10..19) with labels."""
    d = tmp_path_factory.mktemp("doc")
    ctx = es.Context(progress=None)
    es.synth("face", n=7, directory=d / "faces", ctx=ctx)
    es.ingest(d / "faces.h5", manifest=d / "faces" / "manifest.csv", ctx=ctx)
    return d


def run_python_block(code, cwd):
    old = os.getcwd()
    os.chdir(cwd)
    try:
        ns = {}
        exec(compile(code, "snippet", "exec"), ns)
        return ns
    finally:
        os.chdir(old)


def test_h5py_snippet_of_the_store_format(doc_store, tmp_path, ctx):
    (code,) = blocks("store-format.md", "python")
    ns = run_python_block(code, doc_store)
    with es.Store(doc_store / "faces.h5", ctx=ctx) as s:
        L = s.lengths()
        assert np.array_equal(ns["block"], L[10:20])
        assert np.array_equal(ns["raw"], s.scales()[:, None] * L)
        assert list(ns["ids"]) == list(s.ids)
        assert list(ns["expr"]) == list(s.label("expression"))
        assert np.array_equal(ns["edges"], s.edges) and np.array_equal(ns["faces"], s.faces)
        assert np.array_equal(ns["xyz0"], s.positions(0))
        assert ns["cols"] == s.columns and ns["kind"] == "mesh"
    # a store without label columns: the null dataspace
    files = sorted((doc_store / "faces").glob("*.obj"))[:2]
    es.ingest(tmp_path / "faces.h5", files=files, ctx=ctx)
    code = code.replace('expr = f["labels/expression"].asstr()[:]', "")
    assert run_python_block(code, tmp_path)["cols"] == []


R_CHECKS = {
    "hdf5r": 'cat(dim(L), dim(blk), ids[1], lab[1], fv, cols, sprintf("%.17g", L[1:3, 2]), '
             'sprintf("%.17g", raw[5, 3]), sep = "\\n")\n',
    "rhdf5": 'cat(dim(L), dim(blk), ids[1], lab[1], fv, sprintf("%.17g", L[1:3, 2]), '
             'sep = "\\n")\n',
}


@pytest.mark.parametrize("package", ["hdf5r", "rhdf5"])
def test_r_snippets_of_the_store_format(package, doc_store, ctx):
    rscript = shutil.which("Rscript")
    if rscript is None:
        pytest.skip("R is not installed")
    if subprocess.run([rscript, "-e", f"library({package})"], capture_output=True).returncode:
        pytest.skip(f"the R package {package} is not installed")
    (code,) = [b for b in blocks("store-format.md", "r") if f"library({package})" in b]
    r = subprocess.run([rscript, "-e", code + R_CHECKS[package]], cwd=doc_store,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = r.stdout.split()
    with es.Store(doc_store / "faces.h5", ctx=ctx) as s:
        L = s.lengths()
        N, E = L.shape
        want = [str(E), str(N), str(E), "10", s.ids[0], s.label("expression")[0], "3"]
        if package == "hdf5r":
            want += s.columns
        want += ["%.17g" % v for v in L[1, :3]]   # R's column 2 is row 1
        if package == "hdf5r":
            want.append("%.17g" % (s.scales()[2] * L[2, 4]))
    assert out == want


def test_h5py_snippet_of_the_statismo_format(doc_store, tmp_path, ctx):
    (code,) = blocks("statismo.md", "python")
    with es.Store(doc_store / "faces.h5", write=True, ctx=ctx) as s:
        g = s.gpa("g")
        s.export_statismo(tmp_path / "model.h5", gpa="g")
        faces = s.faces
    ns = run_python_block(code, tmp_path)
    assert np.array_equal(ns["faces"], faces)
    assert np.allclose(ns["mean"], g.mean, rtol=0, atol=1e-6 * np.abs(g.mean).max())
    want = g.mean + 2 * g.pc_sdev[0] * g.pc_loadings[0]
    assert np.allclose(ns["shape"], want, rtol=0, atol=1e-5 * np.abs(want).max())
