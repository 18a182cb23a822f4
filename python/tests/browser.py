"""python/tests/browser.py — headless Chromium for the tests that drive a
page as its user's browser does (test_explore.py: edgespace explore's page;
test_widgets.py: the widget in Debian's classic notebook) and for
tools/bench/bench_explore.py. No display is needed."""
import os
import shutil
import time

import pytest


def chromium():
    """A headless Chromium driven by selenium (python3-selenium,
    chromium-driver), or a skip naming what is missing."""
    webdriver = pytest.importorskip("selenium.webdriver",
                                    reason="python3-selenium is not installed (tools/setup.sh)")
    from selenium.webdriver.chrome.service import Service
    driver = shutil.which("chromedriver")
    if not driver or not shutil.which("chromium"):
        pytest.skip("chromium and chromium-driver are not installed (tools/setup.sh)")
    o = webdriver.ChromeOptions()
    # software WebGL (SwiftShader): three.js draws without a GPU or display
    for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
              "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
              "--window-size=1400,900", "--disable-gpu-sandbox"):
        o.add_argument(a)
    o.binary_location = shutil.which("chromium")
    o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(driver), options=o)


def wait_for(driver, script, timeout=60, what=""):
    """The first truthy value the script returns, polled; AssertionError
    after timeout seconds, with the errors an explorer page showed."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        v = driver.execute_script(script)
        if v:
            return v
        time.sleep(0.05)
    errors = driver.execute_script("return window.esExplorer && window.esExplorer.errors")
    raise AssertionError(f"timed out waiting for {what or script} (errors: {errors})")


def screenshot_dir(tmp_path):
    """Where screenshots go: $EDGESPACE_SCREENSHOTS (to look at them), else
    the test's temporary folder."""
    d = os.environ.get("EDGESPACE_SCREENSHOTS")
    if d:
        os.makedirs(d, exist_ok=True)
        return d
    return str(tmp_path)
