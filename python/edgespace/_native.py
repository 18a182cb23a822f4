"""python/edgespace/_native.py — libedgespace loaded through cffi (ABI mode).

The declarations handed to cffi are the library's own public headers
(lib/include/edgespace/es_*.h, in the order edgespace.h includes them),
stripped of comments and preprocessor lines at import, so the binding never
carries a second copy of the API that could drift from the C one.
tests/test_native.py compiles a C program that prints sizeof/offsetof of
every struct cffi laid out and compares.

Where the pieces are found (first hit wins):
  library  $EDGESPACE_LIBRARY (a path), then <checkout>/build/lib/libedgespace.so
           when this package sits in a source checkout (python/edgespace), then
           the system's libedgespace (meson install; ctypes.util.find_library);
  headers  $EDGESPACE_INCLUDE (the folder holding es_core.h), then the
           checkout's lib/include/edgespace, then <prefix>/include/edgespace
           beside the library that was found, /usr/local and /usr.
"""
import ctypes.util
import os
import re

import cffi

_HERE = os.path.dirname(os.path.abspath(__file__))
_CHECKOUT = os.path.dirname(os.path.dirname(_HERE))   # python/edgespace -> repo root


class LoadError(ImportError):
    """libedgespace or its headers could not be found or read."""


def _library_path():
    env = os.environ.get("EDGESPACE_LIBRARY")
    if env:
        if not os.path.isfile(env):
            raise LoadError(f"EDGESPACE_LIBRARY={env!r} is not a file")
        return env
    built = os.path.join(_CHECKOUT, "build", "lib", "libedgespace.so")
    if os.path.isfile(built):
        return built
    found = ctypes.util.find_library("edgespace")
    if found:
        return found
    raise LoadError("libedgespace not found: build it (bash tools/setup.sh build), install it "
                    "(meson install -C build) or set EDGESPACE_LIBRARY to libedgespace.so")


def _include_dir(libpath):
    cands = []
    env = os.environ.get("EDGESPACE_INCLUDE")
    if env:
        cands.append(env)
    cands.append(os.path.join(_CHECKOUT, "lib", "include", "edgespace"))
    if os.path.isabs(libpath):
        d = os.path.dirname(os.path.realpath(libpath))
        for up in (1, 2):   # <prefix>/lib/ and <prefix>/lib/<multiarch>/
            prefix = os.path.normpath(os.path.join(d, *([".."] * up)))
            cands.append(os.path.join(prefix, "include", "edgespace"))
    cands += ["/usr/local/include/edgespace", "/usr/include/edgespace"]
    for c in cands:
        if os.path.isfile(os.path.join(c, "es_core.h")) and \
                os.path.isfile(os.path.join(c, "edgespace.h")):
            return c
    raise LoadError("the edgespace headers (es_core.h) were not found in " + ", ".join(cands) +
                    "; set EDGESPACE_INCLUDE")


def _header_order(incdir):
    """The es_*.h files in the order edgespace.h includes them (es_config.h
    is generated and holds only a macro)."""
    with open(os.path.join(incdir, "edgespace.h"), encoding="utf-8") as f:
        text = f.read()
    names = re.findall(r'#include\s+"(es_[a-z0-9_]+\.h)"', text)
    return [n for n in names if n != "es_config.h"]


def declarations(incdir):
    """C declarations of the public headers, as cffi's cdef reads them."""
    out = []
    for name in _header_order(incdir):
        with open(os.path.join(incdir, name), encoding="utf-8") as f:
            t = f.read()
        t = re.sub(r"/\*.*?\*/", " ", t, flags=re.S)
        t = re.sub(r"//[^\n]*", "", t)
        # the extern "C" wrapper, which sits between preprocessor lines
        t = re.sub(r'#ifdef\s+__cplusplus\s*\n\s*(extern\s+"C"\s*\{|\})\s*\n\s*#endif', "", t)
        t = re.sub(r"\\\n", " ", t)
        # preprocessor lines go, except integer constants (array sizes such
        # as ES_VARIATION_MAX_AXES), which cffi's cdef reads
        t = "\n".join(line for line in t.split("\n")
                      if not line.lstrip().startswith("#")
                      or re.fullmatch(r"\s*#\s*define\s+\w+\s+\d+\s*", line))
        t = re.sub(r"\bES_API\b", "", t)
        t = re.sub(r"__attribute__\s*\(\(.*?\)\)", "", t)
        out.append(t)
    return "\n".join(out)


LIBRARY_PATH = _library_path()
INCLUDE_DIR = _include_dir(LIBRARY_PATH)

ffi = cffi.FFI()
try:
    ffi.cdef(declarations(INCLUDE_DIR))
except cffi.CDefError as e:   # a header construct the binding cannot read
    raise LoadError(f"reading the headers in {INCLUDE_DIR}: {e}") from e
try:
    # RTLD_NODELETE: the library stays mapped after cffi's handle closes at
    # interpreter exit, when objects that free library memory (ffi.gc, numpy
    # views of it) may still be collected; without it such a collection
    # called into unmapped code (a SIGSEGV after the test suite had passed,
    # once ipywidgets' imports had changed the order of the exit)
    lib = ffi.dlopen(LIBRARY_PATH, ffi.RTLD_NOW | ffi.RTLD_NODELETE)
except OSError as e:
    raise LoadError(f"loading {LIBRARY_PATH}: {e}") from e


def has(symbol):
    """True if the loaded library exports `symbol` (figures are optional)."""
    try:
        getattr(lib, symbol)
        return True
    except AttributeError:
        return False
