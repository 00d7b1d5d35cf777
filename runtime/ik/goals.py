"""Goals for goal-directed positioning: what they ask, their residuals and Jacobians.

Three kinds of goal put a part of a figure somewhere in the world
(``docs/semantics-ik.md`` has the formulas):

* :class:`PointGoal` -- a point of a link onto a world point;
* :class:`PlaneGoal` -- a point of a link onto a world plane;
* :class:`AxisGoal` -- a direction fixed in a link along a world direction.

Each has a weight.  As in Badler, Manoochehri and Walters' POSIT only the
ratios of the weights matter, and a weight of 0 switches a goal off: the
solvers minimise ``sum_i w_i |r_i|^2 / max_j w_j``.

Targets, plane data, directions and weights may carry a leading batch
dimension ``B`` (many independent solves of the same goal structure, e.g. a
moving target); :class:`GoalStack` packs a list of goals into arrays and
evaluates every residual and its analytic Jacobian for the whole batch at
once.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure.tree import Figure
from liganimate.runtime.ik.model import IKModel, cross3, matvec3

__all__ = [
    "GoalError",
    "PointGoal",
    "PlaneGoal",
    "AxisGoal",
    "GoalStack",
    "resolve_link",
    "batch_size",
]


class GoalError(LigError):
    """A goal that cannot be posed: an unknown link, a zero normal or direction, a negative weight."""


@dataclass(frozen=True)
class PointGoal:
    """Put a point of a link onto a world point.

    Parameters
    ----------
    link : str or int
        The link: a name (case-insensitive; with several links of that name,
        the first met depth first, as FIGURE ... MAIN LINK chooses) or an
        index into ``figure.links``.
    target : array_like, shape (3,) or (B, 3)
        The world point.
    point : array_like, shape (3,), default (0, 0, 0)
        The point in the link's own coordinates (those of its shape, so a
        SCALE MODEL keeps it on the same spot of the segment).
    weight : float or array_like of shape (B,), default 1
        Non-negative; 0 switches the goal off.
    """

    link: str | int
    target: object
    point: object = (0.0, 0.0, 0.0)
    weight: object = 1.0


@dataclass(frozen=True)
class PlaneGoal:
    """Put a point of a link onto a world plane.

    Parameters
    ----------
    link : str or int
        As for :class:`PointGoal`.
    origin : array_like, shape (3,) or (B, 3)
        A point of the plane.
    normal : array_like, shape (3,) or (B, 3)
        The plane's normal (any non-zero length).
    point : array_like, shape (3,), default (0, 0, 0)
        The point in the link's own coordinates.
    weight : float or array_like of shape (B,), default 1
    """

    link: str | int
    origin: object
    normal: object
    point: object = (0.0, 0.0, 0.0)
    weight: object = 1.0


@dataclass(frozen=True)
class AxisGoal:
    """Turn a direction fixed in a link onto a world direction.

    Parameters
    ----------
    link : str or int
        As for :class:`PointGoal`.
    axis : array_like, shape (3,)
        The direction in the link's own coordinates (any non-zero length).
    direction : array_like, shape (3,) or (B, 3)
        The world direction (any non-zero length).
    weight : float or array_like of shape (B,), default 1

    Notes
    -----
    Its residual is the chord between the two unit vectors times the link's
    length (:func:`ikmodel.link_lengths`; the mean link length for a link
    of length 0), so an axis goal weighs like a point goal at the link's far
    end, and the solve does not change when the figure is scaled.
    """

    link: str | int
    axis: object
    direction: object
    weight: object = 1.0


Goal = PointGoal | PlaneGoal | AxisGoal


def resolve_link(figure: Figure, ref) -> tuple[int, str | None]:
    """The index of the link a goal names.

    Parameters
    ----------
    figure : Figure
    ref : str or int
        A link name (case-insensitive) or an index into ``figure.links``.

    Returns
    -------
    index : int
    warning : str or None
        When several links bear the name: which one was taken (the first met
        depth first from the original main link, as FIGURE ... MAIN LINK
        does) and which joints attach the others.

    Raises
    ------
    GoalError
        For an unknown name or an index out of range.
    """
    if isinstance(ref, str):
        found = figure.links_named(ref)
        if not found:
            names = sorted({l.name.upper() for l in figure.links if l.name is not None})
            raise GoalError(
                f"the model has no link named {ref}.", hint=f"its links are named {', '.join(names) or 'nothing'}"
            )
        warning = None
        if len(found) > 1:
            others = ", ".join(str(j.id) for i in found[1:] if (j := figure.parent_joint_of(i)) is not None)
            up = figure.parent_joint_of(found[0])
            which = "the original main link" if up is None else f"the one attached by joint {up.id}"
            warning = (
                f"{len(found)} links are named {ref}; the goal uses {which}, the first met depth first "
                f"(the others are attached by joint {others})."
            )
        return found[0], warning
    if isinstance(ref, bool) or not isinstance(ref, (int, np.integer)):
        raise GoalError(f"a goal's link must be a link name or a link number, not {ref!r}.")
    if not 0 <= int(ref) < figure.n_links:
        raise GoalError(f"the model has no link number {int(ref)}; it has links 0 to {figure.n_links - 1}.")
    return int(ref), None


def _vectors(value, what: str, batch: int | None) -> np.ndarray:
    """``value`` as finite vectors of shape (3,) or (B, 3)."""
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise GoalError(f"{what} must be a vector of three numbers, not {value!r}.") from None
    if v.shape[-1:] != (3,) or v.ndim > 2:
        raise GoalError(
            f"{what} must be a vector of three numbers (or a batch of them), not an array of shape {v.shape}."
        )
    if not np.isfinite(v).all():
        raise GoalError(f"{what} must be finite.")
    return v


def _unit(v: np.ndarray, what: str) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    if np.any(n == 0.0):
        raise GoalError(f"{what} must not be the zero vector.")
    return v / n


def _weights(value, what: str) -> np.ndarray:
    if type(value) is float and 0.0 <= value < math.inf:
        # The usual case, checked without numpy's calls (a single solve pays for each).
        return np.array(value)
    try:
        w = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise GoalError(f"{what} must be a number, not {value!r}.") from None
    if w.ndim > 1 or not np.all(np.isfinite(w)):
        raise GoalError(f"{what} must be a finite number (or a batch of them).")
    if np.any(w < 0):
        raise GoalError(
            f"{what} must not be negative.", hint="only the ratios of weights matter; 0 switches a goal off"
        )
    return w


def _batched(v: np.ndarray, shape: tuple) -> np.ndarray:
    """``np.broadcast_to(v, shape)``; an unbatched value for a batch of one is only given its axis.

    A single solve builds its goals on every call, and broadcast_to's
    checks cost more than the rest of a goal's packing.
    """
    if shape[0] == 1 and v.ndim == len(shape) - 1:
        return v[None]
    return np.broadcast_to(v, shape)


def batch_size(goals: Sequence[Goal]) -> int | None:
    """The batch size the goals' data imply (None when nothing is batched).

    Parameters
    ----------
    goals : sequence of PointGoal, PlaneGoal or AxisGoal

    Returns
    -------
    int or None
        The common leading size of every batched target, plane, direction
        (shape (B, 3)) and weight (shape (B,)).

    Raises
    ------
    GoalError
        If a goal is of no known kind, or two batched values disagree on
        the size.
    """
    batched_fields = {
        PointGoal: ("target", "weight"),
        PlaneGoal: ("origin", "normal", "weight"),
        AxisGoal: ("direction", "weight"),
    }
    sizes = set()
    for i, g in enumerate(goals):
        fields = batched_fields.get(type(g))
        if fields is None:
            raise GoalError(f"goal {i + 1} is not a point, plane or axis goal.")
        for f in fields:
            v = np.asarray(getattr(g, f))
            if (f == "weight" and v.ndim == 1) or (f != "weight" and v.ndim == 2):
                sizes.add(v.shape[0])
    if len(sizes) > 1:
        raise GoalError(f"the goals' batched values disagree on the batch size ({', '.join(map(str, sorted(sizes)))}).")
    return sizes.pop() if sizes else None


# (a x b)_i = eps_ijk a_j b_k.
_LEVI_CIVITA = np.zeros((3, 3, 3))
_LEVI_CIVITA[0, 1, 2] = _LEVI_CIVITA[1, 2, 0] = _LEVI_CIVITA[2, 0, 1] = 1.0
_LEVI_CIVITA[0, 2, 1] = _LEVI_CIVITA[2, 1, 0] = _LEVI_CIVITA[1, 0, 2] = -1.0


def _gathered(model: IKModel, goals: tuple, B: int, warnings: list) -> tuple[dict, dict, dict]:
    """The goals sorted by kind (point, plane, axis), each field a list in the user's order within its kind.

    Warnings (an ambiguous link name) are appended to ``warnings``.

    Raises
    ------
    GoalError
        As :class:`GoalStack`.
    """
    scale = model.link_scale
    pts: dict[str, list] = {"link": [], "local": [], "target": [], "w": [], "index": []}
    pls: dict[str, list] = {"link": [], "local": [], "origin": [], "normal": [], "w": [], "index": []}
    axs: dict[str, list] = {"link": [], "local": [], "dir": [], "ell": [], "w": [], "index": []}
    mean_length = None  # only axis goals need it
    for i, g in enumerate(goals):
        if not isinstance(g, (PointGoal, PlaneGoal, AxisGoal)):
            raise GoalError(f"goal {i + 1} is not a point, plane or axis goal.")
        what = f"goal {i + 1}"
        link, warning = resolve_link(model.figure, g.link)
        if warning:
            warnings.append(f"{what}: {warning}")
        w = _batched(_weights(g.weight, f"the weight of {what}"), (B,))
        if isinstance(g, AxisGoal):
            a = _vectors(g.axis, f"the axis of {what}", None)
            if a.ndim != 1:
                raise GoalError(f"the axis of {what} is a direction in the link and cannot be batched.")
            # A mirrored link (negative scale) turns its own directions round.
            axs["local"].append(_unit(a, f"the axis of {what}") * np.sign(scale[link]))
            axs["dir"].append(
                _batched(
                    _unit(_vectors(g.direction, f"the direction of {what}", B), f"the direction of {what}"), (B, 3)
                )
            )
            ell = model.lengths[link]
            if mean_length is None:
                positive = model.lengths[model.lengths > 0]
                mean_length = float(positive.mean()) if positive.size else model.length
            axs["ell"].append(ell if ell > 0 else mean_length)
            d = axs
        else:
            point = _vectors(g.point, f"the link point of {what}", None)
            if point.ndim != 1:
                raise GoalError(f"the link point of {what} cannot be batched.")
            local = point * scale[link]  # shape coordinates to link frame
            if isinstance(g, PointGoal):
                pts["target"].append(_batched(_vectors(g.target, f"the target of {what}", B), (B, 3)))
                d = pts
            else:
                pls["origin"].append(_batched(_vectors(g.origin, f"the plane point of {what}", B), (B, 3)))
                pls["normal"].append(
                    _batched(
                        _unit(_vectors(g.normal, f"the plane normal of {what}", B), f"the plane normal of {what}"),
                        (B, 3),
                    )
                )
                d = pls
            d["local"].append(local)
        d["link"].append(link)
        d["w"].append(w)
        d["index"].append(i)
    return pts, pls, axs


_STACKS: dict = {}  # (id(model), structure) -> (model, GoalStack); the stored model keeps the id valid
_STACKS_MAX = 256


def _structure(goals: Sequence, batch: int) -> tuple | None:
    """What a :class:`GoalStack` packs besides the targets, as a key; None when it cannot serve as one.

    Each goal's kind, link, link point or axis and weight, the latter as a
    plain number (a batch of weights, or anything else, is packed afresh).
    """
    parts: list = [int(batch)]
    for g in goals:
        if type(g) not in (PointGoal, PlaneGoal, AxisGoal):
            return None
        w = g.weight
        if type(w) not in (float, int) or isinstance(w, bool):
            return None
        local = g.axis if isinstance(g, AxisGoal) else g.point
        if type(local) is not tuple or len(local) != 3 or any(type(x) not in (float, int) for x in local):
            return None
        link = g.link
        if type(link) not in (str, int):
            return None
        parts.append((type(g), link, local, w))
    return tuple(parts)


class GoalStack:
    """A list of goals packed into arrays, evaluated for a batch of poses.

    Parameters
    ----------
    model : IKModel
    goals : sequence of PointGoal, PlaneGoal or AxisGoal
    batch : int
        ``B``; every goal value is broadcast to it.

    Attributes
    ----------
    n_goals : int
    n_rows : int
        ``M``: 3 per point goal, 1 per plane goal, 3 per axis goal.
    weights : numpy.ndarray, shape (B, n_goals)
        As given, in the order of ``goals``.
    warnings : list of str
        Ambiguous link names (see :func:`resolve_link`).

    Raises
    ------
    GoalError
        For an unknown link, a malformed vector, a zero normal, axis or
        direction, or a negative weight.
    """

    def __init__(self, model: IKModel, goals: Sequence[Goal], batch: int):
        self.model = model
        B = int(batch)
        self.batch = B
        self.goals = tuple(goals)
        self.warnings: list[str] = []
        pts, pls, axs = _gathered(model, self.goals, B, self.warnings)

        def stack(lst, shape):
            return np.stack(lst, axis=1) if lst else np.zeros(shape)

        self.p_link = np.array(pts["link"], dtype=np.intp)
        self.p_local = np.array(pts["local"]).reshape(-1, 3)
        self.p_target = stack(pts["target"], (B, 0, 3))
        self.q_link = np.array(pls["link"], dtype=np.intp)
        self.q_local = np.array(pls["local"]).reshape(-1, 3)
        self.q_origin = stack(pls["origin"], (B, 0, 3))
        self.q_normal = stack(pls["normal"], (B, 0, 3))
        self.h_link = np.array(axs["link"], dtype=np.intp)
        self.h_local = np.array(axs["local"]).reshape(-1, 3)
        self.h_dir = stack(axs["dir"], (B, 0, 3))
        self.h_ell = np.array(axs["ell"], dtype=float)
        G, Q, H = len(self.p_link), len(self.q_link), len(self.h_link)
        self.n_goals = G + Q + H
        self.n_rows = 3 * G + Q + 3 * H
        # Goal order: points, planes, axes; ``order`` maps it back to the user's.
        self.order = np.array(pts["index"] + pls["index"] + axs["index"], dtype=np.intp)
        w_packed = stack(pts["w"] + pls["w"] + axs["w"], (B, 0))
        self.weights = np.empty_like(w_packed)
        self.weights[:, self.order] = w_packed
        wmax = w_packed.max(axis=1, keepdims=True) if self.n_goals else np.zeros((B, 1))
        # Only ratios matter: normalising by the largest weight makes the
        # cost, and so the damping and stopping rules, independent of the
        # weights' overall size.
        wn = np.divide(w_packed, wmax, out=np.zeros_like(w_packed), where=wmax > 0)
        self._active_packed = wn > 0
        rows_per_goal = np.array([3] * G + [1] * Q + [3] * H, dtype=np.intp)
        self.row_weight = np.repeat(np.sqrt(wn), rows_per_goal, axis=1)  # (B, M)
        moved_by = model.moved_by  # (n_links, V), as floats
        self._downstream_p = moved_by[self.p_link]  # (G, V)
        self._downstream_q = moved_by[self.q_link]
        self._downstream_h = moved_by[self.h_link]
        # For evaluate_one: point goals only (then the packed order is the
        # user's), and their link points in homogeneous coordinates.
        self._points_only = Q == 0 and H == 0
        self._unit_rows = B == 1 and bool(np.all(self.row_weight == 1.0))
        self._p_local_h = np.concatenate((self.p_local, np.ones((G, 1))), axis=1)[:, :, None]
        # What other modules derive from this packing (runtime/ik/entrywise.py's
        # float goals): shared with the re-targeted copies of
        # :meth:`_with_targets`, not with the sub-batches of :meth:`take`.
        self.memo: dict = {}

    @classmethod
    def cached(cls, model: IKModel, goals: Sequence[Goal], batch: int) -> GoalStack:
        """A :class:`GoalStack`, reusing the packing of the same goals on the same model.

        A script that solves one figure again and again (STARTREACH in a DO
        loop, a batch of single solves) asks for the same links, link points,
        axes and weights each time, and only the targets change.  Resolving
        the links and packing the weights and Jacobian masks is done once per
        such set of goals (remembered for the last :data:`_STACKS_MAX` sets);
        the targets, planes and directions are checked and packed on every
        call, exactly as the constructor does.  Goals whose weight is a
        batch, or any other value than a number, are packed afresh.

        Parameters, returns and raises as the constructor.
        """
        key = _structure(goals, batch)
        if key is None:
            return cls(model, goals, batch)
        key = (id(model),) + key
        hit = _STACKS.get(key)
        if hit is None or hit[0] is not model:
            stack = cls(model, goals, batch)
            if len(_STACKS) >= _STACKS_MAX:
                _STACKS.clear()
            _STACKS[key] = (model, stack)
            return stack
        return hit[1]._with_targets(tuple(goals))

    def _with_targets(self, goals: tuple) -> GoalStack:
        """This packing with the targets, plane points, normals and directions of ``goals`` (same structure)."""
        B = self.batch
        pts: list = []
        origins: list = []
        normals: list = []
        dirs: list = []
        for i, g in enumerate(goals):
            what = f"goal {i + 1}"
            if isinstance(g, PointGoal):
                pts.append(_batched(_vectors(g.target, f"the target of {what}", B), (B, 3)))
            elif isinstance(g, PlaneGoal):
                origins.append(_batched(_vectors(g.origin, f"the plane point of {what}", B), (B, 3)))
                n = _vectors(g.normal, f"the plane normal of {what}", B)
                normals.append(_batched(_unit(n, f"the plane normal of {what}"), (B, 3)))
            else:
                d = _vectors(g.direction, f"the direction of {what}", B)
                dirs.append(_batched(_unit(d, f"the direction of {what}"), (B, 3)))
        out = object.__new__(GoalStack)
        out.__dict__.update(self.__dict__)
        out.goals = goals
        out.warnings = list(self.warnings)
        # One point goal (a reach): its (B, 3) targets given their goal axis, without np.stack's checks.
        out.p_target = (pts[0][:, None] if len(pts) == 1 else np.stack(pts, axis=1)) if pts else self.p_target
        if origins:
            out.q_origin, out.q_normal = np.stack(origins, axis=1), np.stack(normals, axis=1)
        if dirs:
            out.h_dir = np.stack(dirs, axis=1)
        return out

    # ------------------------------------------------------------ batches

    def take(self, idx: np.ndarray) -> GoalStack:
        """The same goals for the batch elements ``idx`` only.

        Parameters
        ----------
        idx : numpy.ndarray of int, shape (B',)
            Sorted and without repeats.

        Returns
        -------
        GoalStack
            Sharing every unbatched array with this one.
        """
        if len(idx) == self.batch:
            return self  # every element, in order: the sub-batches are sorted and unique
        out = object.__new__(GoalStack)
        out.__dict__.update(self.__dict__)
        out.batch = len(idx)
        out.memo = {}
        for name in ("p_target", "q_origin", "q_normal", "h_dir", "weights", "_active_packed", "row_weight"):
            setattr(out, name, getattr(self, name)[idx])
        return out

    @property
    def active(self) -> np.ndarray:
        """Which goals count, shape (B, n_goals), in the user's order (weight above 0)."""
        out = np.empty_like(self._active_packed)
        out[:, self.order] = self._active_packed
        return out

    # ------------------------------------------------------------ evaluation

    def _link_points(self, R, p, links, local):
        return p[:, links] + matvec3(R[:, links], local)

    def evaluate(self, R, p, t, omega=None, c=None):
        """Weighted residuals, their Jacobian and each goal's distance.

        Parameters
        ----------
        R, p : numpy.ndarray, shapes (B, n_links, 3, 3) and (B, n_links, 3)
            Link frames from :meth:`IKModel.forward`.
        t : numpy.ndarray, shape (B, 3), or None
            Root translation (world), when translating.
        omega, c : numpy.ndarray, shape (B, V, 3), optional
            Variable axes and pivots from :meth:`IKModel.axes`; without
            them no Jacobian is computed.

        Returns
        -------
        r : numpy.ndarray, shape (B, M)
            Residual rows, each times the square root of its goal's
            normalised weight; the solvers minimise ``|r|^2 / 2``.
        jac : numpy.ndarray, shape (B, M, n_params), or None
            ``dr/dq``: per radian for angle variables, per figure length
            for the translation variables (which are the translation over
            :attr:`IKModel.length`).
        dist : numpy.ndarray, shape (B, n_goals)
            Unweighted, in the user's goal order: a point goal's distance,
            a plane goal's absolute signed distance, an axis goal's angle
            in radians times its length scale.  The tolerance applies to it.
        """
        B = R.shape[0]
        want_j = omega is not None
        rows, jacs, dists = [], [], []
        kinds = (
            (self.p_link, self._point_rows),
            (self.q_link, self._plane_rows),
            (self.h_link, self._axis_rows),
        )
        for links, rows_of in kinds:
            if len(links):
                row, jac_rows, dist_rows = rows_of(R, p, t, omega, c)
                rows.append(row)
                dists.append(dist_rows)
                if want_j:
                    jacs.append(jac_rows)
        Pn = self.model.n_params
        r = np.concatenate(rows, axis=1) if rows else np.zeros((B, 0))
        r = r * self.row_weight
        jac = None
        if want_j:
            jac = np.concatenate(jacs, axis=1) if jacs else np.zeros((B, 0, Pn))
            jac = jac * self.row_weight[:, :, None]
        packed = np.concatenate(dists, axis=1) if dists else np.zeros((B, 0))
        dist = np.empty_like(packed)
        dist[:, self.order] = packed
        return r, jac, dist

    def _point_rows(self, R, p, t, omega, c):
        """Point goals: residual rows (B, 3G), Jacobian rows (B, 3G, n_params) or None, distances (B, G)."""
        m = self.model
        B, V, Pn = R.shape[0], m.n_vars, m.n_params
        y = self._link_points(R, p, self.p_link, self.p_local)  # (B, G, 3)
        res = m.to_world(y, t) - self.p_target
        row = res.reshape(B, 3 * len(self.p_link))
        dist = np.sqrt(np.einsum("bgi,bgi->bg", res, res))
        if omega is None:
            return row, None, dist
        Jw = self._point_jacobian(y, omega, c, self._downstream_p)  # (B, G, 3, V)
        Jp = np.zeros(Jw.shape[:3] + (Pn,))
        Jp[..., :V] = Jw
        if m.translate:
            Jp[..., V:] = np.eye(3) * m.length
        return row, Jp.reshape(B, 3 * len(self.p_link), Pn), dist

    def _plane_rows(self, R, p, t, omega, c):
        """Plane goals: signed distances as rows (B, Q), their Jacobian (B, Q, n_params) or None, |distance|."""
        m = self.model
        B, V, Pn = R.shape[0], m.n_vars, m.n_params
        y = self._link_points(R, p, self.q_link, self.q_local)
        n = self.q_normal
        s = np.einsum("bqi,bqi->bq", n, m.to_world(y, t) - self.q_origin)
        if omega is None:
            return s, None, np.abs(s)
        Jw = self._point_jacobian(y, omega, c, self._downstream_q)  # (B, Q, 3, V)
        Jq = np.zeros((B, len(self.q_link), Pn))
        Jq[..., :V] = np.einsum("bqi,bqiv->bqv", n, Jw)
        if m.translate:
            Jq[..., V:] = n * m.length
        return s, Jq, np.abs(s)

    def _axis_rows(self, R, p, t, omega, c):
        """Axis goals: rows (B, 3H), Jacobian rows (B, 3H, n_params) or None, angles times length (B, H)."""
        m = self.model
        B, V, Pn = R.shape[0], m.n_vars, m.n_params
        vm = matvec3(R[:, self.h_link], self.h_local)  # model frame
        vw = m.to_world_vectors(vm)
        nv = np.linalg.norm(vw, axis=-1, keepdims=True)
        u = vw / nv
        ell = self.h_ell[:, None]
        diff = u - self.h_dir
        row = (diff * ell).reshape(B, 3 * len(self.h_link))
        chord = np.linalg.norm(diff, axis=-1)
        dist = 2.0 * np.arcsin(np.minimum(chord / 2.0, 1.0)) * self.h_ell
        if omega is None:
            return row, None, dist
        dv = cross3(omega[:, None], vm[:, :, None]) * self._downstream_h[None, :, :, None]  # (B, H, V, 3)
        dv = m.to_world_vectors(dv)
        # d(v/|v|) = (I - u u^T) dv / |v|
        du = (dv - u[:, :, None] * np.einsum("bhi,bhvi->bhv", u, dv)[..., None]) / nv[:, :, None]
        Jh = np.zeros((B, len(self.h_link), 3, Pn))
        Jh[..., :V] = np.swapaxes(du, -1, -2) * self.h_ell[None, :, None, None]
        return row, Jh.reshape(B, 3 * len(self.h_link), Pn), dist

    def evaluate_one(self, X, t, omega, c):
        """:meth:`evaluate` with the Jacobian, for a batch of one, from 4x4 link transforms.

        Parameters
        ----------
        X : numpy.ndarray, shape (n_links, 4, 4)
            From :meth:`IKModel.forward_one`.
        t : numpy.ndarray, shape (3,), or None
        omega, c : numpy.ndarray, shape (V, 3)

        Returns
        -------
        r : numpy.ndarray, shape (M,)
        jac : numpy.ndarray, shape (M, n_params)
        dist : numpy.ndarray, shape (n_goals,)

        Notes
        -----
        Point goals alone (what a reach asks) are evaluated here in a few
        numpy calls on (G, V, 3) arrays; plane and axis goals go through
        :meth:`evaluate` with a batch dimension of one.
        """
        m = self.model
        if not self._points_only:
            R, p = X[None, :, :3, :3], X[None, :, :3, 3]
            r, jac, dist = self.evaluate(R, p, None if t is None else t[None], omega[None], c[None])
            return r[0], jac[0], dist[0]
        V = m.n_vars
        y = (X[self.p_link] @ self._p_local_h)[:, :3, 0]  # (G, 3), model frame
        res = m.to_world(y[None], None if t is None else t[None])[0] - self.p_target[0]
        d = y[:, None, :] - c  # (G, V, 3)
        # omega x d, straight into the Jacobian's (G, 3, V) layout: one
        # einsum with the Levi-Civita symbol costs less than cross3's views
        # and stack on arrays this small (and adds the same two products).
        v = np.einsum("ijk,vj,gvk->giv", _LEVI_CIVITA, omega, d) * self._downstream_p[:, None, :]
        if not m.placement_is_identity:
            v = np.einsum("ij,gjv->giv", m.A, v)
        G = len(self.p_link)
        if m.translate:
            jac = np.zeros((G, 3, m.n_params))
            jac[..., :V] = v
            jac[..., V:] = np.eye(3) * m.length
            jac = jac.reshape(3 * G, -1)
        else:
            jac = v.reshape(3 * G, V)
        r = res.reshape(-1)
        dist = np.sqrt((res * res).sum(axis=1))
        if self._unit_rows:
            return r, jac, dist  # every weight the largest: multiplying by 1 changes nothing
        w = self.row_weight[0]
        return r * w, jac * w[:, None], dist

    def _point_jacobian(self, y, omega, c, down):
        """World velocity of link points per radian of each variable, shape (B, N, 3, V)."""
        # A point y moved by a variable turns about the variable's axis
        # through its pivot: dy = omega x (y - c), zero if it does not move.
        d = y[:, :, None, :] - c[:, None, :, :]  # (B, N, V, 3)
        v = cross3(omega[:, None], d) * down[None, :, :, None]
        v = self.model.to_world_vectors(v)
        return np.swapaxes(v, -1, -2)

    def report(self, dist: np.ndarray) -> np.ndarray:
        """Each goal's residual in its natural unit, for messages.

        Parameters
        ----------
        dist : numpy.ndarray, shape (B, n_goals)
            Distances from :meth:`evaluate`.

        Returns
        -------
        numpy.ndarray, shape (B, n_goals)
            In the user's goal order: a point goal's distance to its target
            and a plane goal's distance to its plane (world units), an axis
            goal's angle to its direction in degrees.
        """
        out = np.array(dist, dtype=float)
        if len(self.h_link):
            cols = self.order[len(self.p_link) + len(self.q_link) :]
            out[:, cols] = np.rad2deg(out[:, cols] / self.h_ell)
        return out
