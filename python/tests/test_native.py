"""The binding's view of the C API against the C compiler's: cffi lays out
the structs from the header text (ABI mode), so a mismatch would corrupt
memory silently. A C program compiled against the same headers prints
sizeof and offsetof of every struct and field cffi knows; they must agree.
Also: the library loaded is the one meson built, and its version is the
command's."""
import os
import shutil
import subprocess

import pytest

import edgespace as es
from edgespace import _native
from conftest import BUILD_ROOT


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
    assert "#" not in decl and "ES_API" not in decl and "/*" not in decl
    assert "es_status es_study_embed(" in " ".join(decl.split())
    assert es.has_figures() == _native.has("es_render")
