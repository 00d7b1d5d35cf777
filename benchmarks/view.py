"""Viewer and studio benchmark: the five-figure page's size and load time, and the Generator's speed.

* ``page``: ``liganimate view`` on ``benchmarks/five_humans.lig`` (five
  Appendix A humans, 1,000 ticks): the time to run the scene without
  drawing and build the page, and the page's size (goal: under 10 MB);
* ``load``: headless Chromium (Debian's chromium and chromium-driver,
  WebGL through SwiftShader) opening the page from its file, from
  navigation to the first frame drawn, as the page measures it
  (``performance.now()`` when the viewer is ready; goal: under 2 s).  The
  best of a few loads (the machine is shared);
* ``draw``: in the same browser, the page drawing 100 frames of the scene
  one after another (``setFrame``, then a pixel read that waits for the
  GPU), in the thesis look and the modern look, and of the modern look's
  time the contact shadow's (``LigShadow.compute``: the height map from the
  pose, its blur; the goal is a small share of a frame at 24 frames a
  second);
* ``generator``: the studio's Generator producing nine candidates for the
  library HUMANOID, first generation and later ones at three intensities
  (goal: under 50 ms each).  The median and the worst of many.

Usage: ``python benchmarks/view.py [--quick]`` (``--quick``: fewer rounds,
under a minute).  The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "five_humans.lig")
# The browser tests' Chromium, started the same way (flags, fresh profile, no network of its own).
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests"))

from browser import Browser, missing  # noqa: E402 - found through the sys.path line above


def build_page(folder: str):
    """Run the scene and write its page; return (path, seconds)."""
    from liganimate.compiler import load_program
    from liganimate.runtime import exchange as X
    from liganimate.runtime.view import viewer_html

    program, _ = load_program(SCENE)
    t0 = time.perf_counter()
    page = viewer_html(X.collect(program), "five_humans.lig").encode("utf-8")
    path = os.path.join(folder, "five_humans.html")
    X.write_files([(path, page)])
    return path, time.perf_counter() - t0


# Draws 100 frames; the milliseconds a frame, and the contact shadow's share of them.
_DRAW = """
var real = LigShadow.compute, spent = 0;
LigShadow.compute = function (pos, objects) {
  var t = performance.now(), m = real(pos, objects);
  spent += performance.now() - t;
  return m;
};
var gl = document.getElementById('view').getContext('webgl'), px = new Uint8Array(4);
var t0 = performance.now();
for (var f = 0; f < 100; f++) ligViewer.setFrame(f * 7);
gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
LigShadow.compute = real;
return [(performance.now() - t0) / 100, spent / 100];
"""


def draw_times(driver, path: str, rounds: int) -> dict:
    """Milliseconds a frame drawing the page, in each look, and the modern look's shadow; the best of ``rounds``."""
    out: dict = {}
    for _ in range(rounds):
        for look in ("thesis", "modern"):
            driver.get("about:blank")
            driver.get("file://" + os.path.abspath(path) + f"#size=640x480&look={look}")
            deadline = time.time() + 60
            while not driver.execute_script("return !!(window.ligViewer && window.ligViewer.ready)"):
                if time.time() > deadline:
                    raise RuntimeError("the viewer did not start")
                time.sleep(0.02)
            frame, shadow = driver.execute_script(_DRAW)
            out[f"{look}_ms"] = min(out.get(f"{look}_ms", frame), frame)
            if look == "modern":
                out["shadow_ms"] = min(out.get("shadow_ms", shadow), shadow)
    return out


def load_times(path: str, rounds: int, draws: dict):
    """Milliseconds from navigation to the first frame, one per load; None without Chromium.

    ``draws`` receives :func:`draw_times`'s figures, measured in the same browser.
    """
    if missing():
        return None
    times = []
    with Browser(1000, 760) as browser:
        driver = browser.driver
        draws.update(draw_times(driver, path, rounds))
        for _ in range(rounds):
            driver.get("about:blank")
            driver.get("file://" + os.path.abspath(path))
            deadline = time.time() + 60
            ready = None
            while ready is None and time.time() < deadline:
                ready = driver.execute_script("return window.ligViewer ? window.ligViewer.ready : null")
                if ready is None:
                    time.sleep(0.02)
            if ready is None:
                raise RuntimeError("the viewer did not start")
            times.append(float(ready))
    return times


def generator_times(rounds: int) -> dict:
    """Seconds per population of nine for the library HUMANOID."""
    from liganimate.runtime.studio import Generator, studio_model

    fig = studio_model(None, None)[0]
    Generator(fig, seed=0)  # builds the tessellations once, as a running studio has
    out = {}
    first = []
    for seed in range(rounds):
        t0 = time.perf_counter()
        Generator(fig, seed=seed)
        first.append(time.perf_counter() - t0)
    out["first"] = first
    for intensity in (0.1, 0.4, 1.0):
        g = Generator(fig, seed=1, intensity=intensity)
        times = []
        for k in range(rounds):
            g.take(k % 9, k % fig.n_joints)
            if k % 7 == 6:
                g.set_mode("twist" if g.mode == "flexion" else "flexion")
            t0 = time.perf_counter()
            g.next_generation()
            times.append(time.perf_counter() - t0)
        out[f"later_{intensity:g}"] = times
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer rounds (under a minute)")
    args = ap.parse_args(argv)
    loads, gens = (2, 20) if args.quick else (5, 200)
    result: dict = {"scene": "benchmarks/five_humans.lig", "ticks": 1000, "figures": 5}
    with tempfile.TemporaryDirectory() as tmp:
        path, build = build_page(tmp)
        size = os.path.getsize(path)
        print(f"page: {size / 1e6:.2f} MB (goal < 10 MB), built in {build:.2f} s")
        result.update(html_bytes=size, html_mb=round(size / 1e6, 3), build_s=round(build, 3))
        draws: dict = {}
        times = load_times(path, loads, draws)
    if times is None:
        print("load: skipped (no chromium, chromium-driver or selenium)")
        result["load_ms"] = None
    else:
        print(f"load: best {min(times):.0f} ms, all {[round(t) for t in times]} (goal < 2000 ms)")
        result.update(load_ms=round(min(times), 1), load_ms_all=[round(t, 1) for t in times])
        th, mo, sh = draws["thesis_ms"], draws["modern_ms"], draws["shadow_ms"]
        print(
            f"draw: thesis look {th:.2f} ms a frame, modern look {mo:.2f} ms ({mo / th:.1f}x), "
            f"of which the contact shadow {sh:.2f} ms ({100 * sh / mo:.0f} %)"
        )
        result["draw_ms"] = {k: round(v, 3) for k, v in draws.items()}
    g = generator_times(gens)
    summary = {}
    for name, ts in g.items():
        med, worst = statistics.median(ts) * 1e3, max(ts) * 1e3
        print(f"generator {name}: median {med:.1f} ms, worst {worst:.1f} ms (goal < 50 ms)")
        summary[name] = {"median_ms": round(med, 2), "max_ms": round(worst, 2)}
    result["generator"] = summary
    result["generator_median_ms"] = round(max(v["median_ms"] for v in summary.values()), 2)
    result["goals_met"] = bool(
        size < 10e6 and (times is None or min(times) < 2000) and result["generator_median_ms"] < 50
    )
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
