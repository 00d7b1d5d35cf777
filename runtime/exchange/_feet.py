"""Planted feet of a retargeted motion: each contact held at one point by two-link leg IK, frame by frame.

During a contact the figure's ankle (its foot link's joint) is held at the
mean of where the retargeted angles put it.  The knee turns about its own
axis (the axis of its joint with the widest extremes) to make the hip-ankle
distance right, the thigh turns by the smallest rotation that points the
leg at the ankle, and the foot keeps its retargeted world rotation; each
joint is then clamped into its extremes.  Where the ankle is out of reach
the pelvis comes down (smoothly) until it is not.  All of it is vectorized
over frames.
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.figure.kinematics import matrix_from_euler_zyx

from ._rigging import fit_angles, rotation_between, runs

__all__ = ["keep_feet", "leg_chain_positions"]

REACH = 0.995  # of the straight leg's length
#: A held ankle is within this fraction of the leg's length of its contact point (0.45 mm
#: for HUMANOID's 0.9 m leg), so a planted foot moves at most twice that between two frames.
HOLD = 0.0005


def _world(tgt, angles: np.ndarray, path: np.ndarray, main: np.ndarray | None = None):
    """World rotations (F, n, 3, 3) and joint points (F, n, 3) of every link, the main link at ``path`` turned by ``main``."""
    F = len(angles)
    n = tgt.fig.n_links
    W = np.empty((F, n, 3, 3))
    O = np.empty((F, n, 3))
    P = np.empty((F, n, 3))
    for i in tgt.order:
        p, k = tgt.parent[i], tgt.joint[i]
        if p < 0:
            W[:, i], O[:, i], P[:, i] = np.eye(3) if main is None else main, path, path
            continue
        P[:, i] = O[:, p] + W[:, p] @ tgt.loc1[k]
        W[:, i] = W[:, p] @ matrix_from_euler_zyx(angles[:, k])
        O[:, i] = P[:, i] - W[:, i] @ tgt.loc2[k]
    return W, P


def leg_chain_positions(tgt, angles: np.ndarray, path: np.ndarray, link: int | None, main=None) -> np.ndarray:
    """Where link ``link``'s joint is at every frame (F, 3), in the model's frame (``link`` None: every link's, (F, n, 3)).

    ``main`` (F, 3, 3): the main link's world rotation (None: it does not turn).
    """
    points = _world(tgt, angles, path, main)[1]
    return points if link is None else points[:, link]


def _knee_axis(tgt, k: int) -> int:
    ext = tgt.extremes[k]
    return int(np.argmax(ext[:, 1] - ext[:, 0]))


def _axis_rotation(axis: int, theta: np.ndarray) -> np.ndarray:
    a = np.zeros((len(theta), 3))
    a[:, axis] = theta
    return matrix_from_euler_zyx(a)


def _knee_angle(a, b, axis: int, d: np.ndarray, current: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """The knee angles (degrees) about ``axis`` that make ``|a + R(theta) b| = d``, nearest ``current``."""
    e = np.zeros(3)
    e[axis] = 1.0
    b_par = (b @ e) * e
    b_perp = b - b_par
    P, Q = a @ b_perp, a @ np.cross(e, b)
    c = (d**2 - a @ a - b @ b) / 2 - a @ b_par
    r = max(np.hypot(P, Q), 1e-12)
    base = np.arctan2(Q, P)
    spread = np.arccos(np.clip(c / r, -1.0, 1.0))
    options = np.degrees(np.stack([base + spread, base - spread], axis=1))
    options = (options - current[:, None] + 180.0) % 360.0 - 180.0 + current[:, None]
    inside = (options >= lo - 1e-6) & (options <= hi + 1e-6)
    cost = np.abs(options - current[:, None]) + np.where(inside, 0.0, 1e6)
    return np.clip(options[np.arange(len(d)), np.argmin(cost, axis=1)], lo, hi)


def _anchors(ankle: np.ndarray, planted: np.ndarray) -> tuple:
    """Per frame, where the ankle should be (the mean of its contact), and which frames have one."""
    goal = ankle.copy()
    for a, b in runs(planted):
        goal[a:b] = ankle[a:b].mean(axis=0)
    return goal, planted


def _lower_pelvis(P_hip: np.ndarray, goal: np.ndarray, held: np.ndarray, reach: float) -> np.ndarray:
    """How far (F,) the pelvis must come down for the held ankle to be within reach, smoothed."""
    D = goal - P_hip
    dist = np.linalg.norm(D, axis=1)
    need = held & (dist > REACH * reach)
    drop = np.zeros(len(D))
    if need.any():
        Dy = D[need, 1]
        disc = np.maximum(Dy**2 - (dist[need] ** 2 - (REACH * reach) ** 2), 0.0)
        drop[need] = np.maximum(-Dy - np.sqrt(disc), 0.0)
        w = 5
        padded = np.pad(drop, w, mode="edge")
        grown = np.max(np.lib.stride_tricks.sliding_window_view(padded, 2 * w + 1), axis=1)
        drop = np.convolve(np.pad(grown, w, mode="edge"), np.ones(2 * w + 1) / (2 * w + 1), mode="valid")
    return drop


def _ankle(x, W_parent, hip, a, b, axis):
    """Where the ankle is for hip angles x[:, :3] and knee angle x[:, 3] about ``axis``."""
    knee = _axis_rotation(axis, x[:, 3])
    leg = a + np.einsum("fij,j->fi", knee, b)
    return hip + np.einsum("fij,fj->fi", W_parent @ matrix_from_euler_zyx(x[:, :3]), leg)


def _damped_step(J: np.ndarray, r: np.ndarray, scale: float) -> np.ndarray:
    damping = (1e-4 * (scale * np.pi / 180) ** 2) * np.eye(J.shape[2])
    return np.linalg.solve(np.swapaxes(J, 1, 2) @ J + damping, -np.einsum("fji,fj->fi", J, r)[..., None])[..., 0]


def _solve_leg(x, W_parent, hip, goal, a, b, axis, hip_ext, knee_ext, steps: int = 20) -> np.ndarray:
    """Hip (3) and knee (1) angles, within their extremes, putting the ankle at ``goal``: bounded damped Gauss-Newton."""
    lo = np.concatenate([hip_ext[:, 0], [knee_ext[0]]])
    hi = np.concatenate([hip_ext[:, 1], [knee_ext[1]]])
    free = hi - lo >= 360.0
    lo, hi = np.where(free, -np.inf, lo), np.where(free, np.inf, hi)
    eps = 1e-3
    for _ in range(steps):
        r = _ankle(x, W_parent, hip, a, b, axis) - goal
        if np.abs(r).max() < 1e-7:
            break
        J = np.empty((len(x), 3, 4))
        for c in range(4):
            dx = x.copy()
            dx[:, c] += eps
            J[:, :, c] = (_ankle(dx, W_parent, hip, a, b, axis) - goal - r) / eps
        step = _damped_step(J, r, float(np.linalg.norm(a) + np.linalg.norm(b)))
        # An angle at its extreme that the step pushes further out is held, and the others re-solved without it.
        held = ((x <= lo + 1e-9) & (step < 0)) | ((x >= hi - 1e-9) & (step > 0))
        if held.any():
            step = _damped_step(J * ~held[:, None, :], r, float(np.linalg.norm(a) + np.linalg.norm(b)))
            step[held] = 0.0
        x = np.clip(x + np.clip(step, -20.0, 20.0), lo, hi)
    return x


def keep_feet(tgt, angles: np.ndarray, path: np.ndarray, desired: dict, planted: dict, jmap, main=None) -> list:
    """Hold each planted ankle (changes ``angles`` and ``path`` in place); returns notes.

    ``main`` (F, 3, 3) is the main link's world rotation (its ROOT ORIENTATION); None: it does not turn.
    """
    W, P = _world(tgt, angles, path, main)
    goals = {}
    drop = np.zeros(len(angles))
    for side, mask in planted.items():
        up, low, foot = jmap.feet[side][1]
        goals[side] = _anchors(P[:, foot], mask)
        reach = float(np.linalg.norm(tgt.pivot[low] - tgt.pivot[up]) + np.linalg.norm(tgt.pivot[foot] - tgt.pivot[low]))
        drop = np.maximum(drop, _lower_pelvis(P[:, up], goals[side][0], mask, reach))
    path[:, 1] -= drop
    W, P = _world(tgt, angles, path, main)
    released = {}
    for side, (goal, held) in goals.items():
        up, low, foot = jmap.feet[side][1]
        f = np.flatnonzero(held)
        if not len(f):
            continue
        k_hip, k_knee, k_ankle = tgt.joint[up], tgt.joint[low], tgt.joint[foot]
        a = tgt.loc1[k_knee] - tgt.loc2[k_hip]
        b = tgt.loc1[k_ankle] - tgt.loc2[k_knee]
        axis = _knee_axis(tgt, k_knee)
        D = goal[f] - P[f, up]
        d = np.linalg.norm(D, axis=1)
        lo, hi = tgt.extremes[k_knee, axis]
        theta = _knee_angle(a, b, axis, d, angles[f, k_knee, axis], lo, hi)
        knee = np.zeros((len(f), 3))
        knee[:, axis] = theta
        angles[f, k_knee] = knee
        W_parent = W[f, tgt.parent[up]]
        v = a + _axis_rotation(axis, theta) @ b
        W_thigh = W_parent @ matrix_from_euler_zyx(angles[f, k_hip])
        fix = rotation_between(np.einsum("fij,fj->fi", W_thigh, v), D)
        angles[f, k_hip] = fit_angles(tgt.extremes[k_hip], np.swapaxes(W_parent, -1, -2) @ fix @ W_thigh)[0]
        # Within the extremes the closed form may miss; a few bounded Gauss-Newton steps finish it.
        x = np.column_stack([angles[f, k_hip], angles[f, k_knee, axis]])
        x = _solve_leg(x, W_parent, P[f, up], goal[f], a, b, axis, tgt.extremes[k_hip], (lo, hi))
        angles[f, k_hip] = x[:, :3]
        angles[f, k_knee, axis] = x[:, 3]
        # A contact the leg cannot hold within its extremes is let go at those frames, and counted.
        leg = np.linalg.norm(a) + np.linalg.norm(b)
        miss = np.linalg.norm(_ankle(x, W_parent, P[f, up], a, b, axis) - goal[f], axis=1) > HOLD * leg
        held[f[miss]] = False
        released[side] = int(miss.sum())
        W_shin = W_parent @ matrix_from_euler_zyx(angles[f, k_hip]) @ matrix_from_euler_zyx(angles[f, k_knee])
        want = desired[foot][f] if foot in desired else W[f, foot]
        angles[f, k_ankle] = fit_angles(tgt.extremes[k_ankle], np.swapaxes(W_shin, -1, -2) @ want)[0]
    notes = []
    if any(released.values()):
        notes.append(
            f"{sum(released.values())} contact frames (left {released.get('L', 0)}, right {released.get('R', 0)}) "
            f"could not be held within {HOLD:g} of the leg's length, the legs' extremes allowing no closer; "
            "the foot is let go there"
        )
    if drop.any():
        notes.append(
            f"the pelvis comes down by up to {drop.max():.3g} at {int((drop > 0).sum())} frames, "
            "where a planted foot was out of the leg's reach"
        )
    return notes
