"""edgespace explore: the explorer's computations (edgespace/explore/core.py),
its server as `edgespace explore` starts it (security, bad requests,
concurrent clients), and the page driven in headless Chromium.

Oracles: `edgespace embed` (the command) of the point the page shows, with
the explorer's options, to 1e-9 of the bounding-box diagonal; the library's
own evaluation of the point expression (es_study_point_weights); numpy
edge lengths; h5py for what a save stores; Chromium (python3-selenium and
chromium-driver) as the client of the page, without a display."""
import asyncio
import base64
import hashlib
import http.client
import json
import os
import re
import shutil
import signal
import subprocess
import time

import h5py
import numpy as np
import pytest

import edgespace as es

pytest.importorskip("aiohttp")
from edgespace.explore import Explorer, RequestError   # noqa: E402 (needs aiohttp)

from browser import chromium, screenshot_dir, wait_for   # noqa: E402
from conftest import cli_path, copy_store   # noqa: E402

URL_RE = re.compile(r"^(http://127\.0\.0\.1:(\d+)/\?token=([A-Za-z0-9_-]+))$", re.M)


@pytest.fixture(scope="module")
def study(base_store, tmp_path_factory):
    """The synthetic faces with a PCA, a paired difference and a model."""
    path = tmp_path_factory.mktemp("explore") / "faces.h5"
    shutil.copyfile(base_store, path)
    with es.Store(path, write=True, ctx=es.Context(progress=None)) as s:
        s.pca("p", components=4)
        s.diff("smile", pair_by="subject", column="expression", from_="neutral", to="happy")
        s.model("~ expression", name="m", permutations=0)
    return path


@pytest.fixture(scope="module")
def cold(study):
    """An explorer as `edgespace explore --cold` makes it."""
    ex = Explorer(study, pca="p", warm=False)
    yield ex
    ex.close()


def cli_embed(store, expr, out, fast=True):
    """`edgespace embed` of a point, not stored: its positions (V, 3)."""
    args = [cli_path(), "embed", str(store), "--pca", "p", "--point", expr, "-o", str(out),
            "--no-store"] + (["--fast"] if fast else [])
    r = subprocess.run(args, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with es.Store(store) as s:
        return s.mesh.read_positions(out)


def bbox(V):
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


# -- the computations --------------------------------------------------------------
def test_the_sliders_are_the_stores_directions(cold):
    keys = [d.key for d in cold.directions]
    assert keys == ["pc1", "pc2", "pc3", "pc4", "diff:smile", "coef:m:expression=happy",
                    "coef:m:expression=neutral"]
    d = cold.by_key["coef:m:expression=happy"]
    assert 1.0 < d.hi < 1.5 and d.lo == -d.hi      # 3 sd of a 0/1 column with 6 of 18 ones
    assert cold.default_color_column() == "expression"
    info = cold.describe()
    assert len(info["rows"]["ids"]) == 18 and len(info["rows"]["scores"][0]) == 4
    # scores in sd: each column's sample variance is 1
    z = np.array(info["rows"]["scores"])
    assert np.allclose(z.var(axis=0, ddof=1), 1.0, rtol=1e-9)


def test_a_store_without_a_pca_says_what_to_run(base_store):
    with pytest.raises(RequestError, match="has no PCA: run `edgespace pca"):
        Explorer(base_store)


def test_the_first_pcs_only_when_asked(study):
    ex = Explorer(study, pca="p", pcs=2)
    try:
        assert [d.key for d in ex.directions][:3] == ["pc1", "pc2", "diff:smile"]
        assert len(ex.describe()["rows"]["scores"][0]) == 4     # the scatter has them all
    finally:
        ex.close()


def test_a_position_is_the_point_its_expression_names(cold, study):
    c = cold.coordinates({"pc1": 1.5, "pc3": -0.25, "diff:smile": 0.5,
                          "coef:m:expression=happy": 0.7, "pc2": 0})
    expr = cold.point_expression(c)
    assert expr == ("mean + 1.5*pc:1 - 0.25*pc:3 + 0.5*diff:smile "
                    "+ 0.7*coef:m:expression=happy")
    L, w = cold._lengths(c)
    with es.Store(study) as s:       # the library's evaluation of the text
        pt = s.point_weights(expr, pca="p")
    assert np.max(np.abs(L - pt.lengths)) <= 1e-13 * np.max(pt.lengths)
    assert np.max(np.abs(w - pt.weights)) <= 1e-13 * np.max(np.abs(pt.weights))
    assert pt.scale == cold.scale0


def test_a_cold_position_is_edgespace_embed_of_its_expression(cold, study, tmp_path):
    shape = cold.embed({"pc1": 1.25, "diff:smile": -0.5})
    V = cli_embed(study, shape.expr, tmp_path / "cli.ply")
    assert np.max(np.abs(shape.V - V)) <= 1e-9 * bbox(V)
    assert shape.report["rms_ratio"] < 2e-3 and shape.realizability() is None
    assert np.all(shape.heat["displacement"] >= 0) and shape.heat["displacement"].max() > 0


def test_warm_positions_realize_their_lengths_near_the_cold_ones(study):
    ex = Explorer(study, pca="p")
    try:
        E = ex.store.edges
        for t in np.linspace(-2, 2, 9):
            shape = ex.embed({"pc1": float(t)})
            L, _ = ex._lengths(shape.t)
            got = np.linalg.norm(shape.V[E[:, 0]] - shape.V[E[:, 1]], axis=1)
            want = L * ex.scale0
            rms = np.sqrt(np.mean((got - want) ** 2)) / want.mean()
            # the report tells the truth; the slider accuracy (es_embed_opts_fast: 30
            # local-global iterations) leaves up to 0.3 % here at +-2 sd
            assert np.isclose(rms, shape.report["rms_ratio"], rtol=1e-6) and rms < 5e-3
        assert "last output" in shape.report["init"]
    finally:
        ex.close()
    with es.Store(study) as s:
        cold_V = s.embedder().embed(shape.expr, pca="p", warm=False, fast=True).V
    assert np.sqrt(np.mean(np.sum((shape.V - cold_V) ** 2, axis=1))) < 0.01 * bbox(cold_V)


def kabsch(P, Q):
    """P moved rigidly onto Q (least squares, no reflection; numpy's SVD)."""
    p0, q0 = P.mean(axis=0), Q.mean(axis=0)
    U, _, Wt = np.linalg.svd((P - p0).T @ (Q - q0))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Wt))])
    return (P - p0) @ (U @ D @ Wt) + q0


def test_the_heat_maps_are_what_their_names_say(cold, study, tmp_path):
    """displacement: each vertex's distance from the mean shape, here from
    `edgespace embed`'s mesh of the mean; deviation: from the prior of the
    position's row weights, scaled to the output's size and aligned rigidly,
    in % of its bounding-box diagonal (numpy's Kabsch)."""
    shape = cold.embed({"pc2": 1.5, "diff:smile": 0.5})
    mean = cli_embed(study, cold.mean_expr, tmp_path / "mean.ply")
    want = np.linalg.norm(shape.V - mean, axis=1)
    assert np.max(np.abs(shape.heat["displacement"] - want)) <= 1e-9 * bbox(mean)
    _, w = cold._lengths(shape.t)
    P = cold.session.prior_positions(w)
    E = cold.store.edges
    size = lambda X: np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1).sum()   # noqa: E731
    P *= size(shape.V) / size(P)
    dev = 100 * np.linalg.norm(kabsch(shape.V, P) - P, axis=1) / bbox(P)
    assert np.max(np.abs(shape.heat["deviation"] - dev)) <= 1e-7 * dev.max()
    assert np.isclose(np.sqrt(np.mean(dev ** 2)), 100 * shape.report["prior_rms"], rtol=1e-9)


def test_a_point_that_breaks_the_triangle_inequality_is_flagged(cold):
    shape = cold.embed({"pc1": 3})      # on these faces: 5 faces broken
    r = shape.report
    assert r["n_bad_faces"] > 0 and r["n_projected"] > 0
    assert shape.realizability().startswith(f"not realizable: {r['n_bad_faces']} faces break")


def test_a_row_is_its_own_mesh_with_its_scores(cold, study):
    shape = cold.row_shape("face_s03_angry")
    assert shape.expr == "row:face_s03_angry" and shape.report is None
    with es.Store(study) as s:
        i = s.find_row("face_s03_angry")
        E = s.edges
        want = s.lengths(i)[0] * s.scales()[i]
        pca = s.load_pca("p")
    got = np.linalg.norm(shape.V[E[:, 0]] - shape.V[E[:, 1]], axis=1)
    assert np.allclose(got, want, rtol=1e-9)          # the row, moved rigidly
    j = list(pca.rows).index(i)
    assert np.isclose(shape.t["pc2"], pca.scores[j, 1] / np.sqrt(pca.eigenvalues[1]))


@pytest.mark.parametrize("coords, message", [
    ({"pc9": 1}, "no slider 'pc9'"),
    ({"diff:smiel": 1}, "did you mean diff:smile"),
    ({"pc1": "abc"}, "'abc' is not a number"),
    ({"pc1": "NaN"}, "'NaN' is not a number"),
    ({"pc1": True}, "is not a number"),
    ({"pc1": float("nan")}, "outside what can be explored"),
    ({"pc1": 1e300}, "outside what can be explored (|t| <= 30 sd)"),
    ({"pc1": -31}, "outside"),
    ({"diff:smile": 15}, "this position has"),          # lengths <= 0
    ([1, 2], "coordinates must be an object"),
])
def test_bad_positions_are_refused_with_a_message(cold, coords, message):
    with pytest.raises(RequestError) as e:
        cold.embed(coords)
    assert message in str(e.value)
    assert cold.embed({"pc1": 0.5}).expr == "mean + 0.5*pc:1"   # and it goes on


def stored_digest(store):
    """SHA-256 over a store's file and every result file beside it."""
    h = hashlib.sha256(store.read_bytes())
    for root, dirs, files in sorted(os.walk(f"{store}.results")):
        dirs.sort()
        for name in sorted(files):
            h.update(name.encode())
            with open(os.path.join(root, name), "rb") as f:
                h.update(f.read())
    return h.hexdigest()


def test_saving_writes_a_mesh_and_a_point_and_nothing_else(study, tmp_path):
    store = tmp_path / "faces.h5"
    copy_store(study, store)
    digest = hashlib.sha256(store.read_bytes()).hexdigest()
    ex = Explorer(store, pca="p", warm=False)
    try:
        shape = ex.embed({"pc2": -1.0, "diff:smile": 0.75})
        # exploring never writes the store (opened read-only)
        assert hashlib.sha256(store.read_bytes()).hexdigest() == digest
        for bad in ("../x", "", ".hidden", "a/b", "x" * 65, None):
            with pytest.raises(RequestError, match="a name is"):
                ex.save(bad, shape)
        with pytest.raises(RequestError, match="format"):
            ex.save("ok", shape, format="stl")
        out = ex.save("smile_ish", shape, format="ply")
        assert out["path"] == str(tmp_path / "smile_ish.ply")
        with es.Store(store) as s:
            assert np.array_equal(s.mesh.read_positions(out["path"]), shape.V)
            pt = s.point_weights(shape.expr, pca="p")
        with h5py.File(f"{store}.results/point/smile_ish.h5", "r") as f:   # beside it
            g = f["analysis/point/smile_ish"]
            assert np.array_equal(g["lengths"][()], pt.lengths)
            assert g.attrs["expression"] in (shape.expr, shape.expr.encode())
        # a second save of that name: refused, nothing written (the store
        # and its result files)
        digest = stored_digest(store)
        with pytest.raises(RequestError, match="exists"):
            ex.save("smile_ish", shape, format="ply")
        with pytest.raises(RequestError, match="point/smile_ish"):
            ex.save("smile_ish", shape, format="obj")       # the file is new, the point is not
        assert not (tmp_path / "smile_ish.obj").exists()
        assert stored_digest(store) == digest
        png = ex.save_png("view", b"\x89PNG\r\n\x1a\n")
        assert os.path.exists(png) and ex.saved["view.png"] == png
    finally:
        ex.close()


# -- the server, as the command starts it ------------------------------------------------
class Server:
    """`edgespace explore STORE ARGS...` in a subprocess, until stop()."""

    def __init__(self, store, *args):
        self.proc = subprocess.Popen([cli_path(), "explore", str(store), *args],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        out = ""
        deadline = time.time() + 60
        while time.time() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            out += line
            m = URL_RE.search(out)
            if m:
                self.url, self.port, self.token = m.group(1), int(m.group(2)), m.group(3)
                return
        self.proc.kill()
        raise AssertionError(f"edgespace explore printed no URL:\n{out}\n{self.proc.stderr.read()}")

    def get(self, path, headers=None, token=True):
        c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        h = dict(headers or {})
        if token:
            h["X-Edgespace-Token"] = self.token
        c.request("GET", path, headers=h)
        r = c.getresponse()
        body = r.read()
        c.close()
        return r.status, body

    def stop(self):
        self.proc.send_signal(signal.SIGTERM)
        try:
            rc = self.proc.wait(30)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()
        err = self.proc.stderr.read()
        self.proc.stdout.close()
        self.proc.stderr.close()
        return rc, err


@pytest.fixture(scope="module")
def server(study):
    s = Server(study, "--pca", "p", "--cold")
    yield s
    rc, err = s.stop()
    assert rc == 0, err


def test_the_command_checks_its_options(study):
    r = subprocess.run([cli_path(), "explore", "--help"], capture_output=True, text=True)
    assert r.returncode == 0 and "127.0.0.1" in r.stdout and "--port" in r.stdout
    for args in ([], ["a.h5", "b.h5"], [str(study), "--port", "70000"],
                 [str(study), "--port", "x"], [str(study), "--components", "-1"]):
        r = subprocess.run([cli_path(), "explore", *args], capture_output=True, text=True)
        assert r.returncode == 2, args
    r = subprocess.run([cli_path(), "explore", str(study) + ".missing"], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 1 and "cannot open" in r.stderr


def test_every_request_needs_the_token_and_this_host(server):
    assert server.get("/?token=" + server.token, token=False)[0] == 200
    assert server.get("/", token=False)[0] == 403
    assert server.get("/?token=wrong", token=False)[0] == 403
    assert server.get("/api/info", headers={"X-Edgespace-Token": "x" * 32}, token=False)[0] == 403
    # DNS rebinding: a page of another site that resolves to 127.0.0.1
    status, body = server.get("/api/info", headers={"Host": f"evil.example:{server.port}"})
    assert status == 403 and b"Host" in body
    status, body = server.get("/api/info")
    info = json.loads(body)
    assert status == 200 and info["pca"] == "p" and info["nverts"] == 780 and not info["warm"]


def test_no_file_but_the_pages_and_three_js_is_served(server, study):
    assert server.get("/static/explore.js")[0] == 200
    assert server.get("/vendor/three/build/three.module.js")[0] in (200, 404)   # 404: no npm
    for path in ("/static/core.py", "/static/..%2fcore.py", "/vendor/three/package.json",
                 "/vendor/three/../../core.py", "/vendor/three/build/%2e%2e/package.json",
                 "/vendor/three/%2e%2e/%2e%2e/%2e%2e/__init__.py", "/files/faces.h5",
                 "/files/..%2ffaces.h5", "/etc/passwd", "/api/../../etc/passwd"):
        status, _ = server.get(path)
        assert status in (403, 404), path


async def _socket(server, session, **kw):
    return await session.ws_connect(f"ws://127.0.0.1:{server.port}/ws?token={server.token}",
                                    **kw)


def _decode(msg):
    """A server message as a dict; a shape's positions as "V" (V, 3)."""
    if msg.type.name != "BINARY":
        return json.loads(msg.data)
    n = int.from_bytes(msg.data[:4], "little")
    hdr = json.loads(msg.data[4:4 + n])
    hdr["V"] = np.frombuffer(msg.data, "<f8", 3 * hdr["nverts"], 4 + n).reshape(-1, 3)
    return hdr


async def _answer(ws, seq, timeout=60):
    """The message answering request seq (a shape header, error or saved)."""
    while True:
        msg = await asyncio.wait_for(ws.receive(), timeout)
        if msg.type.name not in ("BINARY", "TEXT"):
            return {"op": msg.type.name.lower(), "code": ws.close_code}
        hdr = _decode(msg)
        if hdr.get("seq") == seq or (hdr["op"] == "error" and hdr.get("seq") is None):
            return hdr


def test_bad_requests_are_answered_with_errors_and_the_server_goes_on(server):
    import aiohttp

    async def run():
        async with aiohttp.ClientSession() as session:
            ws = await _socket(server, session)
            cases = [("{not json", None, "not JSON"), ("[1]", None, "a JSON object"),
                     ('{"op": "fly", "seq": 1}', 1, "unknown request 'fly'"),
                     ('{"op": "embed", "seq": 2, "coords": {"pc7": 1}}', 2, "no slider 'pc7'"),
                     ('{"op": "embed", "seq": 3, "coords": {"pc1": "1.5x"}}', 3, "not a number"),
                     ('{"op": "embed", "seq": 4, "coords": {"pc1": NaN}}', 4, "not a number"),
                     ('{"op": "embed", "seq": 5, "coords": {"pc1": 1e308}}', 5, "outside"),
                     ('{"op": "row", "seq": 6, "id": "face_s99_happy"}', 6, "no row"),
                     ('{"op": "save", "seq": 7, "shape": 99, "name": "x"}', 7, "save again"),
                     ('{"op": "embed", "seq": "8"}', None, "seq must be an integer")]
            for text, seq, message in cases:
                await ws.send_str(text)
                a = await _answer(ws, seq)
                assert a["op"] == "error" and message in a["message"], (text, a)
            await ws.send_str('{"op": "embed", "seq": 9, "coords": {"pc1": 0.5}}')
            a = await _answer(ws, 9)
            assert a["op"] == "shape" and a["expr"] == "mean + 0.5*pc:1"
            # a message over the size bound closes that socket (1009), nothing else
            await ws.send_str(json.dumps({"op": "embed", "seq": 10, "pad": "x" * 70000}))
            a = await _answer(ws, 10)
            assert a["op"] in ("close", "closed", "closing") and a["code"] == 1009
            ws2 = await _socket(server, session)
            await ws2.send_str('{"op": "embed", "seq": 1, "coords": {"pc2": -1}}')
            assert (await _answer(ws2, 1))["op"] == "shape"
            await ws2.close()
            # a socket opened from another site's page
            with pytest.raises(aiohttp.WSServerHandshakeError):
                await _socket(server, session, headers={"Origin": "http://evil.example"})
    asyncio.run(run())


def test_concurrent_clients_each_get_their_newest_position(server, cold):
    """Three pages send six positions each in a burst, faster than the one
    computing thread embeds them: every request is answered once, older
    waiting ones "superseded", and each page's last answer is its newest
    position, embedded as if alone (the server runs --cold: no page's
    position leaks into another's)."""
    import aiohttp

    async def client(session, k):
        ws = await _socket(server, session)
        for i in range(6):
            last = {"pc1": round(0.3 * k + 0.05 * i + 0.05, 4), "pc2": -0.2 * k}
            await ws.send_str(json.dumps({"op": "embed", "seq": i + 1, "coords": last}))
        answers = []
        while not answers or answers[-1].get("seq") != 6:
            answers.append(_decode(await asyncio.wait_for(ws.receive(), 60)))
        await ws.close()
        return last, answers

    async def run():
        async with aiohttp.ClientSession() as session:
            results = await asyncio.gather(*(client(session, k) for k in range(3)))
            # more pages than the server keeps open: told so, not crashed
            socks = [await _socket(server, session) for _ in range(8)]
            extra = await _socket(server, session)
            msg = json.loads((await asyncio.wait_for(extra.receive(), 30)).data)
            assert msg["op"] == "error" and "pages are open" in msg["message"]
            for s in socks:
                await s.close()
            await extra.close()
            return results
    for last, answers in asyncio.run(run()):
        assert sorted(a["seq"] for a in answers) == list(range(1, 7)), answers
        assert sum(a["op"] == "superseded" for a in answers) >= 1
        final = answers[-1]
        assert final["op"] == "shape" and final["t"] == {k: v for k, v in last.items() if v}
        V = cold.embed(last).V
        assert np.max(np.abs(final["V"] - V)) <= 1e-9 * bbox(V)


# -- the page, in Chromium -----------------------------------------------------------------
SETTLED = """const x = window.esExplorer; if (!x || !x.last) return false;
const t = x.timings; const seq = x.state.seq;
return x.last.seq === seq || (t.length && t[t.length - 1].error) ? x.last.seq : false;"""


def test_the_page_in_chromium(study, tmp_path):
    if not os.path.isfile(os.path.join(os.path.dirname(es.__file__), "explore", "web",
                                       "node_modules", "three", "build", "three.module.js")):
        pytest.skip("three.js is not installed (tools/setup.sh: npm ci)")
    store = tmp_path / "faces.h5"
    copy_store(study, store)
    srv = Server(store, "--pca", "p", "--cold")
    d = None
    try:
        d = chromium()
        d.get(srv.url)
        wait_for(d, SETTLED, what="the mean's mesh")
        assert d.execute_script("return window.esExplorer.errors") == []
        # nothing the page loads is refused (the content security policy, missing files)
        severe = [e for e in d.get_log("browser") if e["level"] == "SEVERE"]
        assert severe == [], severe
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.by import By
        from selenium.webdriver.common.keys import Keys
        # drag PC 1's slider as a user does: press on it, move right, let go
        rng = d.find_element(By.ID, "s-pc1")
        ActionChains(d).click_and_hold(rng).move_by_offset(25, 0).pause(0.2) \
            .move_by_offset(20, 0).release().perform()
        seq = wait_for(d, SETTLED, what="the dragged position's mesh")
        assert seq > 1
        expr = d.execute_script("return window.esExplorer.last.expr")
        assert re.fullmatch(r"mean \+ [0-9.]+\*pc:1", expr), expr
        assert d.find_element(By.ID, "expr").get_attribute("value") == expr
        assert expr in d.find_element(By.ID, "cmd").text
        got = np.array(d.execute_script("return Array.from(window.esExplorer.last.positions)"))
        V = cli_embed(store, expr, tmp_path / "cli.ply").reshape(-1)
        assert got.shape == V.shape and np.max(np.abs(got - V)) <= 1e-9 * bbox(V.reshape(-1, 3))
        # the heat map and its colour bar; the mesh is drawn (not a blank canvas)
        d.execute_script("const h = document.getElementById('heat'); h.value = 'displacement';"
                         "h.dispatchEvent(new Event('change'));")
        assert d.find_element(By.ID, "colorbar").is_displayed()
        drawn = d.execute_script("""const c = document.querySelector('#canvas-box canvas');
            const g = document.createElement('canvas'); g.width = c.width; g.height = c.height;
            const x = g.getContext('2d'); x.drawImage(c, 0, 0);
            const p = x.getImageData(0, 0, c.width, c.height).data; let n = 0;
            for (let i = 0; i < p.length; i += 4) if (p[i] < 200 || p[i + 2] < 200) n++;
            return n / (p.length / 4);""")
        assert drawn > 0.05, drawn
        shots = screenshot_dir(tmp_path)
        d.save_screenshot(os.path.join(shots, "explore_page.png"))
        png = d.execute_script("return window.esExplorer.png()")
        raw = base64.b64decode(png.split(",", 1)[1])
        assert png.startswith("data:image/png;base64,") and raw[:8] == b"\x89PNG\r\n\x1a\n"
        with open(os.path.join(shots, "explore_view.png"), "wb") as f:
            f.write(raw)
        # a point that is not realizable: the warning
        d.execute_script("window.esExplorer.setSlider('pc1', 3)")
        wait_for(d, SETTLED, what="pc1 = 3")
        warning = d.find_element(By.ID, "warning")
        assert warning.is_displayed() and "triangle inequality" in warning.text
        d.save_screenshot(os.path.join(shots, "explore_warning.png"))
        # bad input typed or sent: an error in the page, and the page goes on
        box = d.find_element(By.ID, "t-pc2")
        for typed, message in (("abc", "'abc' is not a number"), ("1e300", "outside")):
            box.send_keys(Keys.CONTROL, "a")       # the typed text replaces what is there
            box.send_keys(typed, Keys.ENTER)
            wait_for(d, f"return document.getElementById('error').textContent.includes("
                        f"{json.dumps(message)}) && !document.getElementById('error').hidden",
                     what=message)
        d.execute_script("window.esExplorer.send({op: 'embed', coords: {pc42: 1}})")
        wait_for(d, "return document.getElementById('error').textContent.includes("
                    "\"no slider 'pc42'\")", what="unknown PC")
        d.save_screenshot(os.path.join(shots, "explore_error.png"))
        # a click on a row of the scatter: its mesh, its scores on the sliders
        d.find_element(By.CSS_SELECTOR, "#scatter circle[data-row='face_s02_angry']").click()
        wait_for(d, "return window.esExplorer.last && window.esExplorer.last.row === "
                    "'face_s02_angry'", what="the row's mesh")
        assert d.find_element(By.ID, "expr").get_attribute("value") == "row:face_s02_angry"
        assert d.find_element(By.ID, "error").get_attribute("hidden")
        # save this shape: the mesh beside the store, the point in it
        d.find_element(By.ID, "save-name").send_keys("angry2")
        d.find_element(By.ID, "save").click()
        wait_for(d, "return window.esExplorer.state.saved.length === 1", what="the save")
        got = np.array(d.execute_script("return Array.from(window.esExplorer.last.positions)"))
        with es.Store(store) as s:
            assert np.array_equal(s.mesh.read_positions(tmp_path / "angry2.ply").reshape(-1),
                                  got)
            assert "angry2" in s.results("point")
        href = d.find_element(By.CSS_SELECTOR, "#saved a").get_attribute("href")
        status, body = srv.get("/" + href.split("/", 3)[3])
        assert status == 200 and body.startswith(b"ply")
        d.find_element(By.ID, "save").click()       # the same name again: refused
        wait_for(d, "return document.getElementById('error').textContent.includes('exists')",
                 what="the refusal")
    finally:
        if d is not None:
            d.quit()
        rc, err = srv.stop()
    assert rc == 0, err


# a drag at 60 Hz: the slider set every dt ms from lo to hi in n steps, as input events
DRAG = """const [key, lo, hi, n, dt] = arguments; const x = window.esExplorer;
let i = 0; const first = x.state.seq + 1;
const timer = setInterval(() => {
  x.setSlider(key, +(lo + (hi - lo) * i / (n - 1)).toFixed(4));
  if (++i === n) clearInterval(timer);
}, dt);
return first;"""


def percentiles(xs):
    """(median, p95) of a list of numbers, p95 the nearest rank."""
    xs = sorted(xs)
    return float(np.median(xs)), xs[min(len(xs) - 1, int(round(0.95 * (len(xs) - 1))))]


def test_a_warm_drag_in_chromium(study, tmp_path):
    """The explorer as a user starts it (warm starts, slider accuracy):
    hovering a row names it; the copy buttons copy the point and its
    command; a drag across PC 1 at 60 Hz ends on the newest
    position; the mesh received realizes the library's lengths of the
    expression shown (numpy edge lengths: the report's RMS, < 0.5 %), and
    equals the same positions solved in the same order by an Explorer of
    its own (to 1e-9 x bbox: the server's warm chain is the page's shown
    positions, no more, no fewer); then single steps, whose slider-to-mesh
    times are printed (pytest -s)."""
    if not os.path.isfile(os.path.join(os.path.dirname(es.__file__), "explore", "web",
                                       "node_modules", "three", "build", "three.module.js")):
        pytest.skip("three.js is not installed (tools/setup.sh: npm ci)")
    srv = Server(study, "--pca", "p")
    d = None
    try:
        d = chromium()
        d.get(srv.url)
        wait_for(d, SETTLED, what="the mean's mesh")
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.by import By
        dot = d.find_element(By.CSS_SELECTOR, "#scatter circle[data-row='face_s05_happy']")
        ActionChains(d).move_to_element(dot).perform()
        wait_for(d, "return document.getElementById('hover').textContent === "
                    "'face_s05_happy (expression happy)'", 10, "the hovered row's name")
        first = d.execute_script(DRAG, "pc1", -1.5, 1.5, 31, 16)
        wait_for(d, f"return window.esExplorer.state.seq >= {first + 30}", 30, "the drag")
        last = wait_for(d, SETTLED, what="the drag's last mesh")
        assert last == first + 30
        wait_for(d, f"return window.esExplorer.state.timings[{last}].tDrawn", 10, "the frame")
        shape = d.execute_script("const s = window.esExplorer.last; return {expr: s.expr, "
                                 "init: s.report.init, rms: s.report.rms_ratio, "
                                 "V: Array.from(s.positions), "
                                 "heat: Array.from(s.heat.displacement.data)};")
        assert shape["expr"] == "mean + 1.5*pc:1" and "last output" in shape["init"]
        # the copy buttons put the point and its command on the clipboard
        d.execute_cdp_cmd("Browser.grantPermissions", {
            "origin": srv.url.split("/?")[0],
            "permissions": ["clipboardReadWrite", "clipboardSanitizedWrite"]})
        clip = "navigator.clipboard.readText().then(arguments[0], e => arguments[0]('! ' + e))"
        for button, want in (("copy-expr", shape["expr"]),
                             ("copy-cmd", d.find_element(By.ID, "cmd").text)):
            d.find_element(By.ID, button).click()
            deadline = time.time() + 10
            while (got := d.execute_async_script(clip)) != want and time.time() < deadline:
                time.sleep(0.05)
            assert got == want, (button, got)
        timings = d.execute_script("return window.esExplorer.timings")
        for i in range(12):                      # single moves, each once the last is drawn
            d.execute_script("window.esExplorer.setSlider('pc1', arguments[0])", 1.25 - 0.25 * i)
            wait_for(d, SETTLED, what=f"step {i}")
        wait_for(d, "const t = window.esExplorer.timings; return t[t.length - 1].tDrawn", 10,
                 "the last step's frame")
        steps = d.execute_script("return window.esExplorer.timings")[len(timings):]
    finally:
        if d is not None:
            d.quit()
        rc, err = srv.stop()
    assert rc == 0, err
    V = np.array(shape["V"]).reshape(-1, 3)
    with es.Store(study) as s:
        E = s.edges
        pt = s.point_weights(shape["expr"], pca="p")
    want = pt.lengths * pt.scale
    got = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    rms = np.sqrt(np.mean((got - want) ** 2)) / want.mean()
    assert np.isclose(rms, shape["rms"], rtol=1e-6) and rms < 5e-3
    # the page's shown positions, replayed in order: the mean (seq 1, the page's
    # first request) and every drag position that was solved, not superseded
    solved = [t for t in timings if "tRecv" in t and t["seq"] <= last]
    assert solved[0]["seq"] == 1 and solved[-1]["seq"] == last
    ex = Explorer(study, pca="p")
    try:
        for t in solved:
            mine = ex.embed({t["key"]: t["value"]} if t["key"] else {})
    finally:
        ex.close()
    assert np.max(np.abs(mine.V - V)) <= 1e-9 * bbox(V)
    # the heat map travels beside the positions: distances from the mean shape
    heat = np.linalg.norm(V - ex.mean_V, axis=1)
    assert np.max(np.abs(np.array(shape["heat"]) - heat)) <= 1e-9 * bbox(V)
    drag = [t["tDrawn"] - t["tInput"] for t in solved[1:] if "tDrawn" in t]
    step = [t["tDrawn"] - t["tInput"] for t in steps]
    server = [1000 * t["server"] for t in steps]
    print(f"\nslider input -> mesh drawn, {V.shape[0]} vertices, load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs: drag at 60 Hz median %.0f ms, "
          f"p95 %.0f ms ({len(drag)} of 31 drawn); single steps median %.0f ms, p95 %.0f ms "
          f"(the server's embedding %.0f ms median)"
          % (*percentiles(drag), *percentiles(step), percentiles(server)[0]))


def test_face_study_with_every_kind_of_slider(tmp_path):
    """Real data when ../shared has it: face-study (9.4K vertices) with a PCA,
    a smile and a model of expression and subject, whose subject
    coefficients are directions so large that mean + 1*coef has negative
    lengths (the explorer evaluates directions without that check); a
    position of each kind is edgespace embed's."""
    from conftest import SOURCE_ROOT
    shared = os.environ.get("EDGESPACE_SHARED", os.path.join(SOURCE_ROOT, "..", "shared"))
    data = os.path.join(shared, "data", "face-study")
    if not os.path.isdir(data):
        pytest.skip(f"no face-study at {data}")
    store = tmp_path / "face.h5"
    ctx = es.Context(progress=None)
    es.ingest(store, manifest=os.path.join(data, "manifest.csv"), ctx=ctx)
    with es.Store(store, write=True, ctx=ctx) as s:
        s.pca("p", components=5)
        s.diff("smile", pair_by="subject", column="expression", from_="neutral", to="happy")
        s.model("~ expression + subject", name="es", permutations=0)
    ex = Explorer(store, pca="p", warm=False)
    try:
        keys = [d.key for d in ex.directions]
        assert keys[:6] == ["pc1", "pc2", "pc3", "pc4", "pc5", "diff:smile"]
        assert "coef:es:expression=happy" in keys and "coef:es:subject=s030" in keys
        shape = ex.embed({"pc1": -1.5, "pc3": 0.75, "coef:es:expression=happy": 0.5,
                          "coef:es:subject=s002": 0.25})
    finally:
        ex.close()
    V = cli_embed(store, shape.expr, tmp_path / "cli.ply")
    assert np.max(np.abs(shape.V - V)) <= 1e-9 * bbox(V)
