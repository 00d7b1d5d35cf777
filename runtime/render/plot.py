"""``liganimate plot``: a motion's joint angle curves, drawn with matplotlib.

One panel per joint, its X, Y and Z angles against the frame, each keyframe
marked where it sets its value. The curves are sampled from the motion
itself (the same evaluation ANIMATE uses), so ramps, holds and the velocity
adjustment show as they play.
"""

from __future__ import annotations

import io

import numpy as np

from liganimate.runtime.errors import LigError
from liganimate.runtime.files import AtomicWriter

# Samples across the whole motion: enough for smooth curves over a few
# hundred frames, bounded so that ``1000000000 * WALK`` still plots at once.
MAX_SAMPLES = 4000
MAX_MARKED_KEYFRAMES = 400
_AXES = (("X", "#c0392b"), ("Y", "#27ae60"), ("Z", "#2c5fa8"))


def sample_times(length: float, max_samples: int = MAX_SAMPLES) -> np.ndarray:
    """Frames at which to sample a motion of ``length`` frames, shape (T,).

    Every whole frame when there are few, otherwise ``max_samples`` evenly spaced.
    """
    if length <= 0:
        return np.zeros(1)
    if length <= max_samples / 4:
        return np.linspace(0.0, length, round(length * 4) + 1)
    return np.linspace(0.0, length, max_samples)


def joint_links(variables: dict, joints) -> tuple[dict, str | None]:
    """The link each of ``joints`` moves (its secondary), named from the program's model that has most of them.

    Returns ``({joint id: link name}, model name)``; ``({}, None)`` when no
    MODEL variable has any of the joints (a motion made for a library's model).
    """
    wanted = set(joints)
    best = None
    for name in sorted(variables):
        fig = variables[name]
        ids = getattr(fig, "joint_ids", None)
        if not isinstance(ids, tuple) or not hasattr(fig, "links"):
            continue
        count = len(wanted & set(ids))
        if count and (best is None or count > best[0]):
            best = (count, name, fig)
    if best is None:
        return {}, None
    fig = best[2]
    return {j: fig.links[fig.joint(j).secondary].label for j in joints if j in fig.joint_ids}, best[1]


def plot_motion_figure(motion, title: str, links: dict | None = None, model: str | None = None):
    """A matplotlib Figure of ``motion``'s angle curves (one axes per joint).

    ``links`` names the link each joint moves (:func:`joint_links`), of the MODEL ``model``.
    """
    from matplotlib.figure import Figure

    links = links or {}
    joints = motion.joints
    n = max(1, len(joints))
    fig = Figure(figsize=(8.0, 1.8 + 1.5 * n), dpi=100, layout="constrained")
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    t = sample_times(motion.length)
    angles = motion.evaluate(t) if joints else np.zeros((len(t), 0, 3))
    for i, j in enumerate(joints):
        ax = axes[i]
        for k, (label, colour) in enumerate(_AXES):
            ax.plot(t, angles[:, i, k], color=colour, lw=1.4, label=label)
        try:
            start, keys = motion.keyframes(j, limit=MAX_MARKED_KEYFRAMES)
        except LigError:
            keys, start = None, None  # too many to mark (a long repetition): curves only
        if keys is not None:
            frames = np.array([0.0] + [k.frame for k in keys])
            values = np.array([start] + [k.position for k in keys], dtype=float)
            for k, (_, colour) in enumerate(_AXES):
                ax.plot(frames, values[:, k], "o", color=colour, ms=4, mfc="white", mew=1.2)
        # The link the joint moves says more than its number; the number stays for the program's text.
        ax.set_ylabel(f"{links[j]}\n(joint {j}, degrees)" if j in links else f"joint {j}\n(degrees)", fontsize="small")
        ax.grid(True, color="#dddddd", lw=0.6)
    if not joints:
        axes[0].text(0.5, 0.5, "this motion drives no joint", ha="center", va="center", transform=axes[0].transAxes)
    axes[-1].set_xlabel("frame")
    on = f" on {model}" if model and links else ""
    # The title at the left and the legend at the right, both above the first panel: they never overlap.
    axes[0].set_title(f"MOTION {title}{on}: {motion.length:g} frames (keyframes marked)", loc="left", fontsize="medium")
    axes[0].legend(
        loc="lower right", bbox_to_anchor=(1.0, 1.0), ncols=3, fontsize="small", frameon=False, borderaxespad=0.2
    )
    return fig


def plot_motion(rt, name: str, out_path: str) -> None:
    """Plot the MOTION variable ``name`` of a program run by ``rt`` to the PNG ``out_path``.

    Raises
    ------
    LigError
        When the program has no such motion. Nothing is written then.
    """
    from liganimate.lang.diagnostics import did_you_mean
    from liganimate.runtime.motion.algebra import Motion

    variables = rt.variables
    value = variables.get(name)
    if value is None or not isinstance(value, Motion):
        motions = sorted(n for n, v in variables.items() if isinstance(v, Motion))
        if name in variables:
            raise LigError(f"{name} is not a MOTION", "the program's motions are " + (", ".join(motions) or "none"))
        hint = did_you_mean(name, motions) or ("the program's motions are " + (", ".join(motions) or "none"))
        raise LigError(f"the program has no motion called {name}", hint)
    links, model = joint_links(variables, value.joints)
    fig = plot_motion_figure(value, name, links, model)
    buffer = io.BytesIO()
    # No metadata: the same motion gives the same bytes.
    fig.savefig(buffer, format="png", metadata={"Software": None})
    with AtomicWriter(out_path) as fh:
        fh.write(buffer.getvalue())


__all__ = ["joint_links", "plot_motion", "plot_motion_figure", "sample_times"]
