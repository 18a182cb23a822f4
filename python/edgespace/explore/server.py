"""python/edgespace/explore/server.py — the web server of `edgespace explore`:
one page (web/index.html) and a WebSocket over which the page asks for the
shapes of slider positions and rows, and gets each back as one binary
message (a JSON header, then float64 positions and heat maps).

Why aiohttp (Debian's python3-aiohttp): the explorer's computations are the
Python package's (core.py, shared with the Jupyter widget), so the server
is Python; aiohttp is asyncio-native with WebSockets built in (a slider
position travels as one small message and its mesh back as one binary
frame, with no polling), bounds request and message sizes itself
(client_max_size, max_msg_size), and is kept up by its project and by
Debian. Flask would need a second package for WebSockets and a thread per
client; http.server is documented as not meant for serving.

Embeddings run in one worker thread (the embedding session is
single-threaded), off the event loop, so the server keeps answering while
one runs. Each connection has one pending slot: a newer slider position
replaces an older one that has not started, and the older is answered
"superseded" (a solve that has started runs to its end: the library has no
cancellation, and it takes about a tenth of a second).

Security: loopback only unless --host says otherwise; every request needs
the random token of the printed URL (query, cookie or header), and the Host
header must name this server (DNS rebinding); a WebSocket's Origin must be
this server; request bodies and messages are bounded; the only files served
are the page's own, three.js's (build/ and examples/jsm/ of the npm
package), and the meshes this session saved into the store's folder. A bad
request gets an error message, which the page shows; it never ends the
server.
"""
import asyncio
import base64
import concurrent.futures
import hashlib
import hmac
import json
import math
import os
import re
import secrets
import struct

from aiohttp import WSMsgType, web

from .core import HEAT_MAPS, RequestError

MAX_REQUEST = 64 * 1024        # bytes of an HTTP request body or a WebSocket message
MAX_CLIENTS = 8                # open pages at once
WEB_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "web")
STATIC = {"explore.js": "text/javascript", "view3d.js": "text/javascript",
          "scatter.js": "text/javascript", "util.js": "text/javascript",
          "explore.css": "text/css"}
LOOPBACK = {"127.0.0.1", "localhost", "::1", "[::1]"}


def three_dir():
    """Where three.js is: $EDGESPACE_THREE_DIR, else the npm package that
    tools/setup.sh installs (npm ci) into web/node_modules."""
    d = os.environ.get("EDGESPACE_THREE_DIR")
    return d if d else os.path.join(WEB_DIR, "node_modules", "three")


def hostname(host):
    """The name in a Host header: "127.0.0.1:8080" -> "127.0.0.1",
    "[::1]:8080" -> "[::1]"."""
    if host.startswith("["):
        return host.split("]")[0] + "]"
    return host.rsplit(":", 1)[0]


def _finite(x):
    """JSON-safe: NaN and infinities (which JSON lacks) become None."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    return x


def shape_message(seq, shape, explorer):
    """One binary WebSocket message: u32 header length (little-endian), the
    JSON header padded with blanks so the arrays start 8-byte aligned, then
    float64 positions (V x 3) and one float64 array (V) per heat map, in the
    header's "heat" order."""
    names = [n for n in HEAT_MAPS if n in shape.heat]
    hdr = {"op": "shape", "seq": seq, "expr": shape.expr, "t": shape.t, "row": shape.row,
           "command": explorer.command_line(shape.expr), "report": shape.report,
           "warning": shape.realizability(), "seconds": shape.seconds,
           "cpu_seconds": shape.cpu_seconds,
           "nverts": int(shape.V.shape[0]),
           "heat": [{"name": n, "label": HEAT_MAPS[n], "min": float(shape.heat[n].min()),
                     "max": float(shape.heat[n].max())} for n in names]}
    head = json.dumps(_finite(hdr)).encode()
    head += b" " * ((-(4 + len(head))) % 8)
    parts = [struct.pack("<I", len(head)), head, shape.V.astype("<f8").tobytes()]
    parts += [shape.heat[n].astype("<f8").tobytes() for n in names]
    return b"".join(parts)


class Client:
    """One open page: its socket, its pending request (latest wins) and the
    last shape sent to it (what "save" saves)."""

    def __init__(self, ws):
        self.ws = ws
        self.pending = None
        self.wake = asyncio.Event()
        self.last = None         # (seq, Shape)
        self.closed = False


class ExploreServer:
    """Serves one Explorer. start() binds and returns the URL; stop() closes."""

    def __init__(self, explorer, host="127.0.0.1", port=0, token=None, log=None):
        self.explorer = explorer
        self.host, self.port = host, int(port)
        self.token = token or secrets.token_urlsafe(24)
        self.log = log or (lambda msg: None)
        self.loopback = host in LOOPBACK
        self.clients = set()
        self.pool = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="explore")
        with open(os.path.join(WEB_DIR, "index.html"), encoding="utf-8") as f:
            self.index = f.read()
        self.csp = self._csp(self.index)
        self.runner = None
        self.url = None

    @staticmethod
    def _csp(index):
        """A policy that lets the page run only its own scripts: the inline
        import map (which names three.js for OrbitControls' bare import) by
        its hash, everything else from this server."""
        hashes = ["'sha256-%s'" % base64.b64encode(hashlib.sha256(m.encode()).digest()).decode()
                  for m in re.findall(r'<script type="importmap">(.*?)</script>', index, re.S)]
        return ("default-src 'none'; script-src 'self' " + " ".join(hashes) +
                "; style-src 'self'; img-src 'self' data: blob:; connect-src 'self'; "
                "base-uri 'none'; form-action 'none'; frame-ancestors 'self'")

    # -- the gate every request passes ----------------------------------------
    def _authorized(self, request):
        given = (request.query.get("token") or request.headers.get("X-Edgespace-Token") or
                 request.cookies.get("edgespace_token") or "")
        return hmac.compare_digest(given.encode(), self.token.encode())

    @web.middleware
    async def _gate(self, request, handler):
        if self.loopback and hostname(request.host or "") not in LOOPBACK:
            return web.Response(status=403, text="edgespace explore: wrong Host header "
                                "(this server answers only as 127.0.0.1 or localhost)\n")
        if not self._authorized(request):
            return web.Response(status=403, text="edgespace explore: open the URL with its "
                                "token, as `edgespace explore` printed it\n")
        resp = await handler(request)
        resp.headers["Content-Security-Policy"] = self.csp
        resp.headers["X-Content-Type-Options"] = "nosniff"
        resp.headers["Referrer-Policy"] = "no-referrer"
        resp.headers.setdefault("Cache-Control", "no-store")
        return resp

    # -- routes -----------------------------------------------------------------
    async def _index(self, request):
        resp = web.Response(text=self.index, content_type="text/html")
        resp.set_cookie("edgespace_token", self.token, httponly=True, samesite="Strict")
        return resp

    async def _static(self, request):
        name = request.match_info["name"]
        if name not in STATIC:
            raise web.HTTPNotFound(text=f"no file '{name[:80]}'\n")
        return web.FileResponse(os.path.join(WEB_DIR, name),
                                headers={"Content-Type": STATIC[name]})

    async def _vendor(self, request):
        """three.js: .js files under build/ and examples/jsm/ of the npm
        package, nothing else (resolved paths must stay inside them)."""
        rel = request.match_info["path"]
        base = os.path.realpath(three_dir())
        path = os.path.realpath(os.path.join(base, rel))
        inside = any(path.startswith(os.path.join(base, d) + os.sep)
                     for d in ("build", os.path.join("examples", "jsm")))
        if not inside or not path.endswith(".js") or not os.path.isfile(path):
            if not os.path.isdir(base):
                raise web.HTTPNotFound(text="three.js is not installed: run tools/setup.sh "
                                       "(npm ci in python/edgespace/explore/web)\n")
            raise web.HTTPNotFound(text=f"no file '{rel[:80]}'\n")
        return web.FileResponse(path, headers={"Content-Type": "text/javascript",
                                               "Cache-Control": "max-age=3600"})

    async def _info(self, request):
        info = self.explorer.describe()
        info["three"] = os.path.isfile(os.path.join(three_dir(), "build", "three.module.js"))
        return web.json_response(_finite(info))

    async def _faces(self, request):
        return web.Response(body=self.explorer.faces.astype("<i4").tobytes(),
                            content_type="application/octet-stream")

    async def _file(self, request):
        """A mesh this session saved (and nothing else: no path is taken
        from the request)."""
        name = request.match_info["name"]
        path = self.explorer.saved.get(name)
        if path is None or not os.path.isfile(path):
            raise web.HTTPNotFound(text=f"no saved file '{name[:80]}'\n")
        return web.FileResponse(path, headers={
            "Content-Disposition": f'attachment; filename="{name}"',
            "Content-Type": "application/octet-stream"})

    # -- the WebSocket ---------------------------------------------------------------
    async def _ws(self, request):
        origin = request.headers.get("Origin")
        if origin is not None and origin != f"http://{request.host}":
            return web.Response(status=403, text="edgespace explore: cross-origin socket\n")
        ws = web.WebSocketResponse(max_msg_size=MAX_REQUEST, heartbeat=30)
        await ws.prepare(request)
        if len(self.clients) >= MAX_CLIENTS:
            await ws.send_json({"op": "error", "seq": None, "message":
                                f"{MAX_CLIENTS} pages are open on this explorer already; "
                                "close one and reload"})
            await ws.close()
            return ws
        client = Client(ws)
        self.clients.add(client)
        worker = asyncio.ensure_future(self._shapes(client))
        self.log(f"page connected ({len(self.clients)} open)")
        try:
            async for msg in ws:
                if msg.type == WSMsgType.TEXT:
                    await self._on_message(client, msg.data)
                elif msg.type == WSMsgType.BINARY:
                    await self._error(client, None, "binary messages are not requests")
                elif msg.type == WSMsgType.ERROR:
                    break
        finally:
            client.closed = True
            client.wake.set()
            self.clients.discard(client)
            await worker
            self.log(f"page closed ({len(self.clients)} open)")
        if ws.close_code == 1009:
            self.log("a message over the size limit closed a page's socket")
        return ws

    async def _send(self, client, data):
        if client.closed or client.ws.closed:
            return
        try:
            if isinstance(data, bytes):
                await client.ws.send_bytes(data)
            else:
                await client.ws.send_str(json.dumps(_finite(data)))
        except (ConnectionError, RuntimeError):
            client.closed = True

    async def _error(self, client, seq, message):
        self.log(f"request refused: {message}")
        await self._send(client, {"op": "error", "seq": seq, "message": message})

    async def _on_message(self, client, text):
        try:
            req = json.loads(text, parse_constant=lambda c: c)   # NaN, Infinity stay words
        except ValueError as e:
            return await self._error(client, None, f"a request is not JSON: {e}")
        if not isinstance(req, dict):
            return await self._error(client, None, "a request is a JSON object")
        seq, op = req.get("seq"), req.get("op")
        if not (seq is None or (isinstance(seq, int) and not isinstance(seq, bool))):
            return await self._error(client, None, "seq must be an integer")
        if op in ("embed", "row"):
            if client.pending is not None:
                await self._send(client, {"op": "superseded", "seq": client.pending.get("seq")})
            client.pending = req
            client.wake.set()
        elif op == "save":
            await self._save(client, req)
        else:
            await self._error(client, seq, f"unknown request '{str(op)[:40]}' (embed, row, save)")

    async def _shapes(self, client):
        """The connection's worker: embeds its latest pending request, one at
        a time, in the server's computing thread."""
        loop = asyncio.get_event_loop()
        while True:
            await client.wake.wait()
            client.wake.clear()
            if client.closed:
                return
            req, client.pending = client.pending, None
            if req is None:
                continue
            seq = req.get("seq")
            try:
                if req["op"] == "row":
                    shape = await loop.run_in_executor(self.pool, self.explorer.row_shape,
                                                       req.get("id"))
                else:
                    shape = await loop.run_in_executor(self.pool, self.explorer.embed,
                                                       req.get("coords"))
            except RequestError as e:
                await self._error(client, seq, str(e))
                continue
            except Exception as e:     # noqa: BLE001 (a server never dies on a request)
                await self._error(client, seq, f"{type(e).__name__}: {e}")
                continue
            client.last = (seq, shape)
            await self._send(client, shape_message(seq, shape, self.explorer))

    async def _save(self, client, req):
        seq = req.get("seq")
        if client.last is None or req.get("shape") != client.last[0]:
            return await self._error(client, seq, "the shape on screen changed before it was "
                                     "saved: save again")
        loop = asyncio.get_event_loop()
        try:
            out = await loop.run_in_executor(self.pool, self.explorer.save, req.get("name"),
                                             client.last[1], req.get("format", "ply"))
        except RequestError as e:
            return await self._error(client, seq, str(e))
        except Exception as e:         # noqa: BLE001
            return await self._error(client, seq, f"{type(e).__name__}: {e}")
        self.log(f"saved {out['path']} and /analysis/{out['point']}")
        out.update(op="saved", seq=seq, url=f"files/{out['file']}")
        await self._send(client, out)

    # -- life --------------------------------------------------------------------------
    def app(self):
        app = web.Application(middlewares=[self._gate], client_max_size=MAX_REQUEST)
        app.router.add_get("/", self._index)
        app.router.add_get("/static/{name}", self._static)
        app.router.add_get("/vendor/three/{path:.+}", self._vendor)
        app.router.add_get("/api/info", self._info)
        app.router.add_get("/api/faces", self._faces)
        app.router.add_get("/files/{name}", self._file)
        app.router.add_get("/ws", self._ws)
        return app

    async def start(self):
        self.runner = web.AppRunner(self.app(), access_log=None, handle_signals=False)
        await self.runner.setup()
        site = web.TCPSite(self.runner, self.host, self.port, shutdown_timeout=1.0)
        await site.start()
        port = site._server.sockets[0].getsockname()[1]
        host = f"[{self.host}]" if ":" in self.host else self.host
        self.url = f"http://{host}:{port}/?token={self.token}"
        return self.url

    async def stop(self):
        for c in list(self.clients):
            c.closed = True
            c.wake.set()
            await c.ws.close()
        if self.runner is not None:
            await self.runner.cleanup()
        self.pool.shutdown(wait=True)
