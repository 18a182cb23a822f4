"""python/edgespace/_errors.py — the library's status codes as Python exceptions.

Every fallible C call returns an es_status and leaves its message on the
context (es_ctx_errmsg); check() turns a non-zero status into the exception
of its kind carrying that message, so `except ValueError` catches a bad
argument and `except LookupError` a missing row or result, as Python code
expects, while `except edgespace.Error` catches everything the library says.
"""
from ._native import ffi, lib


class Error(Exception):
    """A libedgespace failure. `status` is the es_status code, `code` its
    name (ES_EINVAL, ...), str() the library's message."""

    def __init__(self, message, status):
        super().__init__(message)
        self.status = status
        self.code = _NAMES.get(status, f"status {status}")


class NoMemoryError(Error, MemoryError):
    """ES_ENOMEM: an allocation failed."""


class InvalidError(Error, ValueError):
    """ES_EINVAL: an argument or input value is invalid."""


class RangeError(Error, OverflowError):
    """ES_ERANGE: a size or index is out of range or overflows."""


class IOFailure(Error, OSError):
    """ES_EIO: a file could not be opened, read or written."""


class FormatError(Error, ValueError):
    """ES_EFORMAT: a file or expression is malformed."""


class NumericError(Error, ArithmeticError):
    """ES_ENUMERIC: a numerical routine failed."""


class ConvergenceError(Error, ArithmeticError):
    """ES_ENOCONV: an iteration did not converge within its limits."""


class NotFoundError(Error, LookupError):
    """ES_ENOTFOUND: a named row, group, point, column or file does not exist."""


class ExistsError(Error):
    """ES_EEXIST: the thing to create exists already."""


class MismatchError(Error, ValueError):
    """ES_EMISMATCH: inputs disagree (topology, vertex count, dimension)."""


class TopologyError(Error, ValueError):
    """ES_ETOPOLOGY: a face list is not an oriented 2-manifold."""


class CancelledError(Error):
    """ES_ECANCELED: the work was cancelled (es_ctx_cancel); nothing was stored."""


_CLASSES = {
    lib.ES_ENOMEM: NoMemoryError, lib.ES_EINVAL: InvalidError, lib.ES_ERANGE: RangeError,
    lib.ES_EIO: IOFailure, lib.ES_EFORMAT: FormatError, lib.ES_ENUMERIC: NumericError,
    lib.ES_ENOCONV: ConvergenceError, lib.ES_ENOTFOUND: NotFoundError,
    lib.ES_EEXIST: ExistsError, lib.ES_EMISMATCH: MismatchError,
    lib.ES_ETOPOLOGY: TopologyError, lib.ES_ECANCELED: CancelledError,
}
_NAMES = dict(ffi.typeof("es_status").elements)   # value -> name


def error_class(status):
    """The exception class of an es_status code."""
    return _CLASSES.get(status, Error)


def check(ctx, status):
    """Raise the exception of `status` with the message on ctx (an es_ctx *)."""
    if status == 0:
        return
    msg = ffi.string(lib.es_ctx_errmsg(ctx)).decode("utf-8", "replace")
    if not msg:
        msg = ffi.string(lib.es_strerror(status)).decode()
    raise error_class(status)(msg, status)
