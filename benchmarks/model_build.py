"""Model building: a chain built one JOINT at a time, against the same chain in one STARTMODEL block.

Issue 24 found ``check`` of a ten-line loop adding one joint per pass
(``M :- JOINT I, M, ...``) quadratic: 2.3 s at 300 joints, 25 s at 1,200,
and no end at 3,000 in a minute. A JOINT statement now costs Python work
independent of the size of the model it extends (runtime/limits.py
``check_joined``, runtime/figure/tree.py ``Figure._grafted``).

Measured side by side in one run, each the best of a few rounds, in
process (compile, then the program's statements as ``check`` runs them):

* ``loop``: ``M :- JOINT I, M, ...`` in a DO loop of N passes;
* ``block``: what a user would otherwise write, the same N JOINTs as one
  ``STARTMODEL ... ENDMODEL`` block (assembled at once, linear).

Reported per size: CPU and wall seconds, CPU microseconds per joint, and the
ratios loop / block and (per kind) CPU at the largest size over CPU at half
of it (2 for linear work, 4 for quadratic). The loop still copies the
model's tuples at C speed on each pass (a model is a value), which shows at
20,000 joints.

Usage: ``python benchmarks/model_build.py [--quick]``; the last line is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

LOOP = """\
      GRAPHICAL G
      MODEL M
      INTEGER I
      G :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      M :- JOINT 0, G, (0.0, 1.0, 0.0), G, (0.0, 0.0, 0.0), (-10, 10)
      DO 10 I = 1, {n}
        M :- JOINT I, M, (0.0, 1.0, 0.0), G, (0.0, 0.0, 0.0), (-10, 10)
 10   CONTINUE
"""


def block_program(n: int) -> str:
    """The same chain, ``n + 1`` joints, as one STARTMODEL block, each segment named (as an imported BVH is)."""
    names = [f"S{i}" for i in range(n + 2)]
    lines = ["      GRAPHICAL G", "      MODEL M"]
    lines += ["      GRAPHICAL " + ", ".join(names[k : k + 8]) for k in range(0, len(names), 8)]
    lines.append("      G :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0")
    lines += [f"      {name} :- G" for name in names]
    lines.append("      STARTMODEL M")
    for i in range(n + 1):
        lines.append(f"        JOINT {i}, {names[i]}, (0.0, 1.0, 0.0), {names[i + 1]}, (0.0, 0.0, 0.0), (-10, 10)")
    lines.append("      ENDMODEL")
    return "\n".join(lines) + "\n"


def measure(text: str, rounds: int) -> tuple[float, float, int]:
    """(best CPU s, best wall s, joints of M) of compiling ``text`` and running its statements."""
    from liganimate.compiler import load_program

    best_cpu = best_wall = float("inf")
    joints = 0
    for _ in range(rounds):
        c0, w0 = time.process_time(), time.perf_counter()
        program, _ = load_program(text=text, name="chain.lig")
        rt = program.execute("check")
        best_cpu = min(best_cpu, time.process_time() - c0)
        best_wall = min(best_wall, time.perf_counter() - w0)
        joints = rt.variables["M"].n_joints
    return best_cpu, best_wall, joints


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="under a minute: 1,000 to 4,000 joints, one round")
    args = parser.parse_args(argv)
    sizes = (1_000, 2_000, 4_000) if args.quick else (1_000, 5_000, 10_000, 20_000)
    rounds = 1 if args.quick else 2
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    rows = {}
    print(
        f"{'joints':>8} {'loop cpu s':>11} {'wall s':>8} {'us/joint':>9} {'block cpu s':>12} {'wall s':>8} {'loop/block':>11}"
    )
    for n in sizes:
        lc, lw, lj = measure(LOOP.format(n=n), rounds)
        bc, bw, bj = measure(block_program(n), rounds)
        assert lj == bj == n + 1, (lj, bj)
        rows[n] = {
            "loop_cpu": round(lc, 3),
            "loop_wall": round(lw, 3),
            "block_cpu": round(bc, 3),
            "block_wall": round(bw, 3),
        }
        print(f"{n + 1:>8} {lc:>11.3f} {lw:>8.3f} {1e6 * lc / n:>9.1f} {bc:>12.3f} {bw:>8.3f} {lc / bc:>11.2f}")
    top, half = sizes[-1], sizes[-2]
    summary = {
        "sizes": list(sizes),
        "rows": rows,
        "loop_cpu_ratio_top_over_half": round(rows[top]["loop_cpu"] / rows[half]["loop_cpu"], 2),
        "block_cpu_ratio_top_over_half": round(rows[top]["block_cpu"] / rows[half]["block_cpu"], 2),
        "size_ratio": top / half,
        "loop_over_block_at_top": round(rows[top]["loop_cpu"] / rows[top]["block_cpu"], 2),
        "quick": args.quick,
    }
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
