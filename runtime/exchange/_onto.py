"""``liganimate import capture.bvh --onto LIBRARY``: the figure to retarget onto, and the library that results.

:func:`load_figure` loads a model the way a program's ``LOAD`` does (so
the figure is exactly the one the motion will play on, SCALE MODEL and name
table included); :func:`retarget_library` runs the retargeting and writes
a library holding only the MOTION, with a report in its comments.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from liganimate.runtime.errors import LigError

from ._joint_map import JointMap, auto_map, read_map
from ._lig_write import motion_library
from ._retarget import CLAMP_REPORT, Retargeted, RetargetOptions, retarget, runs

__all__ = ["OntoOptions", "foot_slide", "load_figure", "retarget_library"]


@dataclass(frozen=True)
class OntoOptions:
    """What ``--onto`` and its companions ask for.

    Attributes
    ----------
    library : str
        A standard library's name (``humanoid``) or a ``.lig`` file.
    model : str or None
        The MODEL in it (None: its only model).
    map_file : str or None
        A joint map (``--map``); None: the automatic map.
    motion : str
        The MOTION's name.
    source_name : str
        The capture's file name, for the comments.
    retarget : RetargetOptions
    tolerance : float
        Degrees, as for a plain import.
    """

    library: str
    model: str | None = None
    map_file: str | None = None
    motion: str = "CAPTURE"
    source_name: str = "capture.bvh"
    retarget: RetargetOptions = RetargetOptions()
    tolerance: float = 0.0


def load_figure(library: str, model: str | None = None):
    """``(name, figure, how LOAD names the library)`` of a model in a library.

    Raises
    ------
    LigError
        When the library has no such model (or several and none was named).
    LigDiagnostics
        When the library does not compile.
    """
    from liganimate.compiler import load_program
    from liganimate.compiler.library import is_path

    if is_path(library):
        where = os.path.abspath(library)
        if "'" in where or "\n" in where:
            raise LigError(f"cannot LOAD {library}: its path holds a quote.", "rename or move the library file")
    else:
        where = library
    program, _ = load_program(text=f"      LOAD '{where}'\n      END\n", name="<retarget>")
    rt = program.execute("check")
    from liganimate.runtime.figure.tree import Figure

    models = {n: v for n, v in rt.variables.items() if isinstance(v, Figure) and not n.startswith("_")}
    if model is None:
        if len(models) != 1:
            names = ", ".join(sorted(models)) or "none"
            raise LigError(
                f"{library} holds {len(models)} models ({names}); which one should the capture drive?",
                "name it with --onto-model",
            )
        model = next(iter(models))
    key = model.upper()
    if key not in models:
        raise LigError(f"{library} has no model called {model}.", "its models are " + ", ".join(sorted(models)))
    return key, models[key], library


def _names(fig) -> tuple:
    names = []
    for l in fig.links:
        own = l.name or ""
        names.append([own] + ([l.source.name] if l.source is not None else []))
    with_joint = sorted(fig.child_of(j) for j in fig.joints)
    return names, with_joint


def joint_map(clip, fig, map_file: str | None) -> JointMap:
    """The automatic map, or the map file's, between a capture and a figure."""
    names, with_joint = _names(fig)
    if map_file is not None:
        return read_map(map_file, clip.names, names, with_joint)
    return auto_map(clip.names, names, with_joint)


def foot_slide(fig, result: Retargeted, jmap: JointMap) -> float:
    """The most a planted ankle of the retargeted motion moves between two frames, in the figure's units.

    Computed with the runtime's own kinematics (``pose_transforms``), not
    the retargeting's.
    """
    from liganimate.runtime.figure.kinematics import pose_transforms
    from liganimate.runtime.motion.turning import orientation_matrix

    angles = np.zeros((len(result.path), fig.n_joints, 3))
    for n, jid in enumerate(result.joint_ids):
        angles[:, fig.joint_index(jid)] = result.angles[:, n]
    X = pose_transforms(fig, angles)
    if result.orientation is not None:  # the figure turns: world = Trans(path) @ Rot(orientation) @ pose
        R = orientation_matrix(result.orientation)
        X[:, :, :3, :] = np.einsum("fij,fnjk->fnik", R, X[:, :, :3, :])
    worst = 0.0
    for side, mask in result.planted.items():
        foot = jmap.feet[side][1][2]
        k = fig.joint_index(fig.parent_joint_of(foot).id)
        ankle = np.einsum("fij,j->fi", X[:, foot, :3, :3], fig.locations[1][k]) + X[:, foot, :3, 3] + result.path
        for a, b in runs(mask):
            if b - a > 1:
                worst = max(worst, float(np.linalg.norm(np.diff(ankle[a:b], axis=0), axis=1).max()))
    return worst


def retarget_library(clip, options: OntoOptions) -> tuple:
    """The library text and the report lines of a capture retargeted onto a library's figure.

    Returns
    -------
    (bytes, list of str, Retargeted)
    """
    name, fig, library = load_figure(options.library, options.model)
    jmap = joint_map(clip, fig, options.map_file)
    result = retarget(clip, fig, jmap, options.retarget)
    report = _report(clip, fig, name, library, jmap, result)
    comments = [
        f"{options.motion}: {clip.data.shape[0]} frames of {options.source_name} retargeted by liganimate onto "
        f"{name} of '{library}'.",
        f"Play it with LOAD {name} FROM '{library}' and ANIMATE {name} ... USING {options.motion}.",
        "",
        *report,
    ]
    text = motion_library(
        options.motion, result.angles, result.joint_ids, result.path, comments, options.tolerance, result.orientation
    )
    return text, report, result


def _report(clip, fig, name, library, jmap: JointMap, result: Retargeted) -> list:
    lines = [f"joint map: capture as {jmap.source_profile}, figure as {jmap.target_profile}"]
    for s, t in jmap.pairs:
        lines.append(f"  {clip.names[s]} -> {fig.links[t].name}")
    if jmap.unmapped_source:
        shown = ", ".join(jmap.unmapped_source[:12]) + (", ..." if len(jmap.unmapped_source) > 12 else "")
        lines.append(f"capture joints left out ({len(jmap.unmapped_source)}): {shown}")
    if jmap.unmapped_target:
        lines.append(f"figure links nothing drives (they stay at neutral): {', '.join(jmap.unmapped_target)}")
    lines.append(f"scale {result.scale:.6g} (the figure's leg length over the capture's)")
    total = sum(result.clamped.values())
    lines.append(
        f"clamped into the figure's extremes (by more than {CLAMP_REPORT:g} degree): {total} joint-frames"
        + (" (" + ", ".join(f"joint {j}: {n}" for j, n in sorted(result.clamped.items())) + ")" if total else "")
    )
    planted = {s: int(m.sum()) for s, m in result.planted.items()}
    if planted:
        slide = foot_slide(fig, result, jmap)
        lines.append(
            f"planted frames: left {planted.get('L', 0)}, right {planted.get('R', 0)}; "
            f"the most a planted ankle moves in a frame: {slide:.3g}"
        )
    heading = result.orientation[:, 1]
    lines.append(
        f"heading (ROOT ORIENTATION, degrees about up): {heading[0]:.0f} to {heading[-1]:.0f}, "
        f"turning {heading[-1] - heading[0]:+.0f} in all (between {heading.min():.0f} and {heading.max():.0f})"
    )
    lines += [f"note: {n}" for n in result.notes]
    return lines
