"""python/edgespace/_context.py — the library's context (es_ctx) from Python:
the seed of everything random, warnings, and progress of long work.

The library keeps one context per thread and nothing global; so does the
binding: every call takes ctx=None (this thread's default context) or a
Context of its own. Objects that hold library memory (stores, PCAs, meshes)
keep their context alive.

Progress (es_ctx_set_progress) reaches `progress`: a callable
progress(what, done, total), True or "auto" (a tqdm bar per stage when tqdm
is installed, else nothing), or None/False (silent); the default context's
is "auto". Warnings the library logs become EdgespaceWarning
(warnings.warn); notes go to the logging logger "edgespace" at INFO.
"""
import logging
import sys
import threading
import warnings

from ._errors import check
from ._native import ffi, lib

_log = logging.getLogger("edgespace")


class EdgespaceWarning(UserWarning):
    """A warning logged by libedgespace (es__warn)."""


def _in_kernel():
    """True in a Jupyter kernel (an IPython shell with a kernel). Not "is
    ipykernel imported": ipywidgets imports it in any process."""
    ip = sys.modules.get("IPython")
    shell = ip.get_ipython() if ip is not None and hasattr(ip, "get_ipython") else None
    return getattr(shell, "kernel", None) is not None


def _tqdm():
    """tqdm's bar class for where we run: widgets in a Jupyter kernel that has
    ipywidgets 7 or later (tqdm.notebook's need: with Debian 12's ipywidgets
    6 its bars raise AttributeError, and its widget messages are ones nbclient
    cannot read, so a notebook executed by nbconvert fails with KeyError
    'state'), text elsewhere; None where neither would read well (a kernel
    without usable widgets, where text bars leave blank lines) or without
    tqdm."""
    try:
        if _in_kernel():
            import ipywidgets
            if int(str(getattr(ipywidgets, "__version__", "0")).split(".")[0]) < 7:
                return None
            from tqdm.notebook import tqdm
        else:
            from tqdm.std import tqdm
    except (ImportError, ValueError):
        return None
    return tqdm


class _TqdmProgress:
    """One tqdm bar per stage name, closed when its stage ends."""

    delay = 1.0   # seconds before a stage's bar appears

    def __init__(self, tqdm):
        self._tqdm = tqdm
        self._bar = None
        self._what = None

    def __call__(self, what, done, total):
        if self._bar is None or what != self._what:
            self.close()
            self._what = what
            # delay: only stages that last show a bar (many take milliseconds)
            self._bar = self._tqdm(total=max(int(total), 1), desc=what, leave=False,
                                   delay=self.delay)
        if done > self._bar.n:   # update() keeps tqdm's delay and rate limits
            self._bar.update(int(done) - self._bar.n)
        if done >= total:
            self.close()

    def close(self):
        if self._bar is not None:
            self._bar.close()
            self._bar = None


class Context:
    """An es_ctx: seed, progress callback, warnings.

    seed      everything random the library does (randomized PCA, permutation
              tests, synthetic data) starts from it; default 0x5eed, the
              library's and the notebooks'.
    progress  callable(what, done, total), True/"auto" (a tqdm bar per stage
              that lasts over a second, when tqdm is installed: text on a
              terminal, a widget in Jupyter with ipywidgets) or None/False.
    """

    def __init__(self, seed=None, progress="auto"):
        p = ffi.new("es_ctx **")
        status = lib.es_ctx_new(p)
        if status:
            raise MemoryError("es_ctx_new failed")
        self._ptr = ffi.gc(p[0], lib.es_ctx_free)
        self._progress_fn = None
        self._progress_cb = None
        self._callback_error = None
        self._log_cb = ffi.callback("es_log_fn", self._on_log)
        lib.es_ctx_set_log(self._ptr, self._log_cb, ffi.NULL)
        if seed is not None:
            self.seed = seed
        self.progress = progress

    # -- seed -------------------------------------------------------------
    @property
    def seed(self):
        return int(lib.es_ctx_seed(self._ptr))

    @seed.setter
    def seed(self, value):
        lib.es_ctx_set_seed(self._ptr, int(value) & 0xFFFFFFFFFFFFFFFF)

    # -- progress ---------------------------------------------------------
    @property
    def progress(self):
        return self._progress_fn

    @progress.setter
    def progress(self, fn):
        if fn is True or fn == "auto":
            t = _tqdm()
            fn = _TqdmProgress(t) if t else None
        elif fn is False:
            fn = None
        elif fn is not None and not callable(fn):
            raise TypeError("progress must be a callable(what, done, total), True, 'auto' "
                            "or None")
        self._progress_fn = fn
        if fn is None:
            lib.es_ctx_set_progress(self._ptr, ffi.NULL, ffi.NULL)
            self._progress_cb = None
        else:
            self._progress_cb = ffi.callback("es_progress_fn", self._on_progress)
            lib.es_ctx_set_progress(self._ptr, self._progress_cb, ffi.NULL)

    # The C side cannot take a Python exception: one raised in a callback is
    # kept and raised once the library call returns (call()).
    def _on_progress(self, userdata, what, done, total):
        if self._callback_error is not None:
            return
        try:
            self._progress_fn(ffi.string(what).decode("utf-8", "replace"), int(done),
                              int(total))
        except BaseException as e:   # noqa: B036 (re-raised after the C call)
            self._callback_error = e

    def _on_log(self, userdata, level, msg):
        text = ffi.string(msg).decode("utf-8", "replace")
        try:
            if level == lib.ES_LOG_WARNING:
                warnings.warn(text, EdgespaceWarning, stacklevel=2)
            else:
                _log.info(text)
        except BaseException as e:   # noqa: B036 (warnings raised as errors)
            if self._callback_error is None:
                self._callback_error = e

    def call(self, fn, *args):
        """Call a library function taking this context first; raise its
        error, or an exception a callback raised meanwhile."""
        self._callback_error = None
        status = fn(self._ptr, *args)
        err, self._callback_error = self._callback_error, None
        if isinstance(self._progress_fn, _TqdmProgress):
            self._progress_fn.close()
        if status:
            check(self._ptr, status)
        if err is not None:
            raise err
        return status

    @property
    def ptr(self):
        """The es_ctx * (for calls the binding does not wrap)."""
        return self._ptr


_local = threading.local()


def default_context():
    """This thread's context (made on first use, seed 0x5eed, progress 'auto')."""
    ctx = getattr(_local, "ctx", None)
    if ctx is None:
        ctx = _local.ctx = Context()
    return ctx


def ctx_of(ctx):
    """ctx, or this thread's default context."""
    return ctx if ctx is not None else default_context()
