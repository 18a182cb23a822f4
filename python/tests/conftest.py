"""python/tests/conftest.py — fixtures of the binding's tests.

The tests run on data the library makes itself (es_synth's face family:
subjects x neutral/happy/angry, written as OBJ with a manifest), ingested by
the binding into a store; the CLI (`edgespace`, $EDGESPACE, as meson test
passes it) runs on copies of the same store so its CSV outputs can be
compared with the arrays bit for bit.
"""
import os
import shutil
import subprocess

import pytest

import edgespace as es

SOURCE_ROOT = os.environ.get(
    "EDGESPACE_SOURCE_ROOT",
    os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
BUILD_ROOT = os.environ.get("EDGESPACE_BUILD_ROOT", os.path.join(SOURCE_ROOT, "build"))


def cli_path():
    return os.environ.get("EDGESPACE", os.path.join(BUILD_ROOT, "tools", "edgespace"))


@pytest.fixture(scope="session")
def cli():
    """Run `edgespace ARGS...`; returns CompletedProcess (check=True by default)."""
    exe = cli_path()
    if not os.access(exe, os.X_OK):
        pytest.skip(f"the edgespace command is not built ({exe})")

    def run(*args, check=True):
        r = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
        if check and r.returncode != 0:
            raise AssertionError(f"edgespace {' '.join(map(str, args))}: exit {r.returncode}\n"
                                 f"{r.stderr}")
        return r
    return run


@pytest.fixture(scope="session")
def faces_dir(tmp_path_factory):
    """Synthetic faces (6 subjects x 3 expressions) as OBJ + manifest.csv."""
    d = tmp_path_factory.mktemp("faces")
    es.synth("face", n=6, directory=d, ctx=es.Context(progress=None))
    return d


@pytest.fixture(scope="session")
def base_store(faces_dir, tmp_path_factory):
    """A store of the synthetic faces, ingested by the binding; tests copy it."""
    path = tmp_path_factory.mktemp("store") / "faces.h5"
    es.ingest(path, manifest=faces_dir / "manifest.csv", ctx=es.Context(progress=None))
    return path


def copy_store(src, dst):
    """A copy of a store with its results: the file and, for format 3, the
    folder of result files beside it (`<store>.results/`), as the README
    says to copy them."""
    shutil.copyfile(src, dst)
    side = f"{src}.results"
    if os.path.isdir(side):
        shutil.copytree(side, f"{dst}.results")
    return dst


@pytest.fixture
def store_path(base_store, tmp_path):
    """A fresh copy of the synthetic store for one test."""
    p = tmp_path / "faces.h5"
    shutil.copyfile(base_store, p)
    return p


@pytest.fixture
def ctx():
    """A quiet context (no progress bars) with the library's default seed."""
    return es.Context(progress=None)
