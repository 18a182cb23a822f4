"""python3 -m edgespace.explore STORE [--port N] [--pca NAME] [--components K]
[--host ADDR] [--cold] [--accurate] [--no-cache]: the program `edgespace explore`
(tools/cmd/explore.c) runs. Prints the URL (with its token) on a line of
its own on standard output once the server listens; progress and requests
refused go to standard error, one line each. Exit status 0 after Ctrl-C or
SIGTERM, 1 when the store cannot be explored or the port not bound, 2 on a
usage error."""
import argparse
import asyncio
import signal
import sys

PROG = "edgespace explore"


def _log(msg):
    print(f"{PROG}: {msg}", file=sys.stderr, flush=True)


def run(store, pca=None, host="127.0.0.1", port=0, warm=True, fast=True, cache=True, pcs=20,
        ready=None, log=_log):
    from .core import Explorer
    from .server import ExploreServer
    log = log or (lambda msg: None)
    explorer = Explorer(store, pca=pca, warm=warm, fast=fast, cache=cache, pcs=pcs, log=log)
    server = ExploreServer(explorer, host=host, port=port, log=log)
    loop = asyncio.new_event_loop()
    stop = asyncio.Event()
    try:
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.add_signal_handler(sig, stop.set)
    except (RuntimeError, ValueError):
        pass          # not the main thread: the caller stops us by other means

    async def main():
        url = await server.start()
        if ready is not None:
            ready(url)
        await stop.wait()
        await server.stop()
    try:
        loop.run_until_complete(main())
    finally:
        loop.close()
        explorer.close()
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(prog=PROG, description="Explore a store's shape space in a "
                                 "browser: edgespace explore --help says more.")
    ap.add_argument("store")
    ap.add_argument("--port", type=int, default=0)
    ap.add_argument("--pca", default=None)
    ap.add_argument("--components", "-k", type=int, default=None)
    ap.add_argument("--pcs", type=int, default=None, help=argparse.SUPPRESS)   # the old spelling
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--cold", action="store_true")
    ap.add_argument("--accurate", action="store_true")
    ap.add_argument("--no-cache", action="store_true")
    a = ap.parse_args(argv)
    if not 0 <= a.port <= 65535:
        ap.error("--port wants 0 (any free port) to 65535")
    if a.pcs is not None:
        # README "Options": one name per concept, as edgespace explore
        if a.components is not None:
            ap.error("give --components (the new spelling of --pcs), not both")
        _log("--pcs K is now --components K; the old spelling will go")
        a.components = a.pcs
    if a.components is None:
        a.components = 20
    if a.components < 0:
        ap.error("--components wants 0 (all) or more")

    def ready(url):
        from .server import LOOPBACK
        if a.host not in LOOPBACK:
            _log(f"warning: listening on {a.host}, not only on this machine: anyone who can "
                 "reach it and has the URL can read the store")
        print(f"{PROG}: open this page (Ctrl-C stops the server):\n{url}", flush=True)

    try:
        return run(a.store, pca=a.pca, host=a.host, port=a.port, warm=not a.cold,
                   fast=not a.accurate, cache=not a.no_cache, pcs=a.components, ready=ready)
    except KeyboardInterrupt:       # Ctrl-C before the server listened
        return 130
    except OSError as e:
        _log(f"{e.strerror or e}" + (f" ({e.filename})" if getattr(e, "filename", None) else ""))
        return 1
    except Exception as e:      # noqa: BLE001 (the message, not a traceback)
        _log(str(e))
        return 1


if __name__ == "__main__":
    sys.exit(main())
