"""Goal-directed positioning: poses and motions asked for by where parts of a figure should be.

This is the Python face of the solvers, and what the language's goal
construct calls.  :func:`solve_pose` finds the pose (and, optionally, the
root translation) that best meets a list of weighted goals;
:func:`reach` wraps that pose into an ordinary :class:`motion.Motion` going
from a start pose at frame 0 to the solved pose at frame ``n``, which then
works with ``+``, ``*``, STRIP, SYNCHRONIZE, SCALE and ANIMATE like any
other motion; :func:`reach_keyframes` solves a batch of goals (a moving
target) at once and strings the poses into one motion.

A figure that cannot reach its goals is not an error: the result is the
least-squares best pose, with each goal's residual reported.

Example (``arm`` a model with a link named HAND)::

    r = reach(arm, [PointGoal("HAND", (0.3, 0.2, 0.0), point=(0, -12, 0), weight=10)],
              frames=24, method="ACCDCC", movable=3)
    r.motion        # a Motion of length 24 driving the three joints above the hand
    r.residuals     # the hand's distance to its goal, shape (1,)
    r.unmet         # () when it gets there, else (UnmetGoal(0, distance, sentence),)
    r.translation   # (0, 0, 0): translate=True would let the whole arm move
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure import pose as PO
from liganimate.runtime.figure.tree import Figure, Joint
from liganimate.runtime.ik.goals import AxisGoal, GoalError, GoalStack, PlaneGoal, PointGoal, batch_size, resolve_link
from liganimate.runtime.ik.model import IKModel, figure_length
from liganimate.runtime.ik.options import ReachOptions
from liganimate.runtime.ik.solvers import CONVERGED, LIMIT, SOLVER_NAMES, SOLVERS, STALLED, solve
from liganimate.runtime.motion.algebra import Motion
from liganimate.runtime.motion.keyframe import Keyframe

__all__ = [
    "ReachOptions",
    "PointGoal",
    "PlaneGoal",
    "AxisGoal",
    "GoalError",
    "PoseSolution",
    "Reach",
    "solve_pose",
    "reach",
    "reach_keyframes",
    "chain_joints",
    "start_pose",
    "residual_warnings",
    "UnmetGoal",
    "unmet_goals",
    "DEFAULT_TOLERANCE",
    "DEFAULT_MAX_ITERATIONS",
]

#: Default tolerance, as a fraction of the figure's length (the sum of its link lengths).
DEFAULT_TOLERANCE = 1e-5
#: Default iteration limits per solver (sweeps for CCD), from the solvers' registry.
DEFAULT_MAX_ITERATIONS = {name: spec.max_iterations for name, spec in SOLVERS.items()}


class SolveStatus(StrEnum):
    """How a solve ended (``PoseSolution.status``); a StrEnum, so each is also its word."""

    CONVERGED = "converged"  # every goal of non-zero weight is within the tolerance
    STALLED = "stalled"  # no move lowers the weighted cost: the least-squares best pose
    LIMIT = "limit"  # the iteration limit came first


#: The solvers' status codes (runtime/ik/solvers.py) as the solution reports them.
_STATUS = {CONVERGED: SolveStatus.CONVERGED, STALLED: SolveStatus.STALLED, LIMIT: SolveStatus.LIMIT}
# The same as an array indexed by the codes: a batch's statuses in one gather.
_STATUS_BY_CODE = np.array([_STATUS.get(code) for code in range(max(_STATUS) + 1)], dtype=object)


_DEFAULT_OPTIONS = ReachOptions()
_OPTION_NAMES = frozenset(f.name for f in dataclasses.fields(ReachOptions))


def reach_options(options: ReachOptions | None = None, **fields) -> ReachOptions:
    """``options`` (default :class:`ReachOptions`) with ``fields`` replacing its values.

    Raises
    ------
    GoalError
        For a keyword that is not a field of :class:`ReachOptions`.
    """
    base = options if options is not None else _DEFAULT_OPTIONS
    unknown = sorted(set(fields) - _OPTION_NAMES)
    if unknown:
        raise GoalError(f"there is no REACH option {', '.join(unknown)}.")
    if not fields:
        return base
    # A script solving one figure again and again passes the same options
    # each time: dataclasses.replace costs more than the rest of the options.
    # Only plain values are remembered, with their types (1, 1.0 and True are
    # equal keys, but not the same option: True restarts is an error).
    if any(type(v) not in _PLAIN for v in fields.values()):
        return dataclasses.replace(base, **fields)
    key = (base, tuple((k, type(v), v) for k, v in fields.items()))
    hit = _OPTIONS_MADE.get(key)
    if hit is None:
        if len(_OPTIONS_MADE) >= 256:
            _OPTIONS_MADE.clear()
        hit = _OPTIONS_MADE[key] = dataclasses.replace(base, **fields)
    return hit


_OPTIONS_MADE: dict = {}  # (options, fields) -> options with those fields; frozen values, so shared
_PLAIN = (type(None), bool, int, float, str)


@dataclass(frozen=True)
class PoseSolution:
    """The result of :func:`solve_pose`.

    Shapes are given for a batch of ``B`` solves; an unbatched solve has no
    leading ``B``.

    Attributes
    ----------
    angles : numpy.ndarray, shape (B, n_joints, 3)
        The solved pose in degrees, in the figure's joint order, within
        every joint's extremes (free axes wrapped into their range).
    translation : numpy.ndarray, shape (B, 3)
        World translation of the whole figure (zero unless translating):
        the solved figure is ``figure.placed(translation matrix)``, i.e.
        ``m :- m <TRANS (t)>``.
    residuals : numpy.ndarray, shape (B, n_goals)
        Per goal, in the order given: a point goal's distance to its target
        and a plane goal's distance to its plane (world units), an axis
        goal's angle to its direction (degrees).
    converged : numpy.ndarray of bool, shape (B,)
        Every goal of non-zero weight is within the tolerance.
    status : numpy.ndarray of SolveStatus, shape (B,)
        ``CONVERGED``, ``STALLED`` (no move lowers the weighted cost: the
        least-squares best pose, goals left unmet) or ``LIMIT`` (the
        iteration limit came first).
    iterations : numpy.ndarray of int, shape (B,)
    tolerance : float
        The tolerance used (world units).
    weights : numpy.ndarray, shape (B, n_goals)
    met : numpy.ndarray of bool, shape (B, n_goals)
        Which goals are within the tolerance (a goal of weight 0 counts as
        met: it asks for nothing).
    warnings : list of str
        Ambiguous link names.
    history : list of numpy.ndarray
        The weighted cost after each iteration (each of shape (B,)), when
        traced.
    """

    angles: np.ndarray
    translation: np.ndarray
    residuals: np.ndarray
    converged: np.ndarray | bool
    status: np.ndarray | SolveStatus
    iterations: np.ndarray | int
    tolerance: float
    weights: np.ndarray
    met: np.ndarray
    warnings: list = field(default_factory=list)
    history: list = field(default_factory=list)


@dataclass(frozen=True)
class UnmetGoal:
    """A goal that a solve leaves unmet, as data.

    Attributes
    ----------
    index : int
        The goal's position in the list given to the solve, from 0 (the
        user's "goal N" is ``index + 1``).
    distance : float
        How far it is left: world units for a point or plane goal, degrees
        for an axis goal (its entry of ``PoseSolution.residuals``).
    sentence : str
        What that means, for a user, e.g. ``"the point of R_HAND stays
        0.1231 from its target."``; ``str()`` prefixes ``"goal N: "``.
    """

    index: int
    distance: float
    sentence: str

    def __str__(self) -> str:
        return f"goal {self.index + 1}: {self.sentence}"


@dataclass(frozen=True)
class Reach:
    """The result of :func:`reach`: a motion and how well its last pose meets the goals.

    Attributes
    ----------
    motion : Motion
        From the start pose at frame 0 to the solved pose(s).
    solution : PoseSolution
    joints : tuple of int
        The joint ids the motion drives.
    unmet : tuple of UnmetGoal, or None
        The goals the solved pose leaves unmet, in the order given (empty
        when it meets them all); None for :func:`reach_keyframes`'s batch
        (see ``solution.met`` there).
    """

    motion: Motion
    solution: PoseSolution
    joints: tuple
    unmet: tuple[UnmetGoal, ...] | None = None

    @property
    def limit_warning(self) -> str | None:
        """A sentence when goals are unmet and the iteration limit stopped the solve, else None."""
        return _limit_sentence(self.solution, self.unmet) if self.unmet else None

    @property
    def residuals(self) -> np.ndarray:
        """Per-goal residuals of the solved pose; see :class:`PoseSolution`."""
        return self.solution.residuals

    @property
    def translation(self) -> np.ndarray:
        """The solved root translation, shape (3,) (or (B, 3))."""
        return self.solution.translation

    @property
    def converged(self):
        """Whether every goal was met (bool, or an array for a batch)."""
        return self.solution.converged


# ---------------------------------------------------------------- helpers


def chain_joints(figure: Figure, link: int, length: int) -> list[int]:
    """The ``length`` joints nearest ``link`` on its path to the current main link.

    Parameters
    ----------
    figure : Figure
    link : int
        Link index.
    length : int
        Non-negative; longer than the path means the whole path.

    Returns
    -------
    list of int
        Joint ids, from ``link`` toward the main link.
    """
    parent = {}
    for level in figure.traversal:
        for k, par, ch in zip(level.joints, level.parents, level.children):
            parent[int(ch)] = (int(par), int(k))
    out: list[int] = []
    cur = link
    while cur != figure.main and len(out) < length:
        cur, k = parent[cur]
        out.append(figure.joints[k].id)
    return out


def start_pose(figure: Figure, start=None) -> np.ndarray:
    """The pose a solve starts from, in degrees, clamped into the extremes.

    Parameters
    ----------
    figure : Figure
    start : None, Motion or array_like of shape (n_joints, 3) or (B, n_joints, 3)
        None is neutral (all zero); a motion gives its final pose (frame
        ``length``; joints it does not drive at neutral, as ANIMATE shows
        them); an array gives the angles in the figure's joint order.

    Returns
    -------
    numpy.ndarray, shape (n_joints, 3) or (B, n_joints, 3)
    """
    if start is None:
        a = np.zeros((figure.n_joints, 3))
    elif isinstance(start, Motion):
        return PO.joint_angles(figure, start, np.array([start.length]))[0]
    else:
        a = np.asarray(start, dtype=float)
        if a.shape[-2:] != (figure.n_joints, 3) or a.ndim > 3:
            raise GoalError(f"a start pose must have shape ({figure.n_joints}, 3) for this model, not {a.shape}.")
        if not np.all(np.isfinite(a)):
            raise GoalError("a start pose must be finite.")
    return K.clamp(figure, a)


#: Rounds of the alternation between the angles and the slides (see :func:`_solve_with_slides`).
SLIDE_ROUNDS = 12


def _solve_with_slides(figure: Figure, goals: list, start, o: ReachOptions, trace: bool) -> PoseSolution:
    """:func:`solve_pose` for a figure with slides: the angles and the slides in turn.

    The solvers' variables are angles.  With the slides held, the goals are
    met by the angles (:func:`_hold_slides`); with the angles held, every
    link is an affine function of the slides' displacements, so the slides
    that may move take the least-squares step of the weighted residuals,
    within their extremes (an active set: a displacement the step would push
    past an extreme is fixed there and the rest solved again).  The two
    alternate until the goals are met, the slides stop moving, or
    :data:`SLIDE_ROUNDS` rounds.  A batch of solves holds the slides.
    """
    held, start_held, values = _hold_slides(figure, start)
    solution = solve_pose(held, goals, start=start_held, options=o, trace=trace)
    mask = _movable_mask(figure, goals, o.movable) & (figure.extremes[..., 1] > figure.extremes[..., 0])
    slide_rows = [int(k) for k in np.flatnonzero(figure.slides)]
    free = [(k, a) for k in slide_rows for a in range(3) if mask[k, a]]
    batched = np.ndim(solution.angles) == 3
    for _ in range(SLIDE_ROUNDS if free and not batched else 0):
        if bool(np.all(solution.met)):
            break
        step = _slide_step(figure, goals, solution, values, free, o.translate)
        if not np.any(np.abs(step) > 1e-12):
            break
        for n, (k, a) in enumerate(free):
            values[slide_rows.index(k), a] += step[n]
        angles = np.array(solution.angles)
        angles[figure.slides] = values
        held, start_held, _ = _hold_slides(figure, angles)
        solution = solve_pose(held, goals, start=start_held, options=o, trace=trace)
    angles = np.array(solution.angles)
    angles[..., figure.slides, :] = values
    return dataclasses.replace(solution, angles=angles)


def _slide_residuals(figure: Figure, goals: list, angles: np.ndarray, translation, translate: bool) -> np.ndarray:
    """The weighted goal residuals of one pose (slides included, through a held figure)."""
    held, start_held, _ = _hold_slides(figure, angles)
    model = IKModel.cached(held, np.zeros((held.n_joints, 3), dtype=bool), translate)
    stack = GoalStack(model, goals, 1)
    R, p = model.forward(np.deg2rad(start_held)[None])
    t = np.asarray(translation, dtype=np.float64)[None] if translate else None
    return stack.evaluate(R, p, t)[0][0]


def _slide_step(figure: Figure, goals: list, solution, values, free: list, translate: bool) -> np.ndarray:
    """The bounded least-squares step of the free slide axes, the angles held."""
    angles = np.array(solution.angles)
    angles[figure.slides] = values
    r0 = _slide_residuals(figure, goals, angles, solution.translation, translate)
    J = np.empty((len(r0), len(free)))
    for n, (k, a) in enumerate(free):
        moved = angles.copy()
        moved[k, a] += 1.0  # the residuals are affine in a displacement: one unit's difference is exact
        J[:, n] = _slide_residuals(figure, goals, moved, solution.translation, translate) - r0
    lo = np.array([figure.extremes[k, a, 0] - angles[k, a] for k, a in free])
    hi = np.array([figure.extremes[k, a, 1] - angles[k, a] for k, a in free])
    step = np.zeros(len(free))
    active = np.zeros(len(free), dtype=bool)
    for _ in range(len(free) + 1):
        idle = ~active
        if not idle.any():
            break
        rhs = -(r0 + J[:, active] @ step[active])
        step[idle] = np.linalg.lstsq(J[:, idle], rhs, rcond=None)[0]
        out = idle & ((step < lo) | (step > hi))
        if not out.any():
            break
        step = np.clip(step, lo, hi)
        active |= out
    return np.clip(step, lo, hi)


def _hold_slides(figure: Figure, start) -> tuple[Figure, np.ndarray, np.ndarray]:
    """REACH holds every slide at its start displacement.

    Returns
    -------
    held : Figure
        The figure with each slide's start displacement built into its
        primary location, the slide made a locked turn joint.
    start : numpy.ndarray
        The start pose for ``held`` (those joints at zero).
    values : numpy.ndarray, shape (n_slides, 3)
        The displacements held.

    Raises
    ------
    GoalError
        When a batch of start poses differs in a slide (one figure cannot
        hold two displacements).
    """
    start_deg = np.array(start_pose(figure, start))
    slides = figure.slides
    d = start_deg[..., slides, :]
    if d.ndim == 3 and not np.all(d == d[:1]):
        raise GoalError(
            "REACH holds slide joints at their start displacement, and this batch of start poses differs there.",
        )
    values = d.reshape(-1, d.shape[-2], 3)[0]
    joints = list(figure.joints)
    for value, k in zip(values, np.flatnonzero(slides)):
        j = joints[k]
        shift = j.slide_scale * (figure.frames[k] @ value)
        joints[k] = Joint(j.id, j.primary, j.secondary, j.loc1 + shift, j.loc2, np.zeros((1, 2)))
    held = Figure(figure.links, tuple(joints), root=figure.root, main=figure.main, placement=figure.placement)
    start_deg[..., slides, :] = 0.0
    return held, start_deg, values


def _movable_mask(figure: Figure, goals: Sequence, movable) -> np.ndarray:
    """Which joint axes may move, shape (n_joints, 3), from the ``movable`` option."""
    J = figure.n_joints
    mask = np.zeros((J, 3), dtype=bool)
    if movable is None:
        mask[:] = True
        return mask
    if isinstance(movable, (int, np.integer)) and not isinstance(movable, bool):
        if movable < 0:
            raise GoalError(f"a chain length must not be negative, not {int(movable)}.")
        for g in goals:
            link, _ = resolve_link(figure, g.link)
            for jid in chain_joints(figure, link, int(movable)):
                mask[figure.joint_index(jid)] = True
        return mask
    try:
        ids = list(movable)
    except TypeError:
        raise GoalError("the movable joints must be a chain length or a list of joint ids.") from None
    for jid in ids:
        try:
            mask[figure.joint_index(jid)] = True
        except Exception as exc:  # FigureError, named for the user
            raise GoalError(getattr(exc, "message", str(exc)), getattr(exc, "hint", None)) from None
    return mask


def _options(figure: Figure, solver: str, tolerance, max_iterations) -> tuple[float, int]:
    if solver not in SOLVERS:
        raise GoalError(f"unknown solver {solver!r}.", hint=f"the solvers are {', '.join(SOLVER_NAMES)}")
    if tolerance is None:
        tol = DEFAULT_TOLERANCE * figure_length(figure)
    else:
        tol = float(tolerance)
        if not math.isfinite(tol) or tol <= 0:
            raise GoalError(f"the tolerance must be a positive number, not {tolerance!r}.")
    if max_iterations is None:
        it = DEFAULT_MAX_ITERATIONS[solver]
    else:
        if isinstance(max_iterations, bool) or int(max_iterations) != max_iterations or max_iterations < 0:
            raise GoalError(f"the iteration limit must be a non-negative whole number, not {max_iterations!r}.")
        it = int(max_iterations)
    return tol, it


# ---------------------------------------------------------------- solving


def solve_pose(
    figure: Figure,
    goals: Sequence,
    *,
    start=None,
    options: ReachOptions | None = None,
    trace: bool = False,
    **fields,
) -> PoseSolution:
    """The pose that best meets weighted goals.

    Parameters
    ----------
    figure : Figure
        Seen from its current main link and placed by its placement: goals
        are in the world, ``placement @ pose``.
    goals : sequence of PointGoal, PlaneGoal, AxisGoal
        Their targets, directions, planes and weights may have a leading
        batch dimension ``B`` (all the same ``B``): ``B`` independent solves,
        done together.
    start : None, Motion or array_like, optional
        See :func:`start_pose`.  An array may also be batched,
        ``(B, n_joints, 3)``.
    options : ReachOptions, optional
        Which joints and whether the figure may move, the solver and its
        tolerance, iteration limit and restarts (default ``ReachOptions()``).
    trace : bool, default False
        Keep the cost after every iteration (``history``).
    **fields
        Fields of :class:`ReachOptions` (``movable=``, ``solver=``...), replacing ``options``' values.

    Returns
    -------
    PoseSolution

    Raises
    ------
    GoalError
        For an unknown link or joint, a malformed goal, a negative weight,
        an unknown solver or a bad option.  Unreachable goals are *not* an
        error: see ``PoseSolution.status`` and ``residuals``.
    """
    goals = list(goals)
    o = reach_options(options, **fields)
    if figure.slides.any():
        return _solve_with_slides(figure, goals, start, o, trace)
    tol, max_iter = _options(figure, o.solver, o.tolerance, o.max_iterations)
    restarts, translate = o.restarts, o.translate
    if isinstance(restarts, bool) or not isinstance(restarts, (int, np.integer)) or restarts < 0:
        raise GoalError(f"the number of restarts must be a non-negative whole number, not {restarts!r}.")
    start_deg, base, B, batched = _start_batch(figure, goals, start)
    model = IKModel.cached(figure, _movable_mask(figure, goals, o.movable), translate)
    stack = GoalStack.cached(model, goals, B)
    x0 = np.zeros((B, model.n_params))
    x0[:, : model.n_vars] = np.deg2rad(start_deg).reshape(B, -1)[:, model.var_flat]
    result = solve(
        model,
        stack,
        x0,
        base,
        method=o.solver,
        tolerance=tol,
        max_iterations=max_iter,
        restarts=int(restarts),
        trace=trace,
    )

    return _pose_solution(figure, model, stack, result, start_deg, tol, translate, batched)


def _start_batch(figure: Figure, goals: list, start) -> tuple:
    """The start poses for a solve: ``(degrees (B, J, 3), radians (1 or B, J, 3), B, batched)``.

    Raises
    ------
    GoalError
        When the goals and the start poses are batches of different sizes.
    """
    start_deg = _neutral(figure) if start is None else start_pose(figure, start)
    B_goals = batch_size(goals)
    B_start = start_deg.shape[0] if start_deg.ndim == 3 else None
    if B_goals is not None and B_start is not None and B_goals != B_start:
        raise GoalError(f"the goals are a batch of {B_goals} but the start poses a batch of {B_start}.")
    batched = B_goals is not None or B_start is not None
    B = B_goals or B_start or 1
    base = np.deg2rad(start_deg).reshape(B_start or 1, figure.n_joints, 3)  # (1 or B, J, 3)
    start_deg = (
        start_deg[None] if start_deg.ndim == 2 and B == 1 else np.broadcast_to(start_deg, (B, figure.n_joints, 3))
    )
    return start_deg, base, B, batched


def _neutral(figure: Figure) -> np.ndarray:
    """``start_pose(figure)``, the neutral pose clamped into the extremes, remembered per figure (read-only)."""
    hit = _NEUTRAL.get(id(figure.joints))
    if hit is not None and hit[0] is figure.joints:
        return hit[1]
    pose = start_pose(figure)
    pose.setflags(write=False)
    if len(_NEUTRAL) >= 256:
        _NEUTRAL.clear()
    _NEUTRAL[id(figure.joints)] = (figure.joints, pose)
    return pose


_NEUTRAL: dict = {}  # id(joints) -> (joints, neutral pose); the stored joints keep the id valid


def _pose_solution(figure, model, stack, result, start_deg, tol: float, translate: bool, batched: bool):
    """The solver's result as a :class:`PoseSolution`: angles clamped, batched or not as the input was."""
    B = start_deg.shape[0]
    q = result.x[:, : model.n_vars]
    angles = start_deg.copy()
    flat = angles.reshape(B, -1)
    flat[:, model.var_flat] = np.rad2deg(q)
    angles = flat.reshape(B, figure.n_joints, 3)
    # kinematics.clamp; where no axis wraps that is a clip, without its checks of the angles it is given.
    angles = (
        K.clamp(figure, angles) if model.wraps else np.minimum(np.maximum(angles, model.extremes_lo), model.extremes_hi)
    )
    t = result.x[:, model.n_vars :] * model.length if translate else np.zeros((B, 3))
    # Wrapping free axes changes no link, so the solver's last distances are the pose's.
    residuals = stack.report(result.dist)
    converged = result.status == CONVERGED
    status = _STATUS_BY_CODE[result.status]
    met = (result.dist <= tol) | ~stack.active
    if batched:
        return PoseSolution(
            angles=angles,
            translation=t,
            residuals=residuals,
            converged=converged,
            status=status,
            iterations=result.iterations,
            tolerance=tol,
            weights=stack.weights,
            met=met,
            warnings=stack.warnings,
            history=result.history,
        )
    return PoseSolution(
        angles=angles[0],
        translation=t[0],
        residuals=residuals[0],
        converged=bool(converged[0]),
        status=status[0],
        iterations=int(result.iterations[0]),
        tolerance=tol,
        weights=stack.weights[0],
        met=met[0],
        warnings=stack.warnings,
        history=[h[0] for h in result.history],
    )


def unmet_goals(figure: Figure, goals: Sequence, solution: PoseSolution) -> tuple[UnmetGoal, ...]:
    """The goals an unbatched solution leaves unmet, as data.

    Parameters
    ----------
    figure : Figure
    goals : sequence of PointGoal, PlaneGoal, AxisGoal
        As given to the solve.
    solution : PoseSolution
        Unbatched.

    Returns
    -------
    tuple of UnmetGoal
        In the order given; empty when every goal is met.
    """
    out = []
    for i, (g, ok, d) in enumerate(zip(goals, solution.met, solution.residuals)):
        if ok:
            continue
        link = figure.links[resolve_link(figure, g.link)[0]].label
        if isinstance(g, PointGoal):
            sentence = f"the point of {link} stays {d:.4g} from its target."
        elif isinstance(g, PlaneGoal):
            sentence = f"the point of {link} stays {d:.4g} from its plane."
        else:
            sentence = f"the axis of {link} stays {d:.3g} degrees from its direction."
        out.append(UnmetGoal(i, float(d), sentence))
    return tuple(out)


def _limit_sentence(solution: PoseSolution, unmet: Sequence[UnmetGoal]) -> str | None:
    """The sentence that says the iteration limit stopped a solve leaving ``unmet`` goals, or None."""
    if unmet and solution.status == SolveStatus.LIMIT:
        return f"the solver stopped at its iteration limit ({solution.iterations}) before settling."
    return None


def residual_warnings(figure: Figure, goals: Sequence, solution: PoseSolution) -> list[str]:
    """One sentence per goal an unbatched solution leaves unmet, for warnings.

    The text of :func:`unmet_goals` (and of :attr:`Reach.limit_warning`),
    for callers that want sentences; code that needs the goal's index or
    distance reads :class:`UnmetGoal` instead.  The parameters are those of
    :func:`unmet_goals`.

    Returns
    -------
    list of str
        E.g. ``"goal 2: the point of R_HAND stays 0.1231 from its target."``;
        when the iteration limit stopped the solve, a last sentence says so.
        Empty when every goal is met.
    """
    unmet = unmet_goals(figure, goals, solution)
    limit = _limit_sentence(solution, unmet)
    return [str(u) for u in unmet] + ([limit] if limit else [])


def _driven(figure: Figure, goals, movable, start, joints) -> list[int]:
    """The joints a goal-made motion drives, in the figure's joint order."""
    if joints is not None:
        ids = set()
        for jid in joints:
            figure.joint_index(jid)  # raises for an unknown joint
            ids.add(int(jid))
    else:
        mask = _movable_mask(figure, goals, movable)
        ids = {figure.joints[k].id for k in np.flatnonzero(mask.any(axis=1))}
        if isinstance(start, Motion):
            # The start motion's joints keep their final angles; driving them
            # keeps that true even when this motion is animated on its own.
            ids |= set(start.joints) & set(figure.joint_ids)
    return [jid for jid in figure.joint_ids if jid in ids]


def reach(
    figure: Figure,
    goals: Sequence,
    frames: float,
    method: str = "LINEAR",
    *,
    start=None,
    joints: Iterable[int] | None = None,
    options: ReachOptions | None = None,
    **fields,
) -> Reach:
    """A motion from a start pose to the pose that best meets the goals.

    Parameters
    ----------
    figure, goals, start, options, **fields
        As for :func:`solve_pose`; the goals must not be batched (see
        :func:`reach_keyframes`).
    frames : float
        The frame of the solved pose (the motion's length), ``>= 0``.
    method : str, default "LINEAR"
        The interpolation method from the start pose to the solved one.
    joints : iterable of int, optional
        The joints the motion drives.  Default: the movable joints, and,
        when ``start`` is a motion, the joints it drives (so that playing
        this motion alone still shows them in the start motion's final
        pose).

    Returns
    -------
    Reach
        ``motion`` has, for each driven joint, the start pose as its start
        value and one keyframe ``(frames, solved angles, method)``.  The
        root translation cannot live in a motion (motions hold angles), so
        it is ``Reach.translation``: apply it to the model with a host
        translation.  ``unmet`` lists the goals left unmet (unreachable
        goals are not an error), ``limit_warning`` says when the iteration
        limit stopped the solve short of them.

    Raises
    ------
    GoalError
        As :func:`solve_pose`; also for batched goals.
    MotionError
        For a negative frame count or an unknown method.
    """
    goals = list(goals)
    if batch_size(goals) is not None:
        raise GoalError("reach() takes unbatched goals; use reach_keyframes() for a batch.")
    o = reach_options(options, **fields)
    sol = solve_pose(figure, goals, start=start, options=o)
    s0 = start_pose(figure, start)
    driven = _driven(figure, goals, o.movable, start, joints)
    tracks = {}
    for jid in driven:
        k = figure.joint_index(jid)
        tracks[jid] = (tuple(s0[k]), [Keyframe(frames, tuple(sol.angles[k]), method)])
    return Reach(Motion.from_tracks(tracks, name="REACH"), sol, tuple(driven), unmet_goals(figure, goals, sol))


def reach_keyframes(
    figure: Figure,
    goals: Sequence,
    frames: Sequence[float],
    method: str = "LINEAR",
    *,
    start=None,
    joints: Iterable[int] | None = None,
    options: ReachOptions | None = None,
    **fields,
) -> Reach:
    """One motion through the solutions of a batch of goals (a moving target).

    The ``B`` solves are independent, all from the start pose, and done as
    one batch; the motion has keyframe ``i`` at ``frames[i]`` with solution
    ``i``.

    Parameters
    ----------
    figure, goals, start, joints, options, **fields
        As for :func:`reach`; the goals carry a batch dimension ``B``.
    frames : sequence of float, length B
        Non-decreasing keyframe frames.
    method : str, default "LINEAR"

    Returns
    -------
    Reach
        Its ``solution`` is batched: ``translation`` has shape (B, 3), one
        per keyframe (apply them with a host translation per frame).
    """
    goals = list(goals)
    frames = [float(f) for f in frames]
    B = batch_size(goals)
    if B is None:
        B = 1
    if len(frames) != B:
        raise GoalError(f"{len(frames)} keyframe frames for a batch of {B} goals.")
    s0 = start_pose(figure, start)
    if s0.ndim == 3:
        raise GoalError("reach_keyframes() starts every solve from one pose; give an unbatched start.")
    o = reach_options(options, **fields)
    sol = solve_pose(figure, goals, start=np.broadcast_to(s0, (B,) + s0.shape), options=o)
    driven = _driven(figure, goals, o.movable, start, joints)
    tracks = {}
    for jid in driven:
        k = figure.joint_index(jid)
        tracks[jid] = (tuple(s0[k]), [Keyframe(f, tuple(sol.angles[i, k]), method) for i, f in enumerate(frames)])
    return Reach(Motion.from_tracks(tracks, name="REACH"), sol, tuple(driven))
