"""Sizes and shape distances in the units geomorph and shapes users read:
centroid size beside the scale of `mean`, Kendall's rho beside the data-unit
Procrustes distances of `compare` and `gpa`. Oracle: R's shapes package
(riemdist, centroid.size) run live on the same configurations when Rscript
with shapes is installed (skipped otherwise; tests/procrustes/test_compare.c
holds a fixed table of riemdist values for es_compare_rho)."""
import io
import re
import shutil
import subprocess

import numpy as np
import pytest

import edgespace as es


def rscript(code):
    if not shutil.which("Rscript"):
        pytest.skip("Rscript is not installed")
    r = subprocess.run(["Rscript", "-e", "suppressMessages(library(shapes))", "-e", code],
                       capture_output=True, text=True)
    if r.returncode != 0 and "shapes" in r.stderr:
        pytest.skip("R package shapes is not installed (r-cran-shapes)")
    assert r.returncode == 0, r.stderr
    return np.array(r.stdout.split(), float)


def test_rho_and_centroid_size_against_r(store_path, faces_dir, tmp_path, cli):
    out = cli("gpa", store_path, "--name", "g").stdout
    assert re.search(r"mean centroid size [0-9.e+]+ \(data units\); rho to the mean: rms", out)
    r = cli("compare", store_path, "--gpa", "g", "-p", "9", "--no-figures", "-o", tmp_path / "c")
    assert "median rho" in r.stdout and "data units" in r.stdout
    rho = np.genfromtxt(tmp_path / "c" / "distances_rho.csv", delimiter=",", skip_header=1)[:, 1:]
    pairs = np.genfromtxt(tmp_path / "c" / "pairs.csv", delimiter=",", names=True, dtype=None,
                          encoding="utf-8")
    assert np.allclose(pairs["rho"], rho[pairs["i"] - 1, pairs["j"] - 1], rtol=0, atol=1e-15)
    assert np.allclose(rho, rho.T) and (np.diag(rho) == 0).all()
    aligned = tmp_path / "aligned.csv"
    cli("export", store_path, "--result", "gpa/g", "--table", "aligned", "--output", aligned)
    # riemdist of row 1 against rows 2..6, on the aligned configurations
    # (rho does not depend on their alignment)
    want = rscript(f"""
        a <- read.csv("{aligned}"); a <- as.matrix(a[, sapply(a, is.numeric)])
        k <- ncol(a) / 3; cfg <- function(i) matrix(a[i, ], k, 3)
        cat(sapply(2:6, function(j) riemdist(cfg(1), cfg(j))), sep = "\\n")""")
    # both take rho as acos of a cosine near 1: about 1e-8 absolute (R gives
    # 2e-8 for a shape against its own mirror image)
    assert np.allclose(rho[0, 1:6], want, rtol=0, atol=1e-7)
    # the centroid size of the neutral rows' meshes as ingested, averaged
    man = np.genfromtxt(faces_dir / "manifest.csv", delimiter=",", names=True, dtype=None,
                        encoding="utf-8")
    files = [str(faces_dir / f) for f, e in zip(man[man.dtype.names[0]], man["expression"])
             if e == "neutral"]
    cs = rscript("""
        f <- c({}); cat(mean(sapply(f, function(p) {{
          v <- grep("^v ", readLines(p), value = TRUE)
          centroid.size(do.call(rbind, lapply(strsplit(v, " +"), function(s) as.numeric(s[2:4]))))
        }})))""".format(", ".join(f'"{p}"' for p in files)))
    m = cli("mean", store_path, "--by", "expression", "--no-store").stdout
    assert "centroid size" in m.splitlines()[0]
    row = next(line.split() for line in m.splitlines() if line.startswith("neutral"))
    assert np.isclose(float(row[3]), cs[0], rtol=1e-5)   # printed with 6 digits
