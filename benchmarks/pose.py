"""Pose benchmark: joint-frames per second for the Appendix A humanoid.

The model is HUMAN from ``examples/appendix_a.lig`` (11 links, 10 joints,
rooted at a FOOT as the program leaves it) and the motion is its SQUAT.
Poses are evaluated at many (fractional) frames spread over the motion.
Reported, side by side in one run:

* liganimate's batched evaluation, what ``liganimate run`` does: the motion
  sampled at all frames at once, every angle clamped to its joint's
  extremes, and the stacked 4x4 link transforms built over all frames
  (one matrix product per depth level of the tree);
* what a user would otherwise write: a per-frame Python loop that, for each
  frame and each joint, interpolates the joint's angles between its
  keyframes, clamps them, builds the joint's 4x4 matrix and multiplies it
  down the tree.

Both give the same transforms (checked, to 1e-9).  A joint-frame is one
joint posed at one frame.  Every figure is the best of several interleaved
rounds (the machine is shared: other load only slows a round down).  The
last line printed is one JSON object with the figures.

Usage: ``python benchmarks/pose.py [--quick]``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

from liganimate.compiler import load_program
from liganimate.runtime.figure.pose import joint_angles, world_transforms
from liganimate.runtime.host import Posed

HERE = os.path.dirname(os.path.abspath(__file__))
PROGRAM = os.path.join(HERE, "..", "examples", "appendix_a.lig")

# The ease curves of docs/semantics-motion.md for the fixed-shape methods,
# written for one number at a time as a loop would use them.
EASE = {
    "ACCELERATE": lambda u: u * u,
    "DECELERATE": lambda u: 1.0 - (1.0 - u) ** 2,
    "ACCDCC": lambda u: 2.0 * u * u if u < 0.5 else 1.0 - 2.0 * (1.0 - u) ** 2,
}


def load_human():
    """HUMAN (a Figure) and SQUAT (a Motion) as the Appendix A program leaves them."""
    program, _ = load_program(PROGRAM)
    rt = program.execute("check")
    human = rt.variables["HUMAN"]
    if isinstance(human, Posed):
        human = human.figure
    return human, rt._motion(rt.variables["SQUAT"], 0)


def batched(fig, motion, frames: np.ndarray) -> np.ndarray:
    """liganimate: sample, clamp and build the stacked transforms (T, links, 4, 4)."""
    angles = joint_angles(fig, motion, frames)
    return world_transforms(fig, angles, np.broadcast_to(np.eye(4), (len(frames), 4, 4)))


def loop_setup(fig, motion):
    """What the loop needs, prepared once: tree order and each joint's keyframes."""
    order = []  # (joint index, parent link, child link, reversed), parents before children
    for level in fig.traversal:
        order += list(
            zip(level.joints.tolist(), level.parents.tolist(), level.children.tolist(), level.reversed.tolist())
        )
    loc1, loc2 = fig.locations
    tracks = {}
    for k, jid in enumerate(fig.joint_ids):
        if jid in motion.joints:
            start, keys = motion.keyframes(jid)
            for key in keys:
                if key.method not in EASE:
                    raise SystemExit(f"the loop baseline has no ease curve for {key.method}")
            tracks[k] = (
                [float(a) for a in start],
                [(float(key.frame), [float(a) for a in key.position], key.method) for key in keys],
            )
    return order, np.asarray(loc1), np.asarray(loc2), fig.extremes.tolist(), tracks, fig.link_scales.tolist()


def loop_interpolate(track, t: float) -> list:
    """A joint's angles at frame t, keyframe by keyframe."""
    if track is None:
        return [0.0, 0.0, 0.0]
    start, keys = track
    prev_f, prev_v = 0.0, start
    for f, v, method in keys:
        if t < f:
            u = (t - prev_f) / (f - prev_f)
            e = EASE[method](u)
            return [a + (b - a) * e for a, b in zip(prev_v, v)]
        prev_f, prev_v = f, v
    return list(prev_v)


def loop(setup, n_links: int, frames) -> np.ndarray:
    """The per-frame loop a user would write: per frame, per joint, interpolate, clamp, build, multiply."""
    order, loc1, loc2, extremes, tracks, scales = setup
    out = np.empty((len(frames), n_links, 4, 4))
    for i, t in enumerate(frames):
        X = [None] * n_links
        X[order[0][1]] = np.eye(4)
        for k, parent, child, rev in order:
            angles = loop_interpolate(tracks.get(k), float(t))
            ax, ay, az = (min(max(a, lo), hi) for a, (lo, hi) in zip(angles, extremes[k]))
            cx, sx = math.cos(math.radians(ax)), math.sin(math.radians(ax))
            cy, sy = math.cos(math.radians(ay)), math.sin(math.radians(ay))
            cz, sz = math.cos(math.radians(az)), math.sin(math.radians(az))
            Rx = np.array([[1, 0, 0, 0], [0, cx, -sx, 0], [0, sx, cx, 0], [0, 0, 0, 1.0]])
            Ry = np.array([[cy, 0, sy, 0], [0, 1, 0, 0], [-sy, 0, cy, 0], [0, 0, 0, 1.0]])
            Rz = np.array([[cz, -sz, 0, 0], [sz, cz, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
            T1, T2 = np.eye(4), np.eye(4)
            if rev:
                # Walked from the secondary: the inverse, Trans(L2) Rx^T Ry^T Rz^T Trans(-L1).
                T1[:3, 3] = loc2[k]
                T2[:3, 3] = -loc1[k]
                A = T1 @ Rx.T @ Ry.T @ Rz.T @ T2
            else:
                T1[:3, 3] = loc1[k]
                T2[:3, 3] = -loc2[k]
                A = T1 @ Rz @ Ry @ Rx @ T2
            X[child] = X[parent] @ A
        for link in range(n_links):
            out[i, link] = X[link]
            out[i, link, :3, :3] *= scales[link]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a short run (under a minute)")
    args = ap.parse_args(argv)
    # 20,000 frames a batch: about what a minute of a 24 fps scene with a
    # dozen models evaluates, and small enough for the transforms (28 MB)
    # not to be dominated by the kernel handing out fresh pages.
    n_frames, n_loop, rounds = (20_000, 500, 5) if args.quick else (20_000, 2_000, 7)

    fig, motion = load_human()
    J, L = fig.n_joints, fig.n_links
    frames = np.linspace(0.0, motion.length, n_frames)
    loop_frames = frames[:: n_frames // n_loop]
    setup = loop_setup(fig, motion)
    print(
        f"model: HUMAN of appendix_a.lig, {L} links, {J} joints, main link {fig.links[fig.main].name}; "
        f"motion SQUAT, {motion.length:g} frames"
    )

    # Same answer?
    ref = batched(fig, motion, loop_frames)
    got = loop(setup, L, loop_frames)
    err = float(np.abs(ref - got).max())
    print(f"loop vs batched: largest difference {err:.2e}")
    assert err < 1e-9, err

    best = {"batched": 0.0, "loop": 0.0}
    print(
        f"timing: batched over {n_frames} frames a call, loop over {len(loop_frames)} frames "
        f"100 at a time, best of {rounds} rounds, the two interleaved"
    )
    # Each timed piece takes a few tens of milliseconds: a batched call over
    # all the frames, or the loop over 100 frames, so that both have about
    # as many chances to meet a quiet moment of the machine.
    pieces = [loop_frames[i : i + 100] for i in range(0, len(loop_frames), 100)]
    for _ in range(rounds):
        for piece in pieces:
            t0 = time.perf_counter()
            loop(setup, L, piece)
            best["loop"] = max(best["loop"], len(piece) * J / (time.perf_counter() - t0))
            t0 = time.perf_counter()
            batched(fig, motion, frames)
            best["batched"] = max(best["batched"], n_frames * J / (time.perf_counter() - t0))
    ratio = best["batched"] / best["loop"]
    print(f"liganimate batched:      {best['batched']:14,.0f} joint-frames/s")
    print(f"per-frame Python loop:   {best['loop']:14,.0f} joint-frames/s")
    print(f"ratio: {ratio:.0f}x (target 100x: {'met' if ratio >= 100 else 'NOT met'})")
    print(
        json.dumps(
            {
                "joints": J,
                "links": L,
                "frames_batched": n_frames,
                "frames_loop": len(loop_frames),
                "batched_joint_frames_per_s": round(best["batched"]),
                "loop_joint_frames_per_s": round(best["loop"]),
                "ratio": round(ratio, 1),
                "max_difference": err,
                "quick": args.quick,
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
