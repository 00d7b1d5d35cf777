"""The STARTREACH block as the language writes it: GOAL lines in, a motion, a translation and warnings out.

The compiled program hands the host each GOAL line as plain fields; the
host calls :func:`language_goal` once per line (so that an unknown link is
reported at its own line), then :func:`reach_block` for the whole block.
Neither knows source positions: errors are :class:`GoalError` sentences and
warnings say which goal they are about, and the host attaches the
``file:line:col``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from liganimate.lang import numbers as N
from liganimate.runtime.figure.tree import Figure
from liganimate.runtime.ik.goals import AxisGoal, GoalError, PlaneGoal, PointGoal, resolve_link
from liganimate.runtime.ik.reach import ReachOptions, reach
from liganimate.runtime.motion.algebra import Motion

__all__ = ["UNMET_HINT", "ReachWarning", "ReachBlock", "check_frames", "language_goal", "reach_block"]

#: The hint under each unmet goal's warning.
UNMET_HINT = "the model cannot get there within its extremes, or other goals pull it away"


@dataclass(frozen=True)
class ReachWarning:
    """A warning of a REACH block: about goal ``goal`` (an index into the block's goals), or the block when None."""

    goal: int | None
    sentence: str
    hint: str | None = None


@dataclass(frozen=True)
class ReachBlock:
    """The result of :func:`reach_block`.

    Attributes
    ----------
    motion : Motion
        From the start pose at frame 0 to the solved pose.
    translation : tuple of 3 float
        The solved root translation, within the geometry limit.
    warnings : tuple of ReachWarning
        The unmet goals in the order given, then the iteration limit's.
    """

    motion: Motion
    translation: tuple[float, float, float]
    warnings: tuple[ReachWarning, ...]


def check_frames(frames) -> None:
    """Refuse a negative frame for the solved pose.

    Raises
    ------
    GoalError
        For ``frames < 0``.
    """
    if frames < 0:
        raise GoalError(f"the solved pose's frame cannot be negative ({frames:g}).")


def language_goal(
    figure: Figure, kind: str, link, joint, point, target, normal, weight
) -> tuple[PointGoal | PlaneGoal | AxisGoal, str | None]:
    """The goal of one GOAL line, its link settled.

    Parameters
    ----------
    figure : Figure
    kind : {"point", "plane", "axis"}
    link : str or None
        The link's name; None when ``joint`` names it.
    joint : int or None
        The joint whose secondary link the goal moves (used when ``link`` is None).
    point : sequence of 3 float, or None
        The point in the link's coordinates (default the origin); unused by an axis goal.
    target : sequence of 3 float
        The world point, the plane's point, or (axis) the world direction.
    normal : sequence of 3 float, or None
        The plane's normal, or (axis) the direction in the link.
    weight : float or None
        Default 1.

    Returns
    -------
    goal : PointGoal, PlaneGoal or AxisGoal
        With its link as an index into ``figure.links``.
    ambiguous : str or None
        A warning sentence when several links bear the name.

    Raises
    ------
    GoalError, FigureError
        For an unknown link name or joint.
    """
    ambiguous = None
    if link is None:
        index = figure.joint(int(joint)).secondary
    else:
        index, ambiguous = resolve_link(figure, link)
    w = 1.0 if weight is None else float(weight)
    p = (0.0, 0.0, 0.0) if point is None else tuple(point)
    if kind == "point":
        return PointGoal(index, tuple(target), p, w), ambiguous
    if kind == "plane":
        return PlaneGoal(index, tuple(target), tuple(normal), p, w), ambiguous
    return AxisGoal(index, tuple(normal), tuple(target), w), ambiguous


def reach_block(
    figure: Figure,
    goals: Sequence,
    frames,
    method: str,
    *,
    start: Motion | None,
    options: ReachOptions,
) -> ReachBlock:
    """Solve a STARTREACH block.

    Parameters
    ----------
    figure : Figure
    goals : sequence of goals
        From :func:`language_goal`, in the block's order.
    frames : float
        The solved pose's frame, ``>= 0`` (:func:`check_frames`).
    method : str
        The interpolation method to the solved pose.
    start : Motion or None
        The motion whose last pose the solve starts from; None for the neutral pose.
    options : ReachOptions
        MOVE, TRANSLATE INTO, the solver and its settings, as the compiled program built them.

    Returns
    -------
    ReachBlock

    Raises
    ------
    GoalError
        For a solved translation beyond the geometry limit, and as :func:`reach.reach`.
    """
    result = reach(figure, goals, float(frames), method, start=start, options=options)
    t = np.asarray(result.translation, dtype=float).reshape(3)
    if not np.all(np.abs(t) <= N.GEOMETRY_MAX):
        raise GoalError(
            "the solved translation is not within the geometry limit.",
            hint="the goals may be too far away for the model; everything drawn stays within 1E12 units",
        )
    # Unmet goals, in the solver's own words and by its own test of "met".
    warnings = [ReachWarning(unmet.index, unmet.sentence, UNMET_HINT) for unmet in result.unmet or ()]
    with np.errstate(all="ignore"):
        limit = result.limit_warning
    if limit:
        warnings.append(ReachWarning(None, limit))
    return ReachBlock(result.motion, (float(t[0]), float(t[1]), float(t[2])), tuple(warnings))
