"""What PRINT writes: one item (a text, a value, a model's tree or table, a motion's keyframes) as text.

The host resolves each item first (a model that has no value, a motion
whose keyframe edits do not fit, are reported at the PRINT statement);
these functions only format values that are sound.
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.errors import LigError


def model_tree(figure, label: str) -> str:
    """``PRINT model``: the model's tree of links and joints."""
    return figure.describe_tree(label)


def model_table(figure, label: str, motion=None, frame: float | None = None) -> str:
    """``PRINT $model``: the joint table, with angles, velocities and accelerations when it is ANIMATEd at ``frame``."""
    if motion is None:
        return f"MODEL {label}\n" + figure.describe_table()
    from liganimate.runtime.figure.pose import joint_angles

    angles, vel, acc = joint_angles(figure, motion, np.array([frame]), full=True)
    return f"MODEL {label} at frame {frame:g}\n" + figure.describe_table(angles[0], vel[0], acc[0])


def motion_listing(motion, label: str) -> str:
    """``PRINT motion``: its length and joints, then each joint's keyframes and the ROOT tracks' (at most 1,000 each)."""
    joints = ", ".join(map(str, motion.joints)) or "none"
    lines = [f"MOTION {label}: length {motion.length:g} frames, joints {joints}"]
    try:
        for j in motion.joints:
            start, kfs = motion.keyframes(j, limit=1000)
            lines.append(f"  JOINT {j} POSITION {_vector(start)}")
            for k in kfs:
                lines.append(f"    FRAME {k.frame:g} POSITION {_vector(k.position)} INTERPOLATE {k.method}")
        if motion.root is not None:
            start, kfs = motion.root_keyframes(limit=1000)
            lines.append(f"  ROOT POSITION {_vector(start)}")
            for k in kfs:
                lines.append(f"    FRAME {k.frame:g} POSITION {_vector(k.position)} INTERPOLATE {k.method}")
        if motion.turn is not None:
            start, kfs = motion.turn_keyframes(limit=1000)
            lines.append(f"  ROOT ORIENTATION POSITION {_vector(start)}")
            for k in kfs:
                lines.append(f"    FRAME {k.frame:g} POSITION {_vector(k.position)} INTERPOLATE {k.method}")
        if motion.morphs is not None:
            lines += _morph_lines(motion.morphs)
    except LigError:
        lines.append("  " + motion.describe())
    return "\n".join(lines)


def _morph_lines(morphs) -> list[str]:
    """A motion's SCALE tracks as keyframes, and its SHAPE tracks as each target's weight (1: that shape)."""
    from liganimate.runtime.motion import morph as mo

    lines = []
    for key in morphs.channels():
        start, kfs = mo.keyframes(morphs, key, 1000)
        if key[0] == mo.SCALE:
            lines.append(f"  SCALE LINK {key[1]} POSITION {_vector(start)}")
            values = [_vector(k.position) for k in kfs]
        else:
            n = morphs.targets[key[2]].triangles
            lines.append(f"  SHAPE LINK {key[1]}: weight of a shape of {n} triangles ({key[2][:8]}) {start[0]:g}")
            values = [f"{k.position[0]:g}" for k in kfs]
        lines += [f"    FRAME {k.frame:g} POSITION {v} INTERPOLATE {k.method}" for k, v in zip(kfs, values)]
    return lines


def value_line(kind: str, value, label: str) -> str:
    """``PRINT expression`` of a number, a vector or a graphical object (``kind``: its static type)."""
    if kind == "GRAPHICAL":
        return f"{label} = GRAPHICAL object of {len(value)} triangles"
    if isinstance(value, float):
        return f"{label} = {value:.6g}"
    return f"{label} = {value!r}"


def _vector(v) -> str:
    return ", ".join(f"{float(x):g}" for x in v)
