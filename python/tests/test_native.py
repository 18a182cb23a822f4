"""The binding's view of the C API against the C compiler's: cffi lays out
the structs from the header text (ABI mode), so a mismatch would corrupt
memory silently. A C program compiled against the same headers prints
sizeof and offsetof of every struct and field cffi knows; they must agree.
Also: the library loaded is the one meson built, and its version is the
command's."""
import os
import re
import shutil
import subprocess
import sys

import pytest

import edgespace as es
from edgespace import _native
from conftest import BUILD_ROOT, SOURCE_ROOT


def _structs():
    out = []
    for name in es.ffi.list_types()[0]:   # typedef names
        t = es.ffi.typeof(name)
        if t.kind == "struct" and t.fields is not None:
            out.append((name, [f for f, _ in t.fields]))
    return out


def test_every_struct_matches_the_compiler(tmp_path):
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    structs = _structs()
    assert len(structs) > 40      # every public struct, not a handful
    lines = ["#include <stddef.h>", "#include <stdio.h>", "#include <edgespace/edgespace.h>",
             "int main(void) {"]
    for name, fields in structs:
        lines.append(f'    printf("{name} %zu\\n", sizeof({name}));')
        for f in fields:
            lines.append(f'    printf("{name}.{f} %zu\\n", offsetof({name}, {f}));')
    lines += ["    return 0;", "}"]
    src = tmp_path / "layout.c"
    src.write_text("\n".join(lines) + "\n")
    inc = os.path.dirname(_native.INCLUDE_DIR)   # .../include, holding edgespace/
    exe = tmp_path / "layout"
    r = subprocess.run([cc, "-std=c11", "-I", inc, "-I", os.path.join(BUILD_ROOT, "lib"),
                        str(src), "-o", str(exe)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    got = dict(line.rsplit(" ", 1) for line in
               subprocess.run([str(exe)], capture_output=True, text=True,
                              check=True).stdout.splitlines())
    bad = []
    for name, fields in structs:
        if int(got[name]) != es.ffi.sizeof(name):
            bad.append(f"sizeof({name}): C {got[name]}, cffi {es.ffi.sizeof(name)}")
        for f in fields:
            c, p = int(got[f"{name}.{f}"]), es.ffi.offsetof(name, f)
            if c != p:
                bad.append(f"offsetof({name}, {f}): C {c}, cffi {p}")
    assert not bad, "\n".join(bad)


def test_enum_values_match_the_headers():
    assert es.lib.ES_OK == 0 and es.lib.ES_ETOPOLOGY == 11
    assert es.lib.ES_SYNTH_FACE == 4 and es.lib.ES_CMAP_GREYS == 2


def test_the_library_is_the_one_built(cli):
    if "EDGESPACE_LIBRARY" in os.environ:
        assert os.path.samefile(es.LIBRARY_PATH, os.environ["EDGESPACE_LIBRARY"])
    assert os.path.isfile(os.path.join(es.INCLUDE_DIR, "es_study.h"))
    assert cli("--version").stdout.split() == ["edgespace", es.version()]
    assert es.__version__ == es.version()


def test_declarations_are_the_headers():
    decl = _native.declarations(_native.INCLUDE_DIR)
    # what cffi cannot read is gone; what the API declares is there
    # (integer constants stay: cffi reads them as array sizes)
    rest = [l for l in decl.split("\n") if not re.fullmatch(r"\s*#\s*define\s+\w+\s+\d+\s*", l)]
    assert "#" not in "\n".join(rest) and "ES_API" not in decl and "/*" not in decl
    assert "#define ES_VARIATION_MAX_AXES 8" in decl or not es.has_figures()
    assert "es_status es_study_embed(" in " ".join(decl.split())
    assert es.has_figures() == _native.has("es_render")


def _import_in_a_fresh_interpreter(tmp_path, code, **env_extra):
    """Run code in Debian's python3 from /, the package found the way
    tools/setup.sh makes it found (a .pth file naming python/ in a site
    directory), with no EDGESPACE_* variables."""
    site = tmp_path / "site"
    site.mkdir(exist_ok=True)
    (site / "edgespace.pth").write_text(os.path.dirname(os.path.dirname(es.__file__)) + "\n")
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("EDGESPACE") and k != "PYTHONPATH"}
    env.update(env_extra)
    # the .pth's entry goes ahead of the interpreter's own path, where another
    # checkout's setup.sh may have left an edgespace.pth of its own
    boot = (f"import site, sys; n = len(sys.path); site.addsitedir({str(site)!r}); "
            "sys.path[:] = sys.path[n:] + sys.path[:n]; " + code)
    return subprocess.run([sys.executable, "-c", boot], cwd="/", env=env,
                          capture_output=True, text=True)


def test_set_up_makes_import_edgespace_work(tmp_path):
    built = os.path.join(SOURCE_ROOT, "build", "lib", "libedgespace.so")
    if not os.path.isfile(built):
        pytest.skip(f"no build/ in this checkout ({built}): the library is found elsewhere")
    r = _import_in_a_fresh_interpreter(
        tmp_path, "import edgespace as es; print(es.LIBRARY_PATH); print(es.INCLUDE_DIR); "
                  "print(es.version())")
    assert r.returncode == 0, r.stderr
    lib_path, inc, version = r.stdout.split()
    assert os.path.samefile(lib_path, built) and version == es.version()
    assert os.path.samefile(inc, os.path.join(SOURCE_ROOT, "lib", "include", "edgespace"))


def test_a_wrong_library_path_is_a_load_error(tmp_path):
    r = _import_in_a_fresh_interpreter(
        tmp_path, "import edgespace", EDGESPACE_LIBRARY=str(tmp_path / "nope.so"))
    assert r.returncode == 1
    assert f"LoadError: EDGESPACE_LIBRARY='{tmp_path / 'nope.so'}' is not a file" in r.stderr
