"""python/tests/run.py, which meson test starts the suites through: a
missing Debian package is a SKIP (exit 77) that names it, --check fails
instead (tools/setup.sh, so CI never skips), and what is there runs."""
import os
import subprocess
import sys

import pytest

import run
from conftest import SOURCE_ROOT


@pytest.fixture
def lacking(monkeypatch):
    """A group whose module no interpreter has."""
    monkeypatch.setitem(run.GROUPS, "absent", {"edgespace_no_such_module": "python3-nothing"})


def test_a_missing_package_is_a_skip_naming_it(lacking, capsys):
    assert run.main(["--need", "absent", "--", "-q"]) == 77
    out = capsys.readouterr().out
    assert out.startswith("SKIP: the Debian packages python3-nothing are missing")
    assert "tools/setup.sh" in out


def test_check_fails_instead(lacking, capsys):
    assert run.main(["--check"]) == 1
    assert "python3-nothing" in capsys.readouterr().err


def test_what_the_suites_need_is_here():
    """This suite is running, so the package group is complete, and
    tools/setup.sh installs every package run.py names."""
    assert run.missing(["package"]) == []
    with open(os.path.join(SOURCE_ROOT, "tools", "setup.sh")) as f:
        listed = f.read().split("\npackages=(\n")[1].split("\n)\n")[0]
    setup = [w for line in listed.splitlines() for w in line.split("#")[0].split()]
    for group in run.GROUPS.values():
        for pkg in group.values():
            assert pkg in setup, pkg
    r = subprocess.run([sys.executable, run.__file__, "--check"], capture_output=True, text=True)
    assert r.returncode == (1 if run.missing(run.GROUPS) else 0), r.stderr
