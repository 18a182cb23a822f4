"""python/edgespace/_arrays.py — numpy arrays across the C boundary without copies.

The library is column-major with explicit leading dimensions: an R x C
es_mat with ld = R is the same memory as a C-order numpy array of shape
(C, R). So an (N, E) float64 C-order array of N length vectors is handed to
the library as the E x N matrix it expects, positions (V, 3) are the 3 x V
xyz arrays of es_mesh.h, and faces (F, 3) int64 are its 3 x F face lists.
Inputs in that layout pass by pointer (ffi.from_buffer); anything else
(another dtype, a transposed view) is converted once. Outputs are written by
the library straight into fresh numpy arrays, and arrays the library
allocated (results read back, fitted PCAs) become read-only numpy views that
keep their owner alive.
"""
import operator

import numpy as np

from ._native import ffi, lib


def f64(a, shape=None, name="array"):
    """a as a C-contiguous float64 array (no copy when it already is one),
    checked against shape (None entries match anything)."""
    arr = np.ascontiguousarray(a, dtype=np.float64)
    _check_shape(arr, shape, name)
    return arr


def i64(a, shape=None, name="array"):
    arr = np.ascontiguousarray(a, dtype=np.int64)
    _check_shape(arr, shape, name)
    return arr


def index(x, name="index"):
    """x as a Python int if it is an integer (int, numpy integer, anything
    with __index__); a TypeError naming it otherwise: 2.7 is not row 2."""
    if isinstance(x, (bool, np.bool_)):
        raise TypeError(f"{name} must be an integer, not a bool")
    try:
        return operator.index(x)
    except TypeError:
        raise TypeError(f"{name} must be an integer, not {type(x).__name__} {x!r}") from None


def indices(a, shape=(None,), name="indices"):
    """An int64 array of integer indices; floats (and bools, a mask here
    would be read as rows 0 and 1) are refused rather than truncated."""
    arr = np.asarray(a)
    if arr.size and arr.dtype.kind not in "iu":
        raise TypeError(f"{name} must be integers, not {arr.dtype}")
    return i64(arr, shape, name)


def out_array(out, shape, name="out"):
    """out, checked to be an array the library may write shape float64
    elements into: a writable, C-contiguous float64 numpy array (bytes, a
    read-only array or memory map, a view of another dtype are refused)."""
    if not isinstance(out, np.ndarray):
        raise TypeError(f"{name} must be a numpy array, not {type(out).__name__}")
    if not out.flags.writeable:
        raise ValueError(f"{name} is read-only")
    if out.shape != tuple(shape) or out.dtype != np.float64 or not out.flags.c_contiguous:
        raise ValueError(f"{name} must be a C-contiguous float64 array of shape {tuple(shape)}")
    return out


def _check_shape(arr, shape, name):
    if shape is None:
        return
    if arr.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, arr.shape)):
        want = "(" + ", ".join("*" if s is None else str(s) for s in shape) + ")"
        raise ValueError(f"{name}: shape {arr.shape}, want {want}")


def dptr(arr):
    """double * into a float64 array from f64() (NULL for None)."""
    if arr is None:
        return ffi.NULL
    return ffi.from_buffer("double[]", arr)


def iptr(arr):
    if arr is None:
        return ffi.NULL
    return ffi.from_buffer("int64_t[]", arr)


def mat(arr, writable=False):
    """An es_mat over a C-order (cols, rows) float64 array: the rows x cols
    column-major matrix in the same memory (ld = rows); writable: the
    library writes it (cffi refuses a read-only buffer then)."""
    m = ffi.new("es_mat *")
    cols, rows = arr.shape
    buf = ffi.from_buffer("double[]", arr, require_writable=writable)
    m.data = buf
    m.rows, m.cols, m.ld = rows, cols, rows
    return m, buf   # the struct only points: keep buf alive with it


class _Owned:
    """A library-allocated buffer seen by numpy (__array_interface__); it
    holds `keep` (the owning cdata, freed when the last view goes)."""

    def __init__(self, keep, addr, shape, typestr):
        self._keep = keep
        self.__array_interface__ = {"data": (addr, True), "shape": tuple(shape),
                                    "typestr": typestr, "version": 3}


def view(ptr, shape, owner, dtype="f8"):
    """A read-only numpy view of shape (C order) over library memory at ptr,
    keeping owner (whatever frees it) alive."""
    n = int(np.prod(shape)) if len(shape) else 1
    if n == 0 or ptr == ffi.NULL:
        return np.zeros(shape, dtype=dtype)
    typestr = "<" + dtype
    return np.asarray(_Owned(owner, int(ffi.cast("uintptr_t", ptr)), shape, typestr))


class Freed:
    """Owner of memory the library allocated through a context (es_free)."""

    def __init__(self, ctx, ptr):
        self._ctx = ctx
        self.ptr = ptr

    # ffi.NULL and es_free bound here: at interpreter exit this may run after
    # the module's globals are cleared
    def __del__(self, _null=ffi.NULL, _free=lib.es_free):
        if self.ptr is not None and self.ptr != _null:
            _free(self._ctx.ptr, self.ptr)
            self.ptr = None


def owned(ctx, ptr, free):
    """ptr under ffi.gc with `free` as destructor; the destructor's closure
    holds the Context, which must outlive memory allocated through it."""
    return ffi.gc(ptr, lambda p, _ctx=ctx: free(p))


def string(p):
    """A C string (NULL: None) as str."""
    if p == ffi.NULL:
        return None
    return ffi.string(p).decode("utf-8", "replace")


def cbytes(s, name="string"):
    """str (or path) -> UTF-8 bytes for a C string; None stays None. A NUL
    inside would cut the string short where C reads it: refused."""
    if s is None:
        return None
    b = s if isinstance(s, bytes) else str(s).encode("utf-8")
    if b"\0" in b:
        raise ValueError(f"{name} {s!r} contains a NUL character")
    return b


class CStrings:
    """A list of str as const char *const * (kept alive with the object)."""

    def __init__(self, items, name="string"):
        self._bufs = [ffi.new("char[]", cbytes(s, name)) for s in items]
        self.ptr = ffi.new("const char *[]", self._bufs) if self._bufs else ffi.NULL

    def __len__(self):
        return len(self._bufs)


def cstr(s, name="string"):
    """str -> char[] (None: NULL)."""
    if s is None:
        return ffi.NULL
    return ffi.new("char[]", cbytes(s, name))


def struct_dict(cdata, ctype):
    """The fields of a struct as a dict of Python values (char arrays as str)."""
    out = {}
    for name, field in ffi.typeof(ctype).fields:
        v = getattr(cdata, name)
        if field.type.kind == "array":
            if field.type.item.cname == "char":
                v = ffi.string(v).decode("utf-8", "replace")
            else:
                v = [v[i] for i in range(field.type.length)]
        elif field.type.kind == "primitive" and field.type.cname in ("int", "_Bool"):
            v = int(v)
        out[name] = v
    return out
