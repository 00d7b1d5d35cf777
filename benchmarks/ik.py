"""Inverse kinematics benchmark: liganimate's batched solver vs ikpy on the same chains and targets.

Chains of 6, 10 and 30 hinge joints, each 1 long in all (equal segments
along +Y), turning alternately about Z within (-120, 120) degrees and about
X within (-90, 90) -- built once as a liganimate figure and once as an ikpy
chain, whose forward kinematics are checked to agree.  For each chain, 1,000
targets are drawn reachable: random joint angles within the limits (seeded),
then forward kinematics.  Both solvers start every solve from the neutral
pose.  A solve succeeds when its final error is under 1e-3 of the chain's
length.

* liganimate: ``solve_pose`` with damped least squares on the whole batch of
  1,000 targets at once, stopping at 1e-4 of the chain length, at most 30
  iterations per attempt and 3 seeded restarts for solves that end in a
  local minimum against the limits.  Also reported: the same solver with
  no restarts and its default iteration limit, and one target per call
  (no batching: ``solve_pose`` with unbatched goals, the path the
  language's STARTREACH takes; same options, same targets).
* ikpy: ``Chain.inverse_kinematics`` with its default optimizer
  (scipy's bounded ``least_squares``) and tolerances, one target per call.

Reported per chain, for both: success rate, median final error and solves
per second, and their ratios, batched and one per call (goals: ten times
ikpy's speed with at least its success, each way).  Timings are the best of several rounds,
liganimate's and ikpy's interleaved (the 2-core machine is shared; other
load only slows a round down; liganimate's batch is timed four times a
round).  ``--quick`` (under a minute) solves a
subsample of the targets with ikpy (success and error then compare both on
that same subsample).  The last line printed is one JSON object.

Usage: ``python benchmarks/ik.py [--quick]``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings

# One BLAS thread, set before numpy loads: the batched solves are many small
# products, and idle OpenBLAS threads spinning on this 2-core machine only
# slow down whichever solver is timed next.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from liganimate.runtime.figure import kinematics as K  # noqa: E402
from liganimate.runtime.figure.tree import Figure, Joint, Link  # noqa: E402
from liganimate.runtime.ik.reach import PointGoal, solve_pose  # noqa: E402

CHAINS = (6, 10, 30)
TARGETS = 1000
SUCCESS = 1e-3  # of the chain's length
TOLERANCE = 1e-4  # liganimate's stopping tolerance, of the chain's length (10 times under success)
OURS = dict(tolerance=TOLERANCE, max_iterations=30, restarts=3)
OURS_PLAIN = dict(tolerance=TOLERANCE)


def axis_and_limits(i: int) -> tuple[int, tuple[float, float]]:
    """Joint ``i`` turns about Z (axis 2) or X (axis 0), alternately."""
    return (2, (-120.0, 120.0)) if i % 2 == 0 else (0, (-90.0, 90.0))


def liganimate_chain(n: int) -> Figure:
    """The chain as a figure: link k's joint at its origin, the next one at (0, 1/n, 0)."""
    seg = 1.0 / n
    links = [Link(f"C{i}", None) for i in range(n + 1)]
    joints = []
    for i in range(n):
        axis, lim = axis_and_limits(i)
        ext = [(0.0, 0.0)] * 3
        ext[axis] = lim
        joints.append(Joint(i + 1, i, i + 1, (0, seg if i else 0, 0), (0, 0, 0), ext))
    return Figure(tuple(links), tuple(joints))


def ikpy_chain(n: int):
    """The same chain for ikpy: an origin link, n revolute links, a fixed tip link."""
    from ikpy.chain import Chain
    from ikpy.link import OriginLink, URDFLink

    seg = 1.0 / n
    links = [OriginLink()]
    for i in range(n):
        axis, lim = axis_and_limits(i)
        vec = [0.0, 0.0, 0.0]
        vec[axis] = 1.0
        links.append(
            URDFLink(
                f"j{i}",
                origin_translation=[0, seg if i else 0, 0],
                origin_orientation=[0, 0, 0],
                rotation=vec,
                bounds=tuple(np.deg2rad(lim)),
            )
        )
    links.append(URDFLink("tip", origin_translation=[0, seg, 0], origin_orientation=[0, 0, 0], joint_type="fixed"))
    return Chain(links, active_links_mask=[False] + [True] * n + [False])


def targets_for(fig: Figure, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Random joint angles within the limits, shape (T, n, 3), and the tips they put, shape (T, 3)."""
    lo, hi = fig.extremes[..., 0], fig.extremes[..., 1]
    angles = rng.uniform(lo, hi, size=(TARGETS, n, 3))
    X = K.pose_transforms(fig, angles)[:, -1]
    return angles, X[:, :3, :3] @ np.array([0, 1.0 / n, 0]) + X[:, :3, 3]


def check_same_chain(fig, chain, angles, tips, n):
    """ikpy's forward kinematics put the tip where liganimate's do."""
    for a, t in zip(angles[:20], tips[:20]):
        full = np.zeros(n + 2)
        full[1:-1] = np.deg2rad(a.sum(axis=1))  # one non-locked axis per joint
        got = chain.forward_kinematics(full)[:3, 3]
        assert np.allclose(got, t, atol=1e-12), (got, t)


def solve_ours(fig, n, tips, **options):
    """One batched solve: (errors (T,), seconds)."""
    goal = PointGoal(n, tips, point=(0, 1.0 / n, 0))
    t0 = time.perf_counter()
    sol = solve_pose(fig, [goal], **options)
    return sol.residuals[:, 0], time.perf_counter() - t0


def solve_ours_one_by_one(fig, n, tips, **options):
    """A Python loop of single solves: (errors, seconds)."""
    errors = np.empty(len(tips))
    t0 = time.perf_counter()
    for i, t in enumerate(tips):
        errors[i] = solve_pose(fig, [PointGoal(n, t, point=(0, 1.0 / n, 0))], **options).residuals[0]
    return errors, time.perf_counter() - t0


def solve_ikpy(chain, n, tips):
    """ikpy, one target per call from the neutral pose: (errors, seconds)."""
    errors = np.empty(len(tips))
    start = np.zeros(n + 2)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i, t in enumerate(tips):
            q = chain.inverse_kinematics(t, initial_position=start)
            errors[i] = np.linalg.norm(chain.forward_kinematics(q)[:3, 3] - t)
    return errors, time.perf_counter() - t0


def summary(errors: np.ndarray, rate: float) -> dict:
    return {
        "success": round(float(np.mean(errors < SUCCESS)), 4),
        "median_error": float(f"{np.median(errors):.3g}"),
        "solves_per_s": round(rate, 1),
        "targets": int(len(errors)),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a short run (under a minute): ikpy on a subsample")
    args = ap.parse_args(argv)
    rounds = 3 if args.quick else 5
    # ikpy solves per chain (all of them in a full run), in `rounds` interleaved chunks.
    ikpy_count = {6: 60, 10: 45, 30: 15} if args.quick else {n: TARGETS for n in CHAINS}
    # One-per-call solves: at least ikpy's sample, so the per-call success
    # is compared on the very targets ikpy solved.
    single_count = 60 if args.quick else TARGETS

    rng = np.random.default_rng(20240601)
    setup = {}
    for n in CHAINS:
        fig, chain = liganimate_chain(n), ikpy_chain(n)
        angles, tips = targets_for(fig, n, rng)
        check_same_chain(fig, chain, angles, tips, n)
        setup[n] = (fig, chain, tips)
        solve_ours(fig, n, tips[:10], **OURS)  # warm caches

    print(
        f"chains: {', '.join(map(str, CHAINS))} hinge joints with limits, length 1; {TARGETS} reachable targets each; "
        f"success: error < {SUCCESS:g} of the length"
    )
    print(
        f"liganimate: DLS, batched, tolerance {TOLERANCE:g}, max 30 iterations, 3 restarts; "
        f"ikpy: inverse_kinematics, defaults, one call per target"
    )
    print(
        f"timing: best of {rounds} interleaved rounds (4 liganimate batches a round)"
        + (" (ikpy on a subsample: --quick)" if args.quick else "")
    )

    results = {}
    for n in CHAINS:
        fig, chain, tips = setup[n]
        k = ikpy_count[n]
        chunks = np.array_split(np.arange(k), rounds)
        singles = np.array_split(np.arange(single_count), rounds)
        ours_best = plain_best = single_best = 0.0
        ours_err = plain_err = None
        single_err = np.empty(single_count)
        ikpy_err = np.empty(k)
        ikpy_best = 0.0
        for r in range(rounds):
            # A batch takes tens of milliseconds: several tries per round
            # catch a quiet moment of the shared machine.
            for _ in range(4):
                e, dt = solve_ours(fig, n, tips, **OURS)
                ours_best, ours_err = max(ours_best, len(tips) / dt), e
                e, dt = solve_ours(fig, n, tips, **OURS_PLAIN)
                plain_best, plain_err = max(plain_best, len(tips) / dt), e
            idx = singles[r]
            e, dt = solve_ours_one_by_one(fig, n, tips[idx], **OURS)
            single_err[idx] = e
            single_best = max(single_best, len(idx) / dt)
            idx = chunks[r]
            e, dt = solve_ikpy(chain, n, tips[idx])
            ikpy_err[idx] = e
            ikpy_best = max(ikpy_best, len(idx) / dt)
        single_rate = single_best
        res = {
            "liganimate": summary(ours_err, ours_best),
            "liganimate_on_ikpy_targets": summary(ours_err[:k], ours_best),
            "liganimate_no_restarts": summary(plain_err, plain_best),
            "liganimate_one_per_call": summary(single_err, single_rate),
            "ikpy": summary(ikpy_err, ikpy_best),
        }
        res["speed_ratio"] = round(ours_best / ikpy_best, 1)
        res["speed_ratio_one_per_call"] = round(single_rate / ikpy_best, 1)
        res["success_ratio"] = round(
            res["liganimate_on_ikpy_targets"]["success"] / max(res["ikpy"]["success"], 1e-9), 4
        )
        # One per call against ikpy on the targets both solved (the first min(k, single_count)).
        both = min(k, single_count)
        res["success_ratio_one_per_call"] = round(
            float(np.mean(single_err[:both] < SUCCESS)) / max(float(np.mean(ikpy_err[:both] < SUCCESS)), 1e-9), 4
        )
        results[n] = res
        print(f"\n{n} joints")
        for name in ("liganimate", "liganimate_no_restarts", "liganimate_one_per_call", "ikpy"):
            s = res[name]
            print(
                f"  {name:26s} success {100 * s['success']:6.2f}%  median error {s['median_error']:9.3g}  "
                f"{s['solves_per_s']:10.1f} solves/s  ({s['targets']} targets)"
            )
        print(
            f"  on ikpy's {k} targets: liganimate {100 * res['liganimate_on_ikpy_targets']['success']:.2f}% "
            f"vs ikpy {100 * res['ikpy']['success']:.2f}%; speed ratio {res['speed_ratio']:.1f}x batched, "
            f"{res['speed_ratio_one_per_call']:.1f}x one per call (success ratio one per call "
            f"{res['success_ratio_one_per_call']:.3f})"
        )

    goals = {
        "success_at_least_ikpy": all(results[n]["success_ratio"] >= 1.0 for n in CHAINS),
        "ten_times_ikpy_speed": all(results[n]["speed_ratio"] >= 10 for n in CHAINS),
        "batched_6_joint_20000_per_s": results[6]["liganimate"]["solves_per_s"] >= 20000,
        # One pose per call, as a script's STARTREACH solves: the same goal.
        "success_at_least_ikpy_one_per_call": all(results[n]["success_ratio_one_per_call"] >= 1.0 for n in CHAINS),
        "ten_times_ikpy_speed_one_per_call": all(results[n]["speed_ratio_one_per_call"] >= 10 for n in CHAINS),
    }
    print("\ngoals: " + ", ".join(f"{k} {'yes' if v else 'NO'}" for k, v in goals.items()))
    print(
        json.dumps(
            {
                "chains": {str(n): results[n] for n in CHAINS},
                "goals": goals,
                "cores": os.cpu_count(),
                "quick": args.quick,
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
