"""Studio Save benchmark: the humanoid's Save, as it was (the whole library compiled) beside as it is.

``liganimate studio`` Save writes the posed model and the kept poses as a
LIG library, checking first that it compiles.  For the standard library's
HUMANOID the library is about 2,700 lines, almost all DRAW POLY statements
of the figure's PRIMITIVEs, the same at every Save.  Measured side by side
in one run (best of interleaved rounds, CPU time beside wall time):

* ``whole``: compiling the whole library, what every Save did (3.9 s a
  Save before the checker's call graph was built once per check instead of
  once per PRIMITIVE);
* ``save``: a Save as the studio does it now, after the session's warm-up
  (a background thread that compiles the whole library once, while the
  user poses): the PRIMITIVEs cut to one triangle each, the rest in full,
  then the atomic write, then the state the page gets back.

The goal (issue 25) is a Save under 0.5 s.  The last line printed is one
JSON object with the figures.

Usage: ``python benchmarks/studio_save.py [--quick]`` (``--quick``: 2 rounds).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time

from liganimate.runtime.studio import Session, studio_model
from liganimate.runtime.studio._session import check_library

GOAL_S = 0.5


def measure(fn) -> tuple:
    """(CPU seconds, wall seconds) of ``fn()``."""
    c0, w0 = time.process_time(), time.perf_counter()
    fn()
    return time.process_time() - c0, time.perf_counter() - w0


def run(rounds: int) -> dict:
    fig, _, _ = studio_model(None, None)
    folder = tempfile.mkdtemp(prefix="liganimate-save-")
    try:
        path = os.path.join(folder, "poses.lig")
        session = Session(fig, "HUMANOID", "POSES", path, seed=7)
        for action in ({"action": "keep"}, {"action": "next"}, {"action": "take", "candidate": 1, "link": 3}):
            session.act(action)
        session.act({"action": "keep"})
        warm = measure(lambda: (session.warm(), session._warming.join()))
        session.act({"action": "save"})
        with open(path, encoding="utf-8") as f:
            text = f.read()
        best = {}
        for _ in range(rounds):
            for name, fn in (
                ("whole", lambda: check_library(text, path)),
                ("save", lambda: session.act({"action": "save"})),
            ):
                cpu, wall = measure(fn)
                if name not in best or cpu < best[name][0]:
                    best[name] = (cpu, wall)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    result = {"rounds": rounds, "lines": text.count("\n"), "goal_s": GOAL_S}
    result["warm_up_cpu_s"], result["warm_up_wall_s"] = round(warm[0], 3), round(warm[1], 3)
    for name, (cpu, wall) in best.items():
        result[f"{name}_cpu_s"], result[f"{name}_wall_s"] = round(cpu, 3), round(wall, 3)
    result["ratio_cpu"] = round(best["whole"][0] / best["save"][0], 2)
    result["within_goal"] = best["save"][1] < GOAL_S
    return result


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="2 rounds")
    ap.add_argument("--rounds", type=int, default=None)
    args = ap.parse_args(argv)
    r = run(args.rounds or (2 if args.quick else 5))
    print(f"HUMANOID library, {r['lines']} lines; best of {r['rounds']} rounds; seconds CPU (wall)")
    print(f"  warm-up, once a session, in the background: {r['warm_up_cpu_s']:.3f} ({r['warm_up_wall_s']:.3f})")
    print(f"  whole library compiled (every Save before): {r['whole_cpu_s']:.3f} ({r['whole_wall_s']:.3f})")
    print(f"  Save now:                                   {r['save_cpu_s']:.3f} ({r['save_wall_s']:.3f})")
    print(f"  {r['ratio_cpu']}x less CPU; goal {GOAL_S} s: {'met' if r['within_goal'] else 'NOT met'}")
    print(json.dumps(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
