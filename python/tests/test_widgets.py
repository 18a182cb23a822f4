"""edgespace.widgets.explore: the Jupyter explorer's backend, driven as a
notebook's front end drives it (setting widget values), without a browser.

Oracles: `edgespace embed` of the point the widget shows, with its options,
to 1e-9 of the bounding-box diagonal; the PNG signature and size of the
view; the store and the files a save leaves (the command's reader)."""
import html
import os
import secrets
import shutil
import socket
import subprocess
import time
import urllib.request

import numpy as np
import pytest

import edgespace as es

pytest.importorskip("ipywidgets")
from conftest import cli_path   # noqa: E402

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def widget(store_path):
    if not es.has_figures():
        pytest.skip("the widget's view needs a library with figures (cairo)")
    import edgespace.widgets as ew
    with es.Store(store_path, write=True, ctx=es.Context(progress=None)) as s:
        s.pca("p", components=3)
        s.diff("smile", pair_by="subject", column="expression", from_="neutral", to="happy")
    w = ew.explore(store_path, pca="p", warm=False)
    yield w
    w.close()


def test_a_slider_moved_in_the_widget_embeds_as_edgespace_embed(widget, store_path, tmp_path):
    assert set(widget.sliders) == {"pc1", "pc2", "pc3", "diff:smile"}
    assert widget.view.value[:8] == PNG and widget.scatter.value[:8] == PNG
    widget.sliders["pc2"].value = -1.25           # what the front end sends on a drag
    widget.sliders["diff:smile"].value = 0.5
    assert widget.wait(60)
    s = widget.shape
    assert s.expr == "mean - 1.25*pc:2 + 0.5*diff:smile" == widget.expr.value
    assert widget.command.value == widget.explorer.command_line(s.expr)
    out = tmp_path / "cli.ply"
    r = subprocess.run([cli_path(), "embed", str(store_path), "--pca", "p", "--point", s.expr,
                        "-o", str(out), "--fast", "--no-store"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with es.Store(store_path) as st:
        V = st.mesh.read_positions(out)
    diag = np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    assert np.max(np.abs(s.V - V)) <= 1e-9 * diag
    # the view with a heat map and turned: a new picture each time
    before = widget.view.value
    widget.heat.value = "displacement"
    with_heat = widget.view.value
    widget.azimuth.value = 40
    assert with_heat[:8] == PNG and len({before, with_heat, widget.view.value}) == 3
    shots = os.environ.get("EDGESPACE_SCREENSHOTS")
    if shots:
        os.makedirs(shots, exist_ok=True)
        with open(os.path.join(shots, "widget_view.png"), "wb") as f:
            f.write(widget.view.value)
        with open(os.path.join(shots, "widget_scatter.png"), "wb") as f:
            f.write(widget.scatter.value)


def test_the_widget_shows_errors_and_goes_on(widget):
    for coords, message in (({"pc1": "abc"}, "not a number"), ({"pc1": 1e300}, "outside"),
                            ({"pc9": 1.0}, "no slider 'pc9'"), ({"diff:smile": 15}, "<= 0")):
        widget.set(**coords)
        assert widget.wait(60)
        assert message in html.unescape(widget.error.value), widget.error.value
    widget.set(pc1=3.0)         # not realizable on these faces: the warning
    assert widget.wait(60)
    assert widget.error.value == "" and "triangle inequality" in widget.warning.value


def test_a_row_and_saving_from_the_widget(widget, store_path):
    widget.row.value = "face_s04_happy"
    assert widget.wait(60)
    assert widget.shape.expr == "row:face_s04_happy" == widget.expr.value
    assert widget.sliders["pc1"].value != 0        # its scores
    widget.name.value = "s04h"
    out = widget._save()
    assert out and os.path.exists(out["path"])
    png = widget._save_png()
    with open(png, "rb") as f:
        assert f.read(8) == PNG
    with es.Store(store_path) as s:
        assert "s04h" in s.results("point")
        assert np.array_equal(s.mesh.read_positions(out["path"]), widget.shape.V)
    assert widget._save() is None and "exists" in widget.error.value
    shutil.rmtree(os.path.dirname(out["path"]), ignore_errors=True)


class ClassicNotebook:
    """Debian's classic notebook server (jupyter-notebook, with the widgets'
    nbextension that python3-ipywidgets brings) on a free loopback port with
    a random token, its config and runtime files in `folder`, until stop().
    Its kernels get this process's environment (the library, PYTHONPATH)."""

    def __init__(self, folder):
        exe = shutil.which("jupyter-notebook")
        if exe is None:
            pytest.skip("jupyter-notebook is not installed (tools/setup.sh)")
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            self.port = s.getsockname()[1]
        self.token = secrets.token_hex(16)
        env = dict(os.environ)
        for var, sub in (("JUPYTER_CONFIG_DIR", "cfg"), ("JUPYTER_RUNTIME_DIR", "rt"),
                         ("JUPYTER_DATA_DIR", "data"), ("IPYTHONDIR", "ipython")):
            env[var] = str(folder / sub)
        args = [exe, "--no-browser", "--ip=127.0.0.1", f"--port={self.port}", "--port-retries=0",
                f"--NotebookApp.token={self.token}", f"--notebook-dir={folder}"]
        if os.geteuid() == 0:
            args.append("--allow-root")
        self.log = open(folder / "notebook.log", "w")
        self.proc = subprocess.Popen(args, env=env, stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.time() + 60
        while time.time() < deadline and self.proc.poll() is None:
            try:
                urllib.request.urlopen(f"{self.url('api/status')}", timeout=5).read()
                return
            except OSError:
                time.sleep(0.3)
        self.stop()
        raise AssertionError(f"jupyter-notebook did not answer:\n{(folder / 'notebook.log').read_text()}")

    def url(self, path):
        return f"http://127.0.0.1:{self.port}/{path}?token={self.token}"

    def stop(self):
        self.proc.terminate()
        try:
            self.proc.wait(30)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()
                self.proc.wait()
            self.log.close()


def test_the_widget_in_a_classic_notebook_in_chromium(store_path, tmp_path):
    """The widget in a real front end: Debian's classic notebook in headless
    Chromium runs a cell that makes it; PageUp on PC 1's slider (a fifth of
    its range: 1.2 sd) travels to the kernel, the page shows the point and a
    new view, and the kernel's shape is `edgespace embed --fast` of that
    point to 1e-9 x bbox."""
    if not es.has_figures():
        pytest.skip("the widget's view needs a library with figures (cairo)")
    from browser import chromium, screenshot_dir, wait_for
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    import nbformat
    with es.Store(store_path, write=True, ctx=es.Context(progress=None)) as s:
        s.pca("p", components=3)
    nb = nbformat.v4.new_notebook()
    nb.cells.append(nbformat.v4.new_code_cell(
        f"import edgespace.widgets as ew\nw = ew.explore({str(store_path)!r}, pca='p', warm=False)\nw"))
    nbformat.write(nb, str(tmp_path / "explore.ipynb"))
    d = chromium()
    server = ClassicNotebook(tmp_path)
    try:
        d.get(server.url("notebooks/explore.ipynb"))
        wait_for(d, "return window.Jupyter && Jupyter.notebook && Jupyter.notebook.kernel && "
                    "Jupyter.notebook.kernel.is_connected()", 180, "the kernel")
        d.execute_script("Jupyter.notebook.execute_all_cells()")
        try:
            wait_for(d, "return document.querySelectorAll('.ui-slider-handle').length >= 5 && "
                        "document.querySelectorAll('.widget-area img').length >= 2", 90,
                     "the widget drawn in the notebook")
        except AssertionError as e:
            d.save_screenshot(os.path.join(screenshot_dir(tmp_path), "widget_notebook.png"))
            out = d.execute_script("return Array.from(document.querySelectorAll('.output_area'))"
                                   ".map(e => e.innerText).join('\\n')")
            log = [x["message"][-300:] for x in d.get_log("browser")]
            raise AssertionError(f"{e}; the cell's output: {out[-3000:]}; the browser's "
                                 f"console: {log[-20:]}") from None
        images = "return Array.from(document.querySelectorAll('.widget-area img')).map(e => e.src)"
        before = d.execute_script(images)
        expr = "return Array.from(document.querySelectorAll('.widget-text input')).map(e => e.value)"
        assert "mean" in d.execute_script(expr)
        d.find_elements(By.CSS_SELECTOR, ".ui-slider-handle")[0].send_keys(Keys.PAGE_UP)
        wait_for(d, "return Array.from(document.querySelectorAll('.widget-text input'))"
                    ".some(e => e.value === 'mean + 1.2*pc:1')", 60, "the point in the page")
        wait_for(d, f"const s = {images[7:]}; return s.length === {len(before)} && "
                    f"s.every((x, i) => x !== {before}[i])", 60, "the new view and scatter")
        d.save_screenshot(os.path.join(screenshot_dir(tmp_path), "widget_notebook.png"))
        out = tmp_path / "kernel.npy"
        d.execute_script("const c = Jupyter.notebook.insert_cell_below('code', 0);"
                         "c.set_text(arguments[0]); c.execute();",
                         f"import numpy as np\nassert w.wait(60)\n"
                         f"np.save({str(out)!r}, w.shape.V) if w.shape.expr == 'mean + 1.2*pc:1' "
                         "else None")
        wait_for(d, "return Jupyter.notebook.kernel_busy === false && "
                    "document.querySelectorAll('.input_prompt')[1].textContent.includes('2')",
                 60, "the second cell")
    finally:
        d.quit()
        server.stop()
    V = np.load(out)
    cli = tmp_path / "cli.ply"
    r = subprocess.run([cli_path(), "embed", str(store_path), "--pca", "p", "--point",
                        "mean + 1.2*pc:1", "-o", str(cli), "--fast", "--no-store"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with es.Store(store_path) as st:
        want = st.mesh.read_positions(cli)
    assert np.max(np.abs(V - want)) <= 1e-9 * np.linalg.norm(want.max(axis=0) - want.min(axis=0))
