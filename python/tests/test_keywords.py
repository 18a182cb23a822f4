"""The keywords of README "Options" (python/README.md "Keywords"): the new
names work, the old ones give the same result with one DeprecationWarning
naming the new keyword, and both at once is a TypeError.

Oracle: the old spelling's result, computed by the call as it was before
the rename, against the new one's, array for array; the row selection
against numpy's comparison of the label column."""
import warnings

import numpy as np
import pytest

import edgespace as es


def one_warning(fn, new):
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        out = fn()
    dep = [x for x in w if issubclass(x.category, DeprecationWarning)]
    assert len(dep) == 1 and f"is now {new}=" in str(dep[0].message), [str(x.message) for x in w]
    return out


def test_where_and_components_beside_the_old_names(store_path, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as s:
        happy = np.flatnonzero(np.asarray(s.label("expression")) == "happy")
        assert np.array_equal(s.select(where="expression=happy"), happy)
        assert np.array_equal(one_warning(lambda: s.select(filter="expression=happy"), "where"),
                              happy)
        new = s.mean(by="subject", where="expression=happy")
        old = one_warning(lambda: s.mean(by="subject", filter="expression=happy"), "where")
        assert np.array_equal(new.means, old.means) and new.groups == old.groups
        p = s.pca(where="expression=happy", components=2)
        q = one_warning(lambda: s.pca(filter="expression=happy", components=2), "where")
        r = one_warning(lambda: s.pca(where="expression=happy", ncomp=2), "components")
        assert p.ncomp == q.ncomp == r.ncomp == 2
        assert np.array_equal(p.eigenvalues, r.eigenvalues)
        d = s.diff(None, pair_by="subject", column="expression", from_="neutral", to="happy")
        e = one_warning(lambda: s.diff(None, key="subject", column="expression",
                                       from_="neutral", to="happy"), "pair_by")
        assert np.array_equal(d.mean, e.mean) and d.npairs == e.npairs > 0
        with pytest.raises(TypeError, match="not both"):
            s.pca(components=2, ncomp=3)
        with pytest.raises(TypeError, match="not both"):
            s.select(where="expression=happy", filter="expression=sad")


def test_module_pca_components(store_path, ctx):
    with es.Store(store_path, ctx=ctx) as s:
        L = s.lengths()
    a = es.pca(L, components=3, ctx=ctx)
    b = one_warning(lambda: es.pca(L, ncomp=3, ctx=ctx), "components")
    assert a.ncomp == b.ncomp == 3 and np.allclose(a.eigenvalues, b.eigenvalues)


def test_gpa_components_beside_npc(store_path, ctx):
    with es.Store(store_path, write=True, ctx=ctx) as s:
        rows = s.select(where="expression=happy")
        a = s.gpa("new", rows=rows, components=2)
        b = one_warning(lambda: s.gpa("old", rows=rows, npc=2), "components")
    assert np.array_equal(a.pc_sdev, b.pc_sdev) and len(a.pc_sdev) == 2
    assert np.array_equal(a.pc_scores, b.pc_scores)


def test_export_meshes_format_beside_fmt(store_path, ctx, tmp_path):
    with es.Store(store_path, ctx=ctx) as s:
        rows = s.select(where="expression=happy")
        s.export_meshes(tmp_path / "new", rows=rows, format="off")
        one_warning(lambda: s.export_meshes(tmp_path / "old", rows=rows, fmt="off"), "format")
    new, old = sorted((tmp_path / "new").iterdir()), sorted((tmp_path / "old").iterdir())
    assert [p.name for p in new] == [p.name for p in old] and new[0].suffix == ".off"
    assert all(a.read_bytes() == b.read_bytes() for a, b in zip(new, old))


def test_mesh_write_format_beside_fmt(store_path, ctx, tmp_path):
    with es.Store(store_path, ctx=ctx) as s:
        m = s.mesh
        m.write(tmp_path / "new.dat", format="off")
        one_warning(lambda: m.write(tmp_path / "old.dat", fmt="off"), "format")
        with pytest.raises(TypeError):
            m.write(tmp_path / "both.dat", format="off", fmt="off")
        with pytest.raises(ValueError, match="'xyz'.*obj"):
            m.write(tmp_path / "bad.dat", format="xyz")
    assert (tmp_path / "new.dat").read_bytes() == (tmp_path / "old.dat").read_bytes()
    assert (tmp_path / "new.dat").read_bytes().startswith(b"OFF")


def test_explore_module_components_beside_pcs(tmp_path):
    """python -m edgespace.explore takes --components as edgespace explore
    does; --pcs still parses, says its new name, and is checked the same."""
    import subprocess
    import sys

    def explore(*args):
        return subprocess.run([sys.executable, "-m", "edgespace.explore",
                               str(tmp_path / "none.h5"), *args],
                              capture_output=True, text=True, timeout=60)
    r = explore("--pcs", "-1")
    assert r.returncode == 2 and "--pcs K is now --components K" in r.stderr, r.stderr
    assert "--components wants 0 (all) or more" in r.stderr
    r = explore("--components", "-1")
    assert r.returncode == 2 and "is now" not in r.stderr and "--components wants" in r.stderr
    r = explore("--components", "2", "--pcs", "2")
    assert r.returncode == 2 and "not both" in r.stderr
