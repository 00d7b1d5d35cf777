"""Pose benchmark: forward kinematics of the library HUMANOID against pinocchio, and a per-frame loop.

Two measurements, each side by side in one run, judged on CPU time (this
process's; wall time and the load average printed beside it, see
``_clock.py``), best of several interleaved rounds:

* **Forward kinematics of HUMANOID** (``LOAD 'humanoid'``: 20 links, 19
  joints, 30 axes that move) from joint angles to every link's transform,
  at random angles within the extremes, against **pinocchio** (``pin``, C++):
  the same model exported as URDF (``liganimate export --urdf``'s writer),
  read by ``pinocchio.buildModelFromXML``, and ``pinocchio.forwardKinematics``
  called once per frame from Python (what a Python user of pinocchio
  writes). liganimate is timed batched (``pose_transforms`` over 4,096
  frames a call, and over 32, the renderer's batch) and one frame a call.
  Both give the same transforms (checked, to 1e-12, on pinocchio's frame
  placements). Goals (issue 22): batched at most 2.0 us a frame, one frame
  at most 20 us.
* **Sampling a motion and posing** HUMAN of ``examples/appendix_a.lig``
  (11 links, 10 joints, rooted at a FOOT) over its SQUAT, batched (what
  ``liganimate run`` does: the motion sampled at all frames at once, every
  angle clamped, the stacked 4x4 link transforms built), against what a user
  would otherwise write: a per-frame Python loop that, per frame and per
  joint, interpolates between keyframes, clamps, builds the joint's 4x4
  matrix and multiplies it down the tree (an extra row; same transforms to
  1e-9). A joint-frame is one joint posed at one frame.

The last line printed is one JSON object with the figures.

Usage: ``python benchmarks/pose.py [--quick]``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile

import numpy as np
from _clock import Cost, best_of, load_text, measure

from liganimate.compiler import load_program
from liganimate.runtime.figure import kinematics as K
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


def load_humanoid(folder: str):
    """The library's HUMANOID (a Figure), from a one-line program that loads it."""
    path = os.path.join(folder, "load_humanoid.lig")
    with open(path, "w", encoding="utf-8") as f:
        f.write("LOAD 'humanoid'\n")
    program, _ = load_program(path)
    fig = program.execute("check").variables["HUMANOID"]
    return fig.figure if isinstance(fig, Posed) else fig


def pinocchio_model(fig, folder: str):
    """(model, data, q_of) for pinocchio, or None without it: the figure through our URDF writer.

    ``q_of(angles)`` turns one frame's angles (n_joints, 3) in degrees into
    pinocchio's configuration vector (radians; cos and sin for a continuous
    joint).
    """
    try:
        import pinocchio as pin
    except ImportError as exc:
        print(f"pinocchio: not measured ({exc}; pip install 'liganimate[bench]')")
        return None
    from liganimate.runtime.exchange._urdf_write import joint_columns, urdf_text

    text, _ = urdf_text(fig, "humanoid", os.path.join(folder, "meshes"), "meshes")
    model = pin.buildModelFromXML(text.decode("utf-8"))
    slots = []
    for name, k, axis, _slide in joint_columns(fig):
        joint = model.joints[model.getJointId(name)]
        slots.append((joint.idx_q, joint.nq, k, axis))

    def q_of(angles: np.ndarray) -> np.ndarray:
        q = np.zeros(model.nq)
        for iq, nq, k, axis in slots:
            v = math.radians(float(angles[k, axis]))
            if nq == 2:
                q[iq : iq + 2] = (math.cos(v), math.sin(v))
            else:
                q[iq] = v
        return q

    return pin, model, model.createData(), q_of


def pinocchio_difference(fig, pin_parts, angles: np.ndarray) -> float:
    """Largest difference between our link transforms and pinocchio's frame placements."""
    from liganimate.runtime.exchange._urdf_write import link_names

    pin, model, data, q_of = pin_parts
    ours = K.pose_transforms(fig, angles)
    ids = [model.getFrameId(name) for name in link_names(fig)]
    err = 0.0
    for t in range(len(angles)):
        pin.framesForwardKinematics(model, data, q_of(angles[t]))
        theirs = np.stack([data.oMf[i].homogeneous for i in ids])
        err = max(err, float(np.abs(ours[t] - theirs).max()))
    return err


def humanoid_fk(args, folder: str) -> dict:
    """Forward kinematics of HUMANOID: liganimate batched and one frame a call, pinocchio per call."""
    fig = load_humanoid(folder)
    lo, hi = fig.extremes[..., 0], fig.extremes[..., 1]
    dof = int(((hi - lo) > 0).sum())
    rng = np.random.default_rng(20261126)
    big, small, singles, rounds = 4096, 32, (200 if args.quick else 1000), (5 if args.quick else 9)
    angles = rng.uniform(lo, hi, size=(big, fig.n_joints, 3))
    print(
        f"\nHUMANOID (LOAD 'humanoid'): {fig.n_links} links, {fig.n_joints} joints, {dof} moving axes; "
        f"random angles within the extremes"
    )
    pin_parts = pinocchio_model(fig, folder)
    err = None
    if pin_parts is not None:
        err = pinocchio_difference(fig, pin_parts, angles[:50])
        print(f"liganimate vs pinocchio: largest difference {err:.2e}")
        assert err < 1e-12, err
        pin, model, data, q_of = pin_parts
        qs = [q_of(a) for a in angles[:singles]]
    costs: dict[str, list[Cost]] = {"batched": [], "batch32": [], "single": [], "pinocchio": []}
    for _ in range(rounds):
        costs["batched"].append(measure(lambda: K.pose_transforms(fig, angles)).per(big))
        costs["batch32"].append(
            measure(lambda: [K.pose_transforms(fig, angles[i : i + small]) for i in range(0, big, small)]).per(big)
        )
        costs["single"].append(
            measure(lambda: [K.pose_transforms(fig, angles[i : i + 1]) for i in range(singles)]).per(singles)
        )
        if pin_parts is not None:
            costs["pinocchio"].append(
                measure(lambda: [pin.forwardKinematics(model, data, q) for q in qs]).per(len(qs))  # noqa: B023
            )
    best = {k: best_of(v) for k, v in costs.items() if v}
    labels = {
        "batched": f"liganimate, {big:,} frames a call",
        "batch32": f"liganimate, {small} frames a call",
        "single": "liganimate, one frame a call",
        "pinocchio": "pinocchio forwardKinematics a call",
    }
    for k, c in best.items():
        print(f"  {labels[k]:38s} {c.cpu * 1e6:8.2f} us CPU a frame  (wall {c.wall * 1e6:8.2f} us, load {c.load:.1f})")
    goals = {
        "batched_at_most_2us": best["batched"].cpu <= 2.0e-6,
        "single_at_most_20us": best["single"].cpu <= 20e-6,
    }
    print("  goals: " + ", ".join(f"{k} {'met' if v else 'NOT met'}" for k, v in goals.items()))
    return {
        "links": fig.n_links,
        "joints": fig.n_joints,
        "moving_axes": dof,
        "us_per_frame": {k: c.json(1e6, 3) for k, c in best.items()},
        "pinocchio_difference": err,
        "goals": goals,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a short run (under a minute)")
    args = ap.parse_args(argv)
    print(load_text())
    with tempfile.TemporaryDirectory() as folder:
        fk = humanoid_fk(args, folder)
    sampled = appendix_a_rows(args)
    print(load_text())
    print(json.dumps({"humanoid_fk": fk, "appendix_a": sampled, "quick": args.quick}))
    return 0


def appendix_a_rows(args) -> dict:
    """HUMAN of Appendix A over its SQUAT: batched sampling and posing against the per-frame loop."""
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
        f"\nmodel: HUMAN of appendix_a.lig, {L} links, {J} joints, main link {fig.links[fig.main].name}; "
        f"motion SQUAT, {motion.length:g} frames"
    )

    # Same answer?
    ref = batched(fig, motion, loop_frames)
    got = loop(setup, L, loop_frames)
    err = float(np.abs(ref - got).max())
    print(f"loop vs batched: largest difference {err:.2e}")
    assert err < 1e-9, err

    print(
        f"timing: batched over {n_frames} frames a call, loop over {len(loop_frames)} frames "
        f"100 at a time, best of {rounds} rounds, the two interleaved"
    )
    # Each timed piece takes a few tens of milliseconds: a batched call over
    # all the frames, or the loop over 100 frames, so that both have about
    # as many chances to meet a quiet moment of the machine.
    pieces = [loop_frames[i : i + 100] for i in range(0, len(loop_frames), 100)]
    costs: dict[str, list[Cost]] = {"batched": [], "loop": []}
    for _ in range(rounds):
        for piece in pieces:
            costs["loop"].append(measure(lambda p=piece: loop(setup, L, p)).per(len(piece) * J))
            costs["batched"].append(measure(lambda: batched(fig, motion, frames)).per(n_frames * J))
    best = {k: best_of(v) for k, v in costs.items()}
    ratio = best["loop"].cpu / best["batched"].cpu
    for k, label in (("batched", "liganimate batched"), ("loop", "per-frame Python loop")):
        c = best[k]
        print(f"{label:24s} {1 / c.cpu:14,.0f} joint-frames/s CPU  (wall {1 / c.wall:14,.0f}, load {c.load:.1f})")
    print(f"ratio (CPU): {ratio:.0f}x (target 100x: {'met' if ratio >= 100 else 'NOT met'})")
    return {
        "joints": J,
        "links": L,
        "frames_batched": n_frames,
        "frames_loop": len(loop_frames),
        "batched_joint_frames_per_cpu_s": round(1 / best["batched"].cpu),
        "loop_joint_frames_per_cpu_s": round(1 / best["loop"].cpu),
        "ratio": round(ratio, 1),
        "max_difference": err,
    }


if __name__ == "__main__":
    sys.exit(main())
