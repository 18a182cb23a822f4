"""python/tests/run.py — runs a pytest suite of the Python package, or says
which Debian packages it lacks.

meson test starts the Python suites through this script (with Debian's
/usr/bin/python3) rather than through `python3 -m pytest`, so that what is
missing is found when the tests run, not when meson configured the build
(installing the packages afterwards then needs no reconfigure), and so that a
machine without them reports a SKIP (exit status 77) naming the packages to
install instead of an import error. tools/setup.sh installs every package
named here and then runs `run.py --check`, which fails rather than skips:
CI, which runs setup.sh on a fresh machine, therefore runs every Python test
or goes red, never skips them quietly.

    run.py [--need GROUP]... [--] PYTEST-ARGS...   run pytest, or exit 77
    run.py --check                                  exit 1 unless all are there
"""
import importlib.util
import os
import shutil
import sys

# module -> the Debian 12 package that provides it, by what needs them
GROUPS = {
    # the binding and its pytest suite (python/tests)
    "package": {"cffi": "python3-cffi", "numpy": "python3-numpy",
                "pytest": "python3-pytest", "h5py": "python3-h5py"},
    # what the binding uses when present; the tests cover both ways, and CI
    # must see the installed way (tqdm bars, pandas tables)
    "optional": {"tqdm": "python3-tqdm", "pandas": "python3-pandas"},
    # executing notebooks-py/*.ipynb with Debian's python3 as the kernel
    "notebooks": {"nbconvert": "jupyter-nbconvert", "ipykernel": "python3-ipykernel"},
    # edgespace explore's server, the Jupyter widget, and the browser that
    # drives the page in test_explore.py and the widget in a classic notebook
    # (test_widgets.py)
    "explore": {"aiohttp": "python3-aiohttp", "ipywidgets": "python3-ipywidgets"},
    "browser": {"selenium": "python3-selenium"},
    # oracles: SciPy's fmin_l_bfgs_b, the minimizer of the published pipeline
    # (test_paper_oracle.py; skipped without it, and --check fails)
    "oracle": {"scipy": "python3-scipy"},
    # edgespace.mpl, the figures as matplotlib Axes (test_mpl.py; skipped
    # without it, and --check fails)
    "figures": {"matplotlib": "python3-matplotlib"},
}
PROGRAMS = {"notebooks": {"jupyter-nbconvert": "jupyter-nbconvert"},
            "browser": {"chromium": "chromium", "chromedriver": "chromium-driver",
                        "jupyter-notebook": "jupyter-notebook"}}
# files installed from elsewhere than Debian: three.js, from the npm registry
# (tools/setup.sh runs npm ci in python/edgespace/explore/web)
THREE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "edgespace",
                     "explore", "web", "node_modules", "three", "build", "three.module.js")
FILES = {"explore": {THREE: "three.js (npm ci in python/edgespace/explore/web)"}}


def missing(groups):
    """Debian packages the groups need that this interpreter or PATH lacks."""
    out = []
    for g in groups:
        for mod, pkg in GROUPS[g].items():
            if importlib.util.find_spec(mod) is None and pkg not in out:
                out.append(pkg)
        for prog, pkg in PROGRAMS.get(g, {}).items():
            if shutil.which(prog) is None and pkg not in out:
                out.append(pkg)
        for path, what in FILES.get(g, {}).items():
            if not os.path.exists(path) and what not in out:
                out.append(what)
    return out


def main(argv):
    if argv == ["--check"]:
        lack = missing(GROUPS)
        if lack:
            print(f"python: {sys.executable} lacks {', '.join(lack)}",
                  file=sys.stderr)
            return 1
        return 0
    groups = ["package"]
    while len(argv) >= 2 and argv[0] == "--need":
        groups.append(argv[1])
        argv = argv[2:]
    if argv[:1] == ["--"]:
        argv = argv[1:]
    lack = missing(groups)
    if lack:
        # meson shows the test as SKIP and prints this with --print-errorlogs
        print(f"SKIP: the Debian packages {' '.join(lack)} are missing for {sys.executable} "
              "(bash tools/setup.sh installs them)")
        return 77
    import pytest
    return pytest.main(argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
