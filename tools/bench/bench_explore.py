#!/usr/bin/python3
"""tools/bench/bench_explore.py — how fast `edgespace explore` answers a
slider: the time from a slider's input event to its mesh drawn, in headless
Chromium (python3-selenium, chromium-driver), for a drag across PC 1.

    /usr/bin/python3 tools/bench/bench_explore.py [STORE] [--pca NAME] [--steps N]
                                                 [--lo T] [--hi T]

STORE: a store with a PCA; without one, face-study (../shared/data, or
$EDGESPACE_SHARED/data) is ingested into a temporary folder with a PCA of
10 components. Two drags from --lo to --hi sd on PC 1 (-3 to 3: the
slider's range; positions whose lengths are not all positive, face-study's
below -2.25 sd, are refused with an error and counted):
  - drag: input events every 16 ms (a mouse drag at 60 Hz), as the page gets
    them from a slider; positions the server had not started when a newer
    one came are skipped (superseded), as in use;
  - step: one position at a time, each sent once the last is drawn: the
    latency of a single move.
Each shown mesh counts from its input event (performance.now()) to the
animation frame after three.js drew it; the server's own time (prior,
solve, heat maps) is given beside it. Prints figures; never a test.
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "python"))
sys.path.insert(0, os.path.join(ROOT, "python", "tests"))


def edgespace_exe():
    return os.environ.get("EDGESPACE", os.path.join(ROOT, "build", "tools", "edgespace"))


def face_study(tmp):
    shared = os.environ.get("EDGESPACE_SHARED", os.path.join(ROOT, "..", "shared"))
    data = os.path.join(shared, "data", "face-study")
    if not os.path.isdir(data):
        sys.exit(f"bench_explore: no store given and no face-study at {data}")
    store = os.path.join(tmp, "face-study.h5")
    for args in (["ingest", store, "--manifest", os.path.join(data, "manifest.csv")],
                 ["pca", store, "--name", "faces", "--components", "10"]):
        subprocess.run([edgespace_exe(), *args], check=True, stdout=subprocess.DEVNULL)
    return store


def stats(name, xs):
    xs = sorted(xs)
    if not xs:
        return f"{name}: none"
    p95 = xs[min(len(xs) - 1, int(round(0.95 * (len(xs) - 1))))]
    return (f"{name}: median {statistics.median(xs):.0f} ms, p95 {p95:.0f} ms, "
            f"min {xs[0]:.0f}, max {xs[-1]:.0f} (n = {len(xs)})")


def report(label, timings, first, last):
    ts = [t for t in timings if first <= t["seq"] <= last]
    shown = [t for t in ts if t.get("tDrawn")]
    skipped = [t for t in ts if t.get("superseded")]
    errors = [t for t in ts if t.get("error")]
    print(f"{label}: {len(ts)} positions, {len(shown)} drawn, {len(skipped)} superseded, "
          f"{len(errors)} refused")
    print("  " + stats("input -> drawn", [t["tDrawn"] - t["tInput"] for t in shown]))
    print("  " + stats("server (prior + solve + heat maps)",
                       [1000 * t["server"] for t in shown]))
    print("  " + stats("server CPU", [1000 * t["serverCpu"] for t in shown]))
    print("  " + stats("received -> drawn", [t["tDrawn"] - t["tRecv"] for t in shown]))
    print("  " + stats("input -> received, less the server",
                       [t["tRecv"] - t["tInput"] - 1000 * t["server"] for t in shown]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("store", nargs="?")
    ap.add_argument("--pca", default=None)
    ap.add_argument("--steps", type=int, default=121)
    ap.add_argument("--lo", type=float, default=-3.0)
    ap.add_argument("--hi", type=float, default=3.0)
    ap.add_argument("--screenshot", default=None, help="save the page's PNG here at the end")
    a = ap.parse_args()
    from browser import chromium, wait_for
    from test_explore import DRAG, SETTLED, Server
    tmp = tempfile.mkdtemp(prefix="bench_explore-")
    try:
        store = a.store or face_study(tmp)
        t0 = time.time()
        srv = Server(store, *(["--pca", a.pca] if a.pca else []))
        print(f"store {store}; the server listened after {time.time() - t0:.1f} s; "
              f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")
        d = chromium()
        try:
            d.get(srv.url)
            t0 = time.time()
            wait_for(d, SETTLED, 120, "the mean")
            info = d.execute_script("return window.esExplorer.state.info")
            print(f"{info['nverts']} vertices, {info['nfaces']} faces; the page showed the mean "
                  f"{time.time() - t0:.1f} s after loading")
            for label, dt in (("drag (input every 16 ms)", 16), ("step (one at a time)", None)):
                if dt:
                    first = d.execute_script(DRAG, "pc1", a.lo, a.hi, a.steps, dt)
                    time.sleep(a.steps * dt / 1000 + 0.5)
                else:
                    first = d.execute_script("return window.esExplorer.state.seq + 1")
                    for i in range(25):
                        d.execute_script("window.esExplorer.setSlider('pc1', arguments[0])",
                                         round(a.lo + (a.hi - a.lo) * i / 24, 4))
                        wait_for(d, SETTLED, 60)
                wait_for(d, SETTLED, 120)
                time.sleep(0.2)
                last = d.execute_script("return window.esExplorer.state.seq")
                report(label, d.execute_script("return window.esExplorer.timings"), first, last)
            print(f"load average at the end {os.getloadavg()[0]:.1f}")
            if a.screenshot:
                d.save_screenshot(a.screenshot)
        finally:
            d.quit()
            srv.stop()
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
