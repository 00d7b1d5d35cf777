"""Joint-space trajectories: each drawn model's joint positions and velocities, tick by tick, for robots.

One trajectory per drawn model of every scene (as BVH export writes one file
per model).  Its joints are the URDF joints URDF export writes for the model
(:func:`._urdf_write.joint_columns`: a LIG joint's moving axes, named by the
name table's URDF joint names where the model has them), so a trajectory and
the URDF of the same program line up.  Positions are in radians (turns) and
the model's units (slides: metres for an imported robot), velocities in the
same per second, from the interpolation's own derivatives (not differences),
at the export's ``fps`` ticks per second; a joint held by its extremes has
velocity 0.

CSV: a header ``time,<joint>,...,<joint>.velocity,...`` then one row per
tick.  JSON: ``{"fps", "models": [{"scene", "model", "joints", "time",
"position", "velocity"}]}`` with the rows as lists.
"""

from __future__ import annotations

import json
import math
import os

import numpy as np

from liganimate.runtime.errors import LigError

from ._urdf_write import joint_columns

__all__ = ["trajectories", "trajectory_csv_files", "trajectory_json"]


def trajectories(scenes, fps: float) -> list:
    """Every drawn model's trajectory: ``[(scene id, model name, joints, time, position, velocity)]``.

    ``position`` and ``velocity`` have shape ``(T, n)`` for the ``n`` joints.

    Raises
    ------
    LigError
        When no scene draws a model.
    """
    out = []
    for take in scenes:
        for m in take.models:
            cols = joint_columns(m.figure)
            fig = m.figure
            vel = m.velocities()
            pos = np.zeros((len(m.ticks), len(cols)))
            speed = np.zeros_like(pos)
            for c, (_, k, axis, slide) in enumerate(cols):
                if slide:
                    gain = fig.joints[k].slide_scale
                else:
                    gain = math.pi / 180.0
                pos[:, c] = m.angles[:, k, axis] * gain
                speed[:, c] = vel[:, k, axis] * gain * fps
            time = m.ticks.astype(np.float64) / fps
            out.append((take.id, m.name, [c[0] for c in cols], time, pos, speed))
    if not out:
        raise LigError(
            "the program draws no animated model, so there is no trajectory to write.",
            "a model is drawn while an ANIMATE covers it in a shot scene",
        )
    return out


def _num(x: float) -> str:
    return repr(float(x) + 0.0)


def _csv_field(name: str) -> str:
    return '"' + name.replace('"', '""') + '"' if any(c in name for c in ',"\n\r') else name


def _csv(joints, time, pos, speed) -> bytes:
    head = ["time"] + [_csv_field(j) for j in joints] + [_csv_field(j + ".velocity") for j in joints]
    lines = [",".join(head)]
    for t, p, v in zip(time, pos, speed):
        lines.append(",".join([_num(t)] + [_num(x) for x in p] + [_num(x) for x in v]))
    return ("\n".join(lines) + "\n").encode("utf-8")


def trajectory_csv_files(scenes, path: str, fps: float) -> list:
    """One CSV per drawn model: the only one to ``path``, else ``<stem>-scene<ID>-<MODEL>.csv``."""
    trajs = trajectories(scenes, fps)
    if len(trajs) == 1:
        return [(path, _csv(*trajs[0][2:]))]
    stem, ext = os.path.splitext(path)
    out = []
    seen: dict = {}
    for scene, name, *rest in trajs:
        seen[(scene, name)] = seen.get((scene, name), 0) + 1
        n = seen[(scene, name)]
        out.append((f"{stem}-scene{scene}-{name}{'-' + str(n) if n > 1 else ''}{ext or '.csv'}", _csv(*rest)))
    return out


def trajectory_json(scenes, fps: float) -> bytes:
    """Every drawn model's trajectory in one JSON document."""
    models = [
        {
            "scene": scene,
            "model": name,
            "joints": joints,
            "time": time.tolist(),
            "position": pos.tolist(),
            "velocity": speed.tolist(),
        }
        for scene, name, joints, time, pos, speed in trajectories(scenes, fps)
    ]
    return (json.dumps({"fps": fps, "units": "radians and model units (metres)", "models": models}) + "\n").encode()
