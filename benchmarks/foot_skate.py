"""Foot-skate benchmark: how far a planted foot slides, per library locomotion motion.

For each locomotion motion of the standard library (humanoid WALK and RUN),
the HUMANOID is posed at every frame of two cycles, exactly as
``liganimate run --poses`` poses it (clamped angles, world link
transforms), and carried by the motion's ROOT track as ANIMATE carries it
(a motion without one would be moved along +X at the body speed of the
scene-level translation the examples use, ``<TRANS (v * T, 0, 0)>``).
The other walk of the library, ROBOT_WALK, is the thesis' section 4.3 walk
*on the spot*, kept as the thesis wrote it: its robot has no feet and does
not travel, so it has no planted foot to measure. For each foot:

* *planted* frames are those whose ankle (the foot link's origin) is
  within 1 cm of its lowest height over the cycles, as issue 9 measured;
* the *slide* is the horizontal distance the foot's contact point (the
  lowest vertex) and its ankle (the foot link's origin) travel between two
  consecutive planted frames, in millimetres per frame.

And for each swinging foot (the frames that are not planted):

* the *swing clearance* is the height of the foot's lowest vertex above
  the floor (the lowest any foot vertex reaches), the least over every
  swing frame, the first after lift-off and the last before touchdown
  included; real gait clears the floor by about 1-2 cm at mid-swing;
* the *drag* is the largest horizontal distance a foot vertex travels from
  one frame to the next while it is within 5 mm of the floor at both
  (outside the planted frames, where that is the slide): a toe skimming
  the floor.

Reported per motion: the documented body speed, the worst contact and
ankle slide at that speed, the body speed that would minimise the slide
(the median backward speed of the planted foot), the worst slide there,
how many frames in a row a foot rests, the swing clearance and the drag.
The targets: a slide and a drag of at most 1 mm a frame (issue 9), a swing
clearance of at least 1 cm (issue 19). The last line printed is one JSON
object with the figures.

Usage: ``python benchmarks/foot_skate.py``.
"""

from __future__ import annotations

import json
import os
import tempfile

import numpy as np

from liganimate.compiler import load_program
from liganimate.runtime.figure.pose import (
    joint_angles,
    mesh_table,
    rooted_placements,
    world_transforms,
    world_triangles,
)
from liganimate.runtime.host import Posed

# Body speed (metres a frame) of the scene-level translation for each motion:
# WALK, 1.2 m per 24-frame cycle (examples/walk_and_wave.lig moves 0.05 a tick);
# RUN, "about 2.2 m" per 16-frame cycle (stdlib/humanoid.lig).
SPEEDS = {"WALK": 1.2 / 24.0, "RUN": 2.2 / 16.0}
PLANTED = 0.01  # metres above the ankle's lowest height
TOUCH = 0.005  # a foot vertex this near the floor touches it (the toe that skimmed it was 4-5 mm up)
CLEARANCE = 0.01  # the least a swinging foot should clear the floor by (metres)


def load():
    """The HUMANOID figure and its locomotion motions, as a program loading them sees them."""
    folder = tempfile.mkdtemp(prefix="foot-skate-")
    path = os.path.join(folder, "load.lig")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("      LOAD HUMANOID, WALK, RUN FROM 'humanoid'\n      END\n")
    program, _ = load_program(path)
    rt = program.execute("check")
    fig = rt.variables["HUMANOID"]
    fig = fig.figure if isinstance(fig, Posed) else fig
    return fig, {name: rt._motion(rt.variables[name], 0) for name in SPEEDS}


def feet(fig, motion, speed):
    """Per foot over two cycles, moved at ``speed``: (contact, next, ankle, vertices).

    ``contact[t]`` is the foot's lowest vertex at frame t and ``next[t]`` the
    same vertex one frame later (the last row repeats), so a slide is
    measured on one material point, not on whichever vertex is lowest;
    ``ankle`` (T, 3) is the foot link's origin and ``vertices`` (T, V, 3)
    all of the foot's vertices.
    """
    frames = np.arange(0.0, 2.0 * motion.length + 1.0)
    angles = joint_angles(fig, motion, frames)
    placement = np.repeat(np.asarray(fig.placement, dtype=np.float64)[None], len(frames), axis=0)
    placement[:, 0, 3] += speed * frames
    # The motion's ROOT track carries the figure as ANIMATE does (placement @ Trans(root)).
    X = world_transforms(fig, angles, rooted_placements(placement, motion, frames))
    table = mesh_table(fig)
    tris = world_triangles(table, X)  # (T, M, 3, 3)
    out = {}
    for name in ("R_FOOT", "L_FOOT"):
        link = fig.links_named(name)[0]
        verts = tris[:, table.link == link].reshape(len(frames), -1, 3)
        low = np.argmin(verts[:, :, 1], axis=1)
        rows = np.arange(len(frames))
        later = np.minimum(rows + 1, len(frames) - 1)
        out[name] = (verts[rows, low], verts[later, low], X[:, link, :3, 3], verts)
    return out


def slide(points, later, planted) -> float:
    """Largest horizontal step (mm/frame) from a planted frame to the next planted one (0 if none).

    ``later[t]`` is where the point of ``points[t]`` is at frame t + 1.
    """
    both = planted[1:] & planted[:-1]
    if not both.any():
        return 0.0
    step = np.linalg.norm((later[:-1] - points[:-1])[:, [0, 2]], axis=1)
    return float(step[both].max() * 1000.0)


def longest_rest(planted) -> int:
    """Most consecutive planted frames."""
    best = run = 0
    for p in planted:
        run = run + 1 if p else 0
        best = max(best, run)
    return best


def measure(fig, motion, speed) -> dict:
    contact = ankle = 0.0
    rests = []
    both = feet(fig, motion, speed)
    floor = min(f[3][:, :, 1].min() for f in both.values())
    clear, drag = np.inf, 0.0
    for pts, nxt, ank, verts in both.values():
        planted = ank[:, 1] <= ank[:, 1].min() + PLANTED
        contact = max(contact, slide(pts, nxt, planted))
        ank_next = np.concatenate([ank[1:], ank[-1:]])
        ankle = max(ankle, slide(ank, ank_next, planted))
        rests.append(longest_rest(planted))
        clear = min(clear, swing_clearance(verts, planted, floor))
        drag = max(drag, dragged(verts, planted, floor))
    return {
        "contact_mm": round(contact, 2),
        "ankle_mm": round(ankle, 2),
        "rest_frames": min(rests),
        "swing_clearance_mm": round(clear * 1000.0, 2),
        "drag_mm": round(drag, 2),
    }


def swing_clearance(verts, planted, floor) -> float:
    """The least height (m) of the foot's lowest vertex above ``floor`` over the frames it swings (inf if none)."""
    if planted.all():
        return float("inf")
    return float(verts[~planted, :, 1].min() - floor)


def dragged(verts, planted, floor) -> float:
    """Largest horizontal step (mm/frame) of a foot vertex within TOUCH of the floor at both frames, off the planted ones."""
    low = verts[:, :, 1] - floor < TOUCH  # (T, V)
    touching = low[1:] & low[:-1] & ~(planted[1:] & planted[:-1])[:, None]
    if not touching.any():
        return 0.0
    step = np.linalg.norm((verts[1:] - verts[:-1])[:, :, [0, 2]], axis=2)
    return float(step[touching].max() * 1000.0)


def best_speed(fig, motion) -> float:
    """The body speed under which the planted feet move least: their median backward speed."""
    v = []
    for pts, nxt, ank, _ in feet(fig, motion, 0.0).values():
        planted = ank[:, 1] <= ank[:, 1].min() + PLANTED
        both = planted[1:] & planted[:-1]
        v.extend((-(nxt[:-1, 0] - pts[:-1, 0]))[both])
    return float(np.median(v)) if v else 0.0


def main() -> None:
    fig, motions = load()
    report = {}
    for name, motion in motions.items():
        # A motion that carries the figure needs no scene-level translation.
        speed = 0.0 if motion.root is not None else SPEEDS[name]
        at = measure(fig, motion, speed)
        v = best_speed(fig, motion)
        best = measure(fig, motion, v)
        report[name] = {
            "speed": round(speed, 4),
            "root_track": motion.root is not None,
            **at,
            "best_speed": round(v, 4),
            "best_contact_mm": best["contact_mm"],
            "best_ankle_mm": best["ankle_mm"],
            "swing_clearance_mm": at["swing_clearance_mm"],
            "drag_mm": at["drag_mm"],
        }
        print(
            f"{name:5s} {'on its ROOT track' if motion.root is not None else f'at {speed * 1000:6.1f} mm/frame'}: planted foot slides up to "
            f"{at['contact_mm']:6.2f} mm/frame at the sole, {at['ankle_mm']:6.2f} at the ankle; "
            f"rests {at['rest_frames']} frames in a row; best body speed {v * 1000:6.1f} mm/frame "
            f"-> {best['contact_mm']:6.2f} / {best['ankle_mm']:6.2f} mm/frame; swinging foot clears the floor by "
            f"at least {at['swing_clearance_mm']:5.1f} mm and drags {at['drag_mm']:6.2f} mm/frame"
        )
    worst = max(max(r["contact_mm"], r["ankle_mm"], r["drag_mm"]) for r in report.values())
    lowest = min(r["swing_clearance_mm"] for r in report.values())
    never = [n for n, r in report.items() if r["rest_frames"] < 2]
    met = worst <= 1.0 and lowest >= CLEARANCE * 1000.0 and not never
    print(
        f"target: slide and drag at most 1 mm/frame, swing clearance at least {CLEARANCE * 1000:.0f} mm; "
        f"worst now {worst:.2f} mm/frame, {lowest:.1f} mm"
        + (f"; no foot rests two frames in {', '.join(never)}" if never else "")
        + f" ({'met' if met else 'not met'})"
    )
    print(json.dumps({"motions": report, "worst_mm": worst, "min_swing_clearance_mm": lowest, "met": met}))


if __name__ == "__main__":
    main()
