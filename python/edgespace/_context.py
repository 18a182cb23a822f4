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

An exception raised in a callback (a progress function, a warning turned
into an error, Ctrl-C arriving while the library works) cancels the work
(es_ctx_cancel): the call returns at the library's next progress report
having stored nothing, and the exception is raised from it. The progress
callback is installed even without a progress function, so that Ctrl-C
reaches long work. One context is used by one thread at a time (the
library's rule): its calls hold a lock, so that threads sharing an object
(a store, an embedder) take turns instead of corrupting it, and a call made
from inside a callback of a running call on the same context is refused.
"""
import contextlib
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
        self._lock = threading.RLock()
        self._depth = 0
        self._progress_fn = None
        self._callback_error = None
        # onerror: an exception escaping a callback (Ctrl-C is raised at the
        # callback's first instruction) is kept and cancels the work
        self._progress_cb = ffi.callback("es_progress_fn", self._on_progress,
                                         onerror=self._on_callback_error)
        lib.es_ctx_set_progress(self._ptr, self._progress_cb, ffi.NULL)
        self._log_cb = ffi.callback("es_log_fn", self._on_log, onerror=self._on_callback_error)
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

    # The C side cannot take a Python exception: one raised in a callback is
    # kept, cancels the work, and is raised once the library call returns
    # (call()).
    def _on_progress(self, userdata, what, done, total):
        fn = self._progress_fn
        if fn is not None and self._callback_error is None:
            fn(ffi.string(what).decode("utf-8", "replace"), int(done), int(total))

    def _on_log(self, userdata, level, msg):
        text = ffi.string(msg).decode("utf-8", "replace")
        if level == lib.ES_LOG_WARNING:
            warnings.warn(text, EdgespaceWarning, stacklevel=2)
        else:
            _log.info(text)

    def _on_callback_error(self, exc_type, exc, tb):
        if self._callback_error is None:
            self._callback_error = exc if exc is not None else exc_type()
        lib.es_ctx_cancel(self._ptr)

    def call(self, fn, *args):
        """Call a library function taking this context first; raise its
        error, or an exception a callback raised meanwhile (which cancelled
        the work: the library stored nothing)."""
        with self._lock:
            if self._depth:
                raise RuntimeError("edgespace: a library call from a callback of a call "
                                   "running on the same context (use another Context)")
            self._depth += 1
            self._callback_error = None
            lib.es_ctx_cancel_clear(self._ptr)
            try:
                status = fn(self._ptr, *args)
            finally:
                self._depth -= 1
                lib.es_ctx_cancel_clear(self._ptr)
                err, self._callback_error = self._callback_error, None
                if isinstance(self._progress_fn, _TqdmProgress):
                    self._progress_fn.close()
            if err is not None:
                raise err
            if status:
                check(self._ptr, status)
            return status

    def hold(self):
        """The lock this context's calls take: held around a block of calls
        or reads of one object, so that another thread's close of it waits."""
        return self._lock

    @contextlib.contextmanager
    def closing(self):
        """Hold the lock to close or free an object: waits for another
        thread's running call; refused from a callback of a call running on
        this context (the object is in use below it)."""
        with self._lock:
            if self._depth:
                raise RuntimeError("edgespace: an object cannot be closed from a callback "
                                   "of a call running on it")
            yield

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
