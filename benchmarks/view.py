"""Viewer and studio benchmark: the five-figure page's size and load time, and the Generator's speed.

* ``page``: ``liganimate view`` on ``benchmarks/five_humans.lig`` (five
  Appendix A humans, 1,000 ticks): the time to run the scene without
  drawing and build the page, and the page's size (goal: under 10 MB);
* ``load``: headless Chromium (Debian's chromium and chromium-driver,
  WebGL through SwiftShader) opening the page from its file, from
  navigation to the first frame drawn, as the page measures it
  (``performance.now()`` when the viewer is ready; goal: under 2 s).  The
  best of a few loads (the machine is shared);
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


def load_times(path: str, rounds: int):
    """Milliseconds from navigation to the first frame, one per load; None without Chromium."""
    if missing():
        return None
    times = []
    with Browser(1000, 760) as browser:
        driver = browser.driver
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
        times = load_times(path, loads)
    if times is None:
        print("load: skipped (no chromium, chromium-driver or selenium)")
        result["load_ms"] = None
    else:
        print(f"load: best {min(times):.0f} ms, all {[round(t) for t in times]} (goal < 2000 ms)")
        result.update(load_ms=round(min(times), 1), load_ms_all=[round(t, 1) for t in times])
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
