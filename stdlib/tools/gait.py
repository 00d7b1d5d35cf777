"""Regenerate the legs and the ROOT track of the humanoid's WALK and RUN (stdlib/humanoid.lig).

The planted foot must not slide (issue 9: at most 1 mm a frame). So the
gaits are designed in the world, not in joint space:

* the pelvis (TOP, the figure's main link) travels at a constant speed along
  +X, with a small vertical bob: that is the motion's ROOT track, one
  keyframe a frame;
* each ankle follows a path: during its stance it stays where it touched
  down, the sole flat on the ground; during its swing it goes forward on a
  cubic whose end velocities match the stance (zero in the world at lift-off
  and touchdown), lifted by a sine, and further wherever the foot, tipped by
  its ankle's extremes, would bring its toe or heel nearer the ground than
  ``CLEARANCE`` (1.2 cm): the toe clears the floor at every swing frame;
* the hip, knee and ankle flexions (joints 31-33, 41-43) come from exact
  two-link inverse kinematics of that path, frame by frame, the foot kept
  flat through the stance.

The legs' keyframes, at every frame, and the ROOT track replace the ones in
stdlib/humanoid.lig between ``STARTMOTION WALK``/``RUN`` and their arm
joints (the arms and the spine keep their hand-made ACCDCC curves).  Run
``python stdlib/tools/gait.py`` from the repository, then
``python benchmarks/foot_skate.py`` to measure the result.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

UNIT = 0.009  # metres per thesis unit (HUMANOID :- HUMANOID <SCALE MODEL 0.009>)
THIGH, SHIN = 45.0 * UNIT, 55.0 * UNIT
ANKLE_HEIGHT = 8.0 * UNIT  # the foot box reaches 8 units below the ankle
STAND = 0.972  # pelvis above the soles in the neutral pose
# The swinging foot's lowest corner above the ground at every swing frame (m): real gait clears
# the floor by about 1-2 cm at mid-swing; benchmarks/foot_skate.py checks at least 1 cm.
CLEARANCE = 0.012

# name: (frames per cycle, stance frames of each foot, metres per cycle, stance window ahead
#        of the hip (m), hip above the ankles (m): mean, bob amplitude, frame of the bob's crest,
#        swing lift (m)).  Found by a search for the flat planted foot within its 20 degrees and
#        the leg within reach at every planted frame.
GAITS = {
    "WALK": (24, 12, 1.2, 0.02, 0.855, -0.025, 2.5, 0.07),
    "RUN": (16, 5, 2.2, 0.06, 0.845, 0.03, 3.5, 0.20),
}


def _swing(u: np.ndarray, a: float, b: float, slope: float) -> np.ndarray:
    """Cubic Hermite from a to b over u in [0, 1] with both end slopes ``slope`` (per unit u)."""
    h00 = 2 * u**3 - 3 * u**2 + 1
    h10 = u**3 - 2 * u**2 + u
    h01 = -2 * u**3 + 3 * u**2
    h11 = u**3 - u**2
    return h00 * a + h10 * slope + h01 * b + h11 * slope


def _forward(n: int, stance: int, travel: float, ahead: float):
    """The right ankle's forward distance from the hip at frames 0..n, and whether it is planted."""
    v = travel / n
    t = np.arange(n + 1, dtype=float)
    sweep = v * (stance - 1)
    planted = t <= stance - 1
    x = np.empty(n + 1)
    planted_end = planted.copy()
    planted_end[-1] = True  # frame n is frame 0 of the next cycle
    # Stance: the ankle stays put in the world while the hip moves on at v.
    x[planted] = ahead + sweep / 2 - v * t[planted]
    # Swing: forward again, leaving and arriving with the world velocity 0.
    frames = n - (stance - 1)
    u = (t[~planted] - (stance - 1)) / frames
    x[~planted] = _swing(u, ahead - sweep / 2, ahead + sweep / 2, -v * frames)
    return x, planted_end


def ankle_path(n: int, stance: int, travel: float, ahead: float, mean: float, bob: float, crest: float, lift: float):
    """The right ankle relative to the hip, and the pelvis' vertical offset, at frames 0..n.

    The hip rides ``mean + bob cos(2 pi (t - crest) / (n / 2))`` above the
    ankles' height, a smooth bob twice a cycle.

    Returns
    -------
    rel : ndarray, shape (n + 1, 2)
        (forward, up) of the ankle from the hip joint, metres.
    pelvis_y : ndarray, shape (n + 1,)
        The ROOT track's height: the pelvis' rise over the standing pose.
    planted : ndarray of bool, shape (n + 1,)
    """
    t = np.arange(n + 1, dtype=float)
    x, planted = _forward(n, stance, travel, ahead)
    height = mean + bob * np.cos(2 * np.pi * (t - crest) / (n / 2))
    pelvis_y = height + ANKLE_HEIGHT - STAND
    y = -height.copy()
    frames = n - (stance - 1)
    u = (t[~planted] - (stance - 1)) / frames
    y[~planted] += lift * np.sin(np.pi * u)
    return np.column_stack([x, y]), pelvis_y, planted


def leg_angles(rel: np.ndarray, planted: np.ndarray) -> np.ndarray:
    """Hip, knee and ankle flexions (degrees, LIG's Z axis) reaching ``rel`` (T, 2).

    Two-link inverse kinematics in the sagittal plane, the knee bending
    backwards; the foot flat where planted, else within its extremes.
    """
    d = np.linalg.norm(rel, axis=1)
    # A swinging foot that the path takes out of reach is pulled in towards the hip.
    far = ~planted & (d > 0.995 * (THIGH + SHIN))
    rel = np.where(far[:, None], rel * (0.995 * (THIGH + SHIN) / np.maximum(d, 1e-12))[:, None], rel)
    d = np.linalg.norm(rel, axis=1)
    if (d > THIGH + SHIN).any():
        raise SystemExit(f"the ankle path is out of reach: {d.max():.4f} > {THIGH + SHIN:.4f} m")
    phi = np.arctan2(rel[:, 0], -rel[:, 1])  # from straight down, forward positive
    alpha = np.arccos(np.clip((THIGH**2 + d**2 - SHIN**2) / (2 * THIGH * d), -1, 1))
    knee = np.pi - np.arccos(np.clip((THIGH**2 + SHIN**2 - d**2) / (2 * THIGH * SHIN), -1, 1))
    hip = np.degrees(phi + alpha)
    knee = -np.degrees(knee)
    foot = -(hip + knee)  # flat
    # A swinging foot is kept as flat as its extremes allow, so its toes clear the ground.
    foot = np.where(planted, foot, np.clip(foot, -20.0, 20.0))
    if (np.abs(foot[planted]) > 20.0).any() or (knee < -160).any() or (hip < -20).any():
        raise SystemExit(f"a planted foot needs {np.abs(foot[planted]).max():.2f} degrees; its extremes are 20")
    return np.column_stack([hip, knee, foot])


def _sole_drop(pitch: np.ndarray) -> np.ndarray:
    """How far (m) the foot box's lowest corner is below the ankle, the foot pitched by ``pitch`` degrees."""
    p = np.radians(pitch)[:, None]
    x = np.array([-6.0, 30.0])[None, :]
    return -(x * np.sin(p) - 8.0 * np.cos(p)).min(axis=1) * UNIT


def gait(name: str):
    """(right leg angles (n+1, 3), left leg angles (n+1, 3), root (n+1, 3)) of one gait."""
    rel, pelvis_y, planted = ankle_path(*GAITS[name])
    n = GAITS[name][0]
    travel = GAITS[name][2]
    right = leg_angles(rel, planted)
    # A swinging foot that cannot stay flat (its extremes) tips its toes or heel down: lift its
    # ankle until that corner clears the ground by CLEARANCE at every swing frame, the first
    # after lift-off included, so the toe never skims the floor.  Lifting the ankle bends the
    # knee and tips the foot further, so this repeats until the angles settle.
    for _ in range(200):
        clearance = (rel[:, 1] + (STAND + pelvis_y)) - _sole_drop(right.sum(axis=1)) - CLEARANCE
        need = np.where(planted, 0.0, np.maximum(0.0, -clearance))
        if need.max() < 1e-6:
            break
        rel = rel + np.column_stack([np.zeros(len(need)), need])
        right = leg_angles(rel, planted)
    else:
        raise SystemExit(f"{name}: the swinging foot cannot be lifted {CLEARANCE * 1000:.0f} mm clear of the ground")
    half = n // 2
    left = np.vstack([right[half:-1], right[: half + 1]])  # half a cycle later, the same curve
    root = np.column_stack([np.arange(n + 1) * travel / n, pelvis_y, np.zeros(n + 1)])
    return right, left, root


def _vec(v) -> str:
    return ", ".join(f"{x:.4f}" for x in v)


def block(name: str) -> str:
    """The legs and the ROOT entry of a STARTMOTION block, as LIG text."""
    right, left, root = gait(name)
    lines = []
    for base, angles in ((31, right), (41, left)):
        for k in range(3):
            axis = np.zeros((len(angles), 3))
            axis[:, 2] = angles[:, k]
            lines.append(f"        JOINT {base + k} POSITION {_vec(axis[0])}")
            lines += [f"          FRAME {f} POSITION {_vec(axis[f])}" for f in range(1, len(axis))]
    lines.append(f"        ROOT POSITION {_vec(root[0])}")
    lines += [f"          FRAME {f} POSITION {_vec(root[f])}" for f in range(1, len(root))]
    return "\n".join(lines) + "\n"


def main() -> None:
    path = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parents[1] / "humanoid.lig")
    text = path.read_text()
    for name in GAITS:
        # The legs (and any ROOT) sit between STARTMOTION and the first arm joint, 11.
        pattern = re.compile(rf"(      STARTMOTION {name}\n)(.*?)(        JOINT 11 )", re.S)
        text, n = pattern.subn(lambda m, name=name: m.group(1) + block(name) + m.group(3), text)
        if n != 1:
            raise SystemExit(f"STARTMOTION {name} not found in {path}")
    path.write_text(text)
    print(f"rewrote WALK and RUN in {path}")


if __name__ == "__main__":
    main()
