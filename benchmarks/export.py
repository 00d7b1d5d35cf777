"""Export and import benchmark: a long five-figure scene to glTF and BVH, a long capture in, against rendering.

The scene is ``benchmarks/five_humans.lig`` (five Appendix A humans, three
squatting and two walking on the spot) lengthened to 10,000 ticks (1,000
with ``--quick``).  Timed, each from the compiled program (compiling is
outside every timing, as it is the same for all):

* ``render``: ``Program.render`` to PNG files, as ``liganimate run`` does;
* ``gltf``: running the scenes without drawing and writing a ``.glb``, with
  the default skinned rig and with ``rig="nodes"`` (the node tree) beside it;
* ``bvh``: the same, writing one ``.bvh`` per figure;
* ``import``: reading a BVH capture of as many frames (the first figure's
  export) and writing its LIG library.

The goal is that export and import each cost less than a tenth of
rendering.  Each figure is the best of a few rounds (the machine is
shared); CPU time is reported beside wall time.  The last line printed is
one JSON object.

Usage: ``python benchmarks/export.py [--quick]``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import tempfile
import time

from liganimate.compiler import load_program
from liganimate.runtime import exchange as X

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "five_humans.lig")


def lengthened(folder: str, ticks: int) -> str:
    """The five-figure scene with ``ticks`` ticks, written into ``folder``."""
    with open(SCENE, encoding="utf-8") as fh:
        text = fh.read()
    text = text.replace("STARTSCENE LENGTH 1000", f"STARTSCENE LENGTH {ticks}")
    text = re.sub(r"FROM 0 TO 999 ", f"FROM 0 TO {ticks - 1} ", text)
    path = os.path.join(folder, "five_humans_long.lig")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return path


def best(fn, rounds: int) -> float:
    """The shortest of ``rounds`` wall-clock timings of ``fn()``."""
    return best_with_cpu(fn, rounds)[0]


def best_with_cpu(fn, rounds: int) -> tuple[float, float]:
    """(wall, CPU) seconds of the round of ``fn()`` with the least CPU time, of ``rounds``."""
    times = []
    for _ in range(rounds):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        times.append((time.process_time() - c0, time.perf_counter() - t0))
    cpu, wall = min(times)
    return wall, cpu


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="1,000 ticks, one round of rendering (under a minute)")
    args = ap.parse_args(argv)
    ticks = 1000 if args.quick else 10_000
    rounds = 2 if args.quick else 3
    with tempfile.TemporaryDirectory() as tmp:
        program, _ = load_program(lengthened(tmp, ticks))
        out = os.path.join(tmp, "out")
        os.makedirs(out)

        def render():
            program.render(os.path.join(tmp, "frames"), quiet=True)

        def gltf():
            data, _ = X.gltf_bytes(X.collect(program), True)
            X.write_files([(os.path.join(out, "film.glb"), data)])

        def gltf_nodes():
            data, _ = X.gltf_bytes(X.collect(program), True, rig="nodes")
            X.write_files([(os.path.join(out, "film-nodes.glb"), data)])

        def bvh():
            X.write_files(X.bvh_files(X.collect(program), os.path.join(out, "film.bvh"), 24.0))

        t_render = best(render, 1 if args.quick else 2)
        t_gltf, c_gltf = best_with_cpu(gltf, rounds)
        t_nodes, c_nodes = best_with_cpu(gltf_nodes, rounds)
        t_bvh = best(bvh, rounds)
        capture = os.path.join(out, "film-scene1-H1.bvh")

        def import_():
            clip = X.read_bvh(capture)
            X.write_files([(os.path.join(out, "capture.lig"), X.lig_library(clip, "H", "M"))])

        t_import = best(import_, rounds)
        sizes = {
            "glb_bytes": os.path.getsize(os.path.join(out, "film.glb")),
            "glb_nodes_bytes": os.path.getsize(os.path.join(out, "film-nodes.glb")),
            "bvh_bytes": os.path.getsize(capture),
            "lig_bytes": os.path.getsize(os.path.join(out, "capture.lig")),
        }
    result = {
        "ticks": ticks,
        "figures": 5,
        "render_s": round(t_render, 3),
        "gltf_s": round(t_gltf, 3),
        "gltf_cpu_s": round(c_gltf, 3),
        "gltf_nodes_s": round(t_nodes, 3),
        "gltf_nodes_cpu_s": round(c_nodes, 3),
        "skin_over_nodes_cpu": round(c_gltf / c_nodes, 3),
        "bvh_s": round(t_bvh, 3),
        "import_s": round(t_import, 3),
        "gltf_over_render": round(t_gltf / t_render, 4),
        "bvh_over_render": round(t_bvh / t_render, 4),
        "import_over_render": round(t_import / t_render, 4),
        "goal_met": max(t_gltf, t_bvh, t_import) < t_render / 10,
        **sizes,
    }
    print(
        f"{ticks} ticks, five figures: render {t_render:.2f} s; glTF {t_gltf:.3f} s "
        f"({100 * t_gltf / t_render:.1f}%; CPU {c_gltf:.3f} s, node tree {c_nodes:.3f} s), BVH {t_bvh:.3f} s ({100 * t_bvh / t_render:.1f}%), "
        f"import of a {ticks}-frame capture {t_import:.3f} s ({100 * t_import / t_render:.1f}%)"
    )
    sys.stdout.write(json.dumps(result) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
