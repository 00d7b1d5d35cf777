"""Batched solvers for goal-directed positioning: damped least squares, Jacobian transpose, CCD.

All three minimise the same weighted cost of a :class:`goals.GoalStack`,

    f(x) = |r(x)|^2 / 2,     lower <= angles <= upper,

over the variables ``x`` of an :class:`ikmodel.IKModel` (angles in radians,
then the root translation divided by the figure's length when it may
translate), for a batch of ``B`` independent problems at once.  Every
iterate is projected into the joint limits, and a step is only kept when it
lowers ``f``, so the cost never rises: no iterate exceeds a limit, and an
unreachable goal ends at a (local) least-squares best pose instead of
oscillating.  ``docs/semantics-ik.md`` gives the formulas and the stopping
rules.

* ``"dls"`` -- damped least squares (Levenberg-Marquardt): the step solves
  ``(J^T J + mu I) dx = -J^T r`` with the damping ``mu`` adapted by the gain
  ratio (Nielsen's rule), no angle moving more than MAXSTEP per step,
  variables held at a limit they push against.
* ``"transpose"`` -- the Jacobian transpose (seed 000's choice): a step along
  ``-J^T r`` of Buss's length ``|g|^2 / |J g|^2``, halved while it fails.
* ``"ccd"`` -- cyclic coordinate descent: each variable in turn, from the
  figure's extremities toward the main link, is set to the exact minimiser
  of ``f`` along its own axis within its limits; then the translation.

The batch elements that have stopped are dropped from the arrays, so a batch
costs what its slowest member costs, with numpy doing the rest.  Restarts
(from random angles, for solves stuck in a local minimum) run inside the
same loop as the other elements' iterations, so they cost little more than
the iterations they take.

The stopping, damping and progress rules are written once (the functions
under "the rules"), for Python scalars and arrays alike; :class:`_State`
owns restarts, resuming and the final choice of attempt for every loop,
including the single-solve DLS loop (:func:`_dls_one`).  :data:`SOLVERS`, at
the end, is the one table of solvers: a new solver is its loop and one
entry there.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np

from .entrywise import (
    Kernel,  # numpy only
    batch_evaluator,
    solve3,
)
from .entrywise import kernel as float_kernel
from .names import DEFAULT_SOLVER, SOLVER_KEYWORDS  # the names alone live there, for the compiler and the host

if TYPE_CHECKING:
    # Only for annotations: importing this module loads numpy and nothing
    # else of the runtime.
    from liganimate.runtime.ik.goals import GoalStack
    from liganimate.runtime.ik.model import IKModel

__all__ = [
    "Solver",
    "SOLVERS",
    "SOLVER_NAMES",
    "SOLVER_KEYWORDS",
    "DEFAULT_SOLVER",
    "SolveResult",
    "solve",
    "CONVERGED",
    "STALLED",
    "LIMIT",
]


# Status codes per batch element.
RUNNING, CONVERGED, STALLED, LIMIT = 0, 1, 2, 3

# A step that lowers the cost by less than this fraction of it, or whose
# length is less than XTOL times (XTOL + the variables' length), means the
# solve has stopped making progress: it is at a least-squares best pose.
# These are MINPACK's and scipy's defaults (about sqrt(machine epsilon)).
FTOL = 1e-8
XTOL = 1e-8
# Damping beyond this multiple of the largest curvature means no step can
# lower the cost any more.
MU_MAX = 1e16
# Progress window: see _State.end_iteration.
WINDOW = 10
WINDOW_FTOL = 1e-6
# Giving up early, only while restarts remain: from GIVEUP_FROM iterations
# on, every GIVEUP_EVERY iterations, an attempt whose cost has not halved and
# is still above GIVEUP_FLOOR times the cost of goals at the tolerance is
# heading for a local minimum; it makes way for a restart, and is resumed if
# every restart fails (see _State.end_iteration).
GIVEUP_FROM = 8
GIVEUP_EVERY = 4
GIVEUP_FLOOR = 100.0
# DLS: the first damping, as a fraction of the largest diagonal entry of
# J^T J, and the largest angle (radians) any variable turns in one step.
# The cap is a trust region: it keeps each step where the linearisation
# holds and stops early steps from slamming joints into their limits,
# which is where most local minima are (it doubled the success of
# unrestarted solves on the benchmark's limited chains).
MU0 = 1e-1
MAXSTEP = 0.8
# Up to this many trials at once, the Jacobian is computed with the residuals.
SMALL_BATCH = 4


@dataclass
class SolveResult:
    """What a batched solve returns.

    Attributes
    ----------
    x : numpy.ndarray, shape (B, n_params)
        Final variables: angles in radians, then the translation over the
        figure's length.
    status : numpy.ndarray of int, shape (B,)
        :data:`CONVERGED` (every active goal within tolerance),
        :data:`STALLED` (no step lowers the cost: a least-squares best pose)
        or :data:`LIMIT` (the iteration limit came first).
    iterations : numpy.ndarray of int, shape (B,)
        Iterations (DLS, transpose) or sweeps (CCD) used.
    cost : numpy.ndarray, shape (B,)
        Final ``f``.
    dist : numpy.ndarray, shape (B, n_goals)
        Final per-goal distances (see :meth:`GoalStack.evaluate`).
    history : list of numpy.ndarray, each shape (B,)
        ``f`` before the first iteration and after each one, when traced.
    """

    x: np.ndarray
    status: np.ndarray
    iterations: np.ndarray
    cost: np.ndarray
    dist: np.ndarray
    history: list = field(default_factory=list)


class _Problem:
    """The pieces every solver needs: evaluation of a sub-batch at given variables."""

    def __init__(self, model: IKModel, stack: GoalStack, base: np.ndarray):
        self.model = model
        self.stack = stack
        self.base = base
        # Every variable's bounds (the translation's infinite): read-only, the model's.
        self.lower, self.upper = model.param_lower, model.param_upper

    # The start angles' trigonometry, made when first asked for: a single
    # solve in floats needs neither (runtime/ik/entrywise.py).

    @functools.cached_property
    def base_cos(self) -> np.ndarray:
        """Cosines of the start angles, (1 or B, J * 3): an unbatched start pose is shared, not copied B times."""
        return np.cos(self.base.reshape(self.base.shape[0], -1))

    @functools.cached_property
    def base_sin(self) -> np.ndarray:
        """Sines of the start angles, as :attr:`base_cos`."""
        return np.sin(self.base.reshape(self.base.shape[0], -1))

    @functools.cached_property
    def base_cs(self) -> np.ndarray | None:
        """For :meth:`one` (a batch of one): the start angles' cosines and sines laid out per joint."""
        return self.model.cos_sin_base(self.base[0]) if self.base.shape[0] == 1 else None

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        V = self.model.n_vars
        t = x[:, V:] * self.model.length if self.model.translate else None
        return x[:, :V], t

    def frames(self, idx, x):
        """Cosines and sines of the angles, and link frames, of sub-batch ``idx`` at ``x``."""
        q, t = self.split(x)
        shared = self.base_cos.shape[0] == 1
        bc = self.base_cos if shared else self.base_cos[idx]
        bs = self.base_sin if shared else self.base_sin[idx]
        c, s = self.model.trig(q, bc, bs)
        R, p = self.model.forward_trig(c, s)
        return (c, s), R, p, t

    def one(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Residuals ``(M,)``, Jacobian ``(M, P)`` and distances ``(n_goals,)`` of a batch of one at ``x (P,)``.

        The same values as :meth:`evaluate`, through the one-pose
        kinematics (:meth:`IKModel.forward_one`), which take a fraction of
        the numpy calls.
        """
        model = self.model
        V = model.n_vars
        t = x[V:] * model.length if model.translate else None
        assert self.base_cs is not None, "one() is only called on a batch of one start pose"
        X, omega, pivot = model.forward_one(model.cos_sin_one(x[:V], self.base_cs))
        return self.stack.evaluate_one(X, t, omega, pivot)

    @functools.cached_property
    def walked(self) -> Callable | None:
        """The entry-by-entry evaluation of a batch (:func:`entrywise.batch_evaluator`), or None."""
        return batch_evaluator(self)

    def evaluate(self, idx, stack, x, jac=True):
        """``r (B', M)``, ``J (B', M, P)`` or None, ``dist (B', n_goals)``."""
        if self.walked is not None:
            r, J, dist = self.walked(stack, x)
            return r, J if jac else None, dist
        (c, s), R, p, t = self.frames(idx, x)
        if jac:
            omega, pivot = self.model.axes_trig(c, s, R, p)
            return stack.evaluate(R, p, t, omega, pivot)
        return stack.evaluate(R, p, t)

    def trial(self, idx, stack, x):
        """Residuals at trial variables, keeping what :meth:`jacobian` needs.

        Returns
        -------
        r : numpy.ndarray, shape (B', M)
        dist : numpy.ndarray, shape (B', n_goals)
        kept : tuple
            The angles' cosines and sines, link frames and translation; or,
            for a handful of trials, their Jacobian already.
        """
        if self.walked is not None:
            # The walk gives the Jacobian for a few more array operations than the residuals.
            r, J, dist = self.walked(stack, x)
            return r, dist, (J,)
        (c, s), R, p, t = self.frames(idx, x)
        if len(idx) <= SMALL_BATCH:
            # Few trials are nearly all kept, and then one evaluation with
            # the Jacobian costs less than two numpy passes.
            r, J, dist = stack.evaluate(R, p, t, *self.model.axes_trig(c, s, R, p))
            return r, dist, (J,)
        r, _, dist = stack.evaluate(R, p, t)
        return r, dist, (c, s, R, p, t)

    def jacobian(self, stack, kept, which):
        """The Jacobian at the trials ``which`` (a boolean mask) kept by :meth:`trial`.

        Returns
        -------
        numpy.ndarray, shape (n_true, M, P)
        """
        if len(kept) == 1:
            return kept[0][which]
        if not which.any():
            return np.zeros((0, stack.n_rows, self.model.n_params))
        if not which.all():
            kept = tuple(None if a is None else a[which] for a in kept)
            stack = stack.take(np.flatnonzero(which))
        c, s, R, p, t = kept
        omega, pivot = self.model.axes_trig(c, s, R, p)
        return stack.evaluate(R, p, t, omega, pivot)[1]


# ---------------------------------------------------------------- the rules
# The stopping, progress and damping rules, written once for the batched loops
# and the single-solve loop: each function works alike on one solve's Python
# scalars (``where`` is :func:`_pick`) and on a batch's arrays of shape (B',)
# (``where`` is :func:`numpy.where`), with only arithmetic, comparisons, ``&``
# and ``|``.


def _pick(cond, a, b):
    """:func:`numpy.where` for one solve's Python scalars: ``a`` if ``cond`` else ``b``."""
    return a if cond else b


def _converged(dist: np.ndarray, inactive: np.ndarray, tol: float) -> np.ndarray:
    """Every goal that counts is within the tolerance.

    Parameters
    ----------
    dist, inactive : numpy.ndarray, shape (..., n_goals)
        Goal distances, and which goals have weight 0 (asking for nothing).

    Returns
    -------
    numpy.ndarray of bool, shape (...)
    """
    return ((dist <= tol) | inactive).all(axis=-1)


def _giveup_floor(where, tol: float, n_active):
    """The cost below which an attempt is never given up, for ``n_active`` goals that count (a number or (B,))."""
    return GIVEUP_FLOOR * 0.5 * tol * tol * where(n_active > 1, n_active, 1)


def _step_status(where, converged, accept, gain, f_old, step, size, spent=False):
    """The status after an iteration's step: CONVERGED, STALLED or RUNNING.

    Converged: every goal within tolerance.  Stalled: an accepted step
    gained less than FTOL of the cost, or a step was shorter than XTOL
    relative to the variables, or ``spent`` (see :func:`_damping_spent`).
    ``step`` and ``size`` are the lengths of the step and of the variables.
    """
    stalled = (accept & (gain <= FTOL * f_old)) | (step <= XTOL * (XTOL + size)) | spent
    return where(converged, CONVERGED, where(stalled, STALLED, RUNNING))


def _first_damping(where, status, curv):
    """An attempt's first damping and growth factor, and its status.

    The damping starts at MU0 times the largest curvature (diagonal entry
    of ``J^T J``); where no variable moves any goal (``curv`` 0) there is
    nothing to do, and a running attempt is stalled.

    Returns
    -------
    status, mu, nu
    """
    return where((status == RUNNING) & (curv == 0.0), STALLED, status), MU0 * where(curv > 0, curv, 1.0), 2.0


def _damping(where, mu, nu, accept, rho):
    """Nielsen's update of the damping ``mu`` and its growth factor ``nu`` after a step.

    Shrink after a kept step by the gain ratio ``rho``, grow fast after a
    rejected one.  Returns ``mu, nu``.
    """
    shrink = 1 - (2 * rho - 1) ** 3
    return where(accept, mu * where(shrink > 1 / 3, shrink, 1 / 3), mu * nu), where(accept, 2.0, nu * 2.0)


def _damping_spent(where, mu, curv):
    """The damping grew beyond MU_MAX times the largest curvature: no step can lower the cost any more."""
    return mu > MU_MAX * where(curv > 1e-300, curv, 1e-300)


def _progress(where, status, k, f, window_f, fast_f, max_iter, may_give_up, giveup_floor):
    """The rules at the end of an attempt's iteration ``k``, for attempts still running.

    Every WINDOW iterations, an attempt whose cost fell by less than
    WINDOW_FTOL of it is stalled: near a joint limit or a saddle (a straight
    chain pulled along its length), steps can keep lowering the cost by a
    hair for hundreds of iterations, and a pose that close to stationary is
    the best pose.  At ``max_iter`` it stops at the LIMIT.  While it
    ``may_give_up`` (restarts remain), an attempt converging slowly toward a
    cost well above the tolerance's (a local minimum) is given up early
    (GIVEUP_*), so that restarts cost few iterations.

    Returns
    -------
    status, window_f, fast_f, gave_up
        ``gave_up``: the attempt was given up just now.
    """
    running = status == RUNNING
    due = running & (k % WINDOW == 0)
    status = where(due & (window_f - f <= WINDOW_FTOL * window_f), STALLED, status)
    window_f = where(due, f, window_f)
    status = where(running & (k >= max_iter), LIMIT, status)
    check = (k % GIVEUP_EVERY == 0) & may_give_up & (status == RUNNING)
    hopeless = check & (k >= GIVEUP_FROM) & (f > giveup_floor) & (f > 0.5 * fast_f)
    return where(hopeless, STALLED, status), window_f, where(check, f, fast_f), hopeless


# ---------------------------------------------------------------- solving


def solve(
    model: IKModel,
    stack: GoalStack,
    x0: np.ndarray,
    base: np.ndarray,
    *,
    method: str = DEFAULT_SOLVER,
    tolerance: float,
    max_iterations: int,
    restarts: int = 0,
    seed: int = 0,
    trace: bool = False,
) -> SolveResult:
    """Minimise the goals' weighted cost for a batch of problems.

    Parameters
    ----------
    model : IKModel
    stack : GoalStack
        With batch size ``B``.
    x0 : numpy.ndarray, shape (B, n_params)
        Start variables (angles in radians within the bounds, then the
        translation over the figure's length).
    base : numpy.ndarray, shape (B, n_joints, 3) or (1, n_joints, 3)
        Radians, for the axes that are not variables.
    method : str
        A name in :data:`SOLVER_NAMES`: ``"dls"``, ``"transpose"`` or ``"ccd"``.
    tolerance : float
        A goal is met when its distance (see :meth:`GoalStack.evaluate`) is
        at most this.
    max_iterations : int
        Iterations (sweeps for CCD) per batch element and attempt.
    restarts : int, default 0
        When an attempt ends without meeting its goals (a local minimum,
        often against joint limits, or the iteration limit), try again, up
        to this many times, from angles drawn uniformly within the limits
        (the translation restarts from ``x0``'s), and keep the first attempt
        that meets them.  If none does, the result is the first attempt's:
        a goal that cannot be met ends at the best pose reached from the
        given start, not from a random one.
    seed : int, default 0
        Seeds the restarts' random angles (results are reproducible).
    trace : bool
        Record the cost after each iteration in ``history`` (with restarts,
        that of the attempt under way).

    Returns
    -------
    SolveResult
        ``iterations`` counts every attempt.
    """
    spec = SOLVERS.get(method)
    if spec is None:
        raise ValueError(f"unknown solver {method!r}; expected one of {', '.join(SOLVER_NAMES)}")
    prob = _Problem(model, stack, base)
    x = np.minimum(np.maximum(np.array(x0, dtype=float), prob.lower), prob.upper)  # np.clip's wrapper costs more
    if method == "dls" and x.shape[0] == 1:
        # One problem (the language's STARTREACH): the batch bookkeeping
        # would cost more than the arithmetic; same iterates, scalar control.
        return _dls_one(prob, x[0], float(tolerance), int(max_iterations), int(restarts), seed, trace)
    st = _State(
        prob,
        x,
        float(tolerance),
        trace,
        jac=spec.jacobian,
        max_iter=int(max_iterations),
        restarts=int(restarts),
        seed=seed,
    )
    spec.run(prob, st)
    return st.finish()


class _State:
    """Per-batch bookkeeping shared by the solver loops: status, stopping rules, restarts.

    Holds the current variables ``x`` (B, P), residuals ``r`` (B, M),
    Jacobian ``J`` (B, M, P) (None for CCD), cost ``f`` (B,) and goal
    distances ``dist`` (B, n_goals) of every batch element, and each
    element's attempt: its status, iterations, progress marks and the first
    attempt set aside by a restart.  This is the one home of restarting,
    resuming and the final choice between attempts, for the batched loops
    and the single solve alike (:func:`_dls_one` hands it its attempts as
    they end).

    Parameters
    ----------
    prob : _Problem
    x : numpy.ndarray, shape (B, P)
        Start variables (kept, and restarts take the translation from them).
    tol, trace, jac, max_iter, restarts, seed
        As for :func:`solve`; ``jac``: whether the loop needs the Jacobian.
    first : tuple, optional
        ``r, J, dist, f`` at ``x`` when already known.
    evaluate : callable, optional
        ``evaluate(idx, x) -> (r, J, dist, f)`` for sub-batch ``idx`` at
        ``x`` (B', P); by default the batched kinematics.
    """

    def __init__(
        self,
        prob: _Problem,
        x: np.ndarray,
        tol: float,
        trace: bool,
        jac: bool,
        max_iter: int,
        restarts: int,
        seed: int,
        *,
        first: tuple | None = None,
        evaluate: Callable[[np.ndarray, np.ndarray], tuple] | None = None,
    ):
        self.prob = prob
        self.x = x
        self.x0 = x.copy()
        B = x.shape[0]
        self.jac = jac
        self.evaluate: Callable[[np.ndarray, np.ndarray], tuple] = evaluate or self._evaluate_batch
        if first is None:
            self.r, self.J, self.dist = prob.evaluate(np.arange(B), prob.stack, x, jac)
            self.f = 0.5 * np.einsum("bm,bm->b", self.r, self.r)
        else:
            self.r, self.J, self.dist, self.f = first
        self.active_goals = prob.stack.active
        self.inactive = ~self.active_goals
        self.tol = tol
        self.max_iter = max_iter
        self.status = np.where(_converged(self.dist, self.inactive, tol), CONVERGED, RUNNING)
        if max_iter <= 0:
            self.status[self.status == RUNNING] = LIMIT
        self.iterations = np.zeros(B, dtype=int)
        self.attempt_iter = np.zeros(B, dtype=int)
        self.history = [self.f.copy()] if trace else None
        self.window_f = self.f.copy()
        V = prob.model.n_vars
        self.attempts_left = np.full(B, restarts if V else 0)
        self.rng = np.random.default_rng(seed)
        # The first attempt of elements that restarted (one dict, made at the first restart).
        self.saved: dict = {}
        self.gave_up = np.zeros(B, dtype=bool)  # the current attempt was given up early
        self.resumed = np.zeros(B, dtype=bool)  # the first attempt was taken up again
        self.fast_f = self.f.copy()
        self.giveup_floor = _giveup_floor(np.where, tol, self.active_goals.sum(axis=-1))
        # The solver's hook to reset its own per-element state.
        self.on_restart: Callable[[np.ndarray], None] | None = None
        self.solver_arrays: dict = {}  # the solver's own per-element state, (B,) arrays, saved with an attempt

    def _evaluate_batch(self, idx: np.ndarray, x: np.ndarray) -> tuple:
        """``r (B', M)``, ``J (B', M, P)`` (or None), ``dist (B', n_goals)`` and ``f (B',)`` of sub-batch ``idx`` at ``x``."""
        prob = self.prob
        r, J, dist = prob.evaluate(idx, prob.stack.take(idx), x, self.jac)
        return r, J, dist, 0.5 * np.einsum("bm,bm->b", r, r)

    def running(self) -> np.ndarray:
        """Indices of the elements still iterating."""
        return np.flatnonzero(self.status == RUNNING)

    def put(self, i: int, **values) -> None:
        """Set element ``i``'s fields (attributes, or the solver's own arrays) by name."""
        for key, value in values.items():
            (self.solver_arrays[key] if key in self.solver_arrays else getattr(self, key))[i] = value

    def get(self, i: int, *names: str) -> list:
        """Element ``i``'s fields by name: copies of array rows, Python scalars."""
        out = []
        for key in names:
            value = (self.solver_arrays[key] if key in self.solver_arrays else getattr(self, key))[i]
            out.append(value.copy() if isinstance(value, np.ndarray) else value.item())
        return out

    def accept(self, idx, accept, x, r, dist, f, J=None) -> None:
        """Keep the trial values of sub-batch ``idx`` where ``accept``."""
        a = idx[accept]
        self.x[a], self.r[a], self.dist[a], self.f[a] = x[accept], r[accept], dist[accept], f[accept]
        if J is not None:
            self.J[a] = J

    def stop_checks(self, idx, accept, gain, f_old, dx, spent=False) -> None:
        """Mark converged and stalled elements of sub-batch ``idx`` after a step (see :func:`_step_status`)."""
        conv = _converged(self.dist[idx], self.inactive[idx], self.tol)
        size = np.sqrt(np.einsum("bp,bp->b", self.x[idx], self.x[idx]))
        step = np.sqrt(np.einsum("bp,bp->b", dx, dx))
        self.status[idx] = _step_status(np.where, conv, accept, gain, f_old, step, size, spent)

    def end_iteration(self, idx: np.ndarray) -> None:
        """Count an iteration of sub-batch ``idx``, apply :func:`_progress`, then :meth:`end_attempts`."""
        # The whole batch (so always, until the first element stops): views, not gathered copies.
        sel = slice(None) if idx.size == self.x.shape[0] else idx
        self.iterations[sel] += 1
        self.attempt_iter[sel] += 1
        if self.history is not None:
            self.history.append(self.f.copy())
        status, window_f, fast_f, gave_up = _progress(
            np.where,
            self.status[sel],
            self.attempt_iter[sel],
            self.f[sel],
            self.window_f[sel],
            self.fast_f[sel],
            self.max_iter,
            self.attempts_left[sel] > 0,
            self.giveup_floor[sel],
        )
        self.status[sel], self.window_f[sel], self.fast_f[sel] = status, window_f, fast_f
        self.gave_up[sel] |= gave_up
        self.end_attempts(idx)

    def end_attempts(self, idx: np.ndarray) -> None:
        """Restart or resume the elements of sub-batch ``idx`` whose attempt has just ended unconverged.

        While an element has restarts left, it starts again from random
        angles (:meth:`_restart`).  When the last restart has ended too, a
        first attempt that was given up early is taken up again where it was
        set aside (:meth:`_resume`), so the result does not depend on
        restarts being allowed.
        """
        ended = idx[(self.status[idx] == STALLED) | (self.status[idx] == LIMIT)]
        # Decide who resumes before restarting: an element that has just drawn
        # its last restart has no restarts left either, but must run it.
        back = ended[:0]
        if self.saved:
            back = ended[(self.attempts_left[ended] == 0) & self.saved["mask"][ended]]
            back = back[self.saved["gave_up"][back] & ~self.resumed[back]]
        again = ended[self.attempts_left[ended] > 0]
        if again.size:
            self._restart(again)
        if back.size:
            self._resume(back)

    _SAVED = ("x", "r", "f", "dist", "status", "attempt_iter", "window_f", "gave_up")

    def _restart(self, idx: np.ndarray) -> None:
        """Start elements ``idx`` again from random angles within the limits."""
        if not self.saved:
            self.saved = {key: getattr(self, key).copy() for key in self._SAVED}
            self.saved["mask"] = np.zeros(self.x.shape[0], dtype=bool)
            if self.jac:
                self.saved["J"] = self.J.copy()
            self.saved["solver"] = {k: v.copy() for k, v in self.solver_arrays.items()}
        first = idx[~self.saved["mask"][idx]]
        for key in self._SAVED + (("J",) if self.jac else ()):
            self.saved[key][first] = getattr(self, key)[first]
        for k, v in self.solver_arrays.items():
            self.saved["solver"][k][first] = v[first]
        self.saved["mask"][first] = True
        prob = self.prob
        V = prob.model.n_vars
        lo = np.where(np.isfinite(prob.lower[:V]), prob.lower[:V], -np.pi)
        hi = np.where(np.isfinite(prob.upper[:V]), prob.upper[:V], np.pi)
        x = self.x0[idx].copy()
        x[:, :V] = self.rng.uniform(lo, hi, size=(idx.size, V))
        r, J, dist, f = self.evaluate(idx, x)
        self.x[idx], self.r[idx], self.dist[idx], self.f[idx] = x, r, dist, f
        if self.jac:
            self.J[idx] = J
        self.window_f[idx] = self.fast_f[idx] = self.f[idx]
        self.attempt_iter[idx] = 0
        self.attempts_left[idx] -= 1
        self.gave_up[idx] = False
        self.status[idx] = np.where(_converged(dist, self.inactive[idx], self.tol), CONVERGED, RUNNING)
        if self.on_restart is not None:
            self.on_restart(idx)

    def _resume(self, idx: np.ndarray) -> None:
        """Take up the first attempt of elements ``idx`` where it was given up."""
        for key in self._SAVED + (("J",) if self.jac else ()):
            getattr(self, key)[idx] = self.saved[key][idx]
        for k, v in self.solver_arrays.items():
            v[idx] = self.saved["solver"][k][idx]
        # Exactly where it was given up: the attempt goes on as it would have
        # without restarts.
        self.status[idx] = RUNNING
        self.gave_up[idx] = False
        self.resumed[idx] = True

    def finish(self) -> SolveResult:
        """The result; elements whose every attempt failed get their first attempt back."""
        self.status[self.status == RUNNING] = LIMIT
        if self.saved:
            back = self.saved["mask"] & (self.status != CONVERGED) & ~self.resumed
            for key in ("x", "f", "dist", "status"):
                getattr(self, key)[back] = self.saved[key][back]
        return SolveResult(self.x, self.status, self.iterations, self.f, self.dist, self.history or [])


def _solve_damped(J: np.ndarray, r: np.ndarray, free: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """``dx = -(J^T J + mu I)^-1 J^T r`` over the free variables (zero elsewhere).

    Uses the smaller of the two equal forms: ``-J^T (J J^T + mu I)^-1 r``
    when there are fewer residual rows than variables.
    """
    Jf = J * free[:, None, :]
    B, M, P = J.shape
    if M == 3 < P:
        # One point goal: the 3x3 system's Cholesky written out over the batch
        # (np.linalg.solve on stacked 3x3s costs several times more).
        A = Jf @ np.swapaxes(Jf, 1, 2)
        y3 = solve3(A[:, 0, 0] + mu, A[:, 0, 1], A[:, 0, 2], A[:, 1, 1] + mu, A[:, 1, 2], A[:, 2, 2] + mu, r.T, np.sqrt)
        if y3 is not None:
            return np.einsum("bmp,mb->bp", Jf, np.array(y3))
    if M < P:
        A = Jf @ np.swapaxes(Jf, 1, 2)
        A[:, np.arange(M), np.arange(M)] += mu[:, None]
        y = np.linalg.solve(A, -r[..., None])[..., 0]
        return np.einsum("bmp,bm->bp", Jf, y)
    A = np.swapaxes(Jf, 1, 2) @ Jf
    A[:, np.arange(P), np.arange(P)] += mu[:, None]
    g = np.einsum("bmp,bm->bp", Jf, r)
    return -np.linalg.solve(A, g[..., None])[..., 0]


def _project(prob: _Problem, x: np.ndarray, dx: np.ndarray, free: np.ndarray) -> np.ndarray:
    """The step actually taken: held variables stay, the rest is clipped into the limits."""
    dx = np.where(free, dx, 0.0)
    return np.clip(x + dx, prob.lower, prob.upper) - x


def _held(prob: _Problem, x: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Variables at a limit that ``direction`` pushes against, shape (B, P)."""
    return ((x <= prob.lower) & (direction < 0)) | ((x >= prob.upper) & (direction > 0))


def _dls(prob: _Problem, st: _State) -> None:
    """Levenberg-Marquardt with projection onto the limits (see module docstring)."""
    B, P = st.x.shape
    V = prob.model.n_vars
    curv = np.zeros(B)
    mu = np.zeros(B)
    nu = np.full(B, 2.0)

    def reset(idx):
        c = np.einsum("bmp,bmp->bp", st.J[idx], st.J[idx]).max(axis=1, initial=0.0)
        curv[idx] = c
        st.status[idx], mu[idx], nu[idx] = _first_damping(np.where, st.status[idx], c)

    reset(np.arange(B))
    st.on_restart = reset
    st.solver_arrays = {"curv": curv, "mu": mu, "nu": nu}
    while True:
        idx = st.running()
        if idx.size == 0:
            break
        # All running (always so for a single solve): views instead of gathered copies.
        sel = slice(None) if idx.size == B else idx
        xs, rs, Js, fs, mus = st.x[sel], st.r[sel], st.J[sel], st.f[sel].copy(), mu[sel]
        # Hold the variables at a limit that the descent direction pushes
        # against, then those the step still pushes against, solving again
        # without them (an active-set projection; rarely more than once).
        free = ~_held(prob, xs, -np.einsum("bmp,bm->bp", Js, rs))
        for _pass in range(3):
            dx = _solve_damped(Js, rs, free, mus)
            out = _held(prob, xs, dx) & free
            if not out.any():
                break
            free &= ~out
        big = np.max(np.abs(dx[:, :V]), axis=1, initial=0.0)
        dx = dx * np.minimum(1.0, MAXSTEP / np.maximum(big, 1e-300))[:, None]
        dx = _project(prob, xs, dx, free)
        xn = xs + dx
        stack = prob.stack.take(idx)
        rn, dn, kept = prob.trial(idx, stack, xn)
        fn = 0.5 * np.einsum("bm,bm->b", rn, rn)
        lin = rs + np.einsum("bmp,bp->bm", Js, dx)
        predicted = fs - 0.5 * np.einsum("bm,bm->b", lin, lin)
        gain = fs - fn
        accept = (gain > 0) & (predicted > 0)
        rho = np.divide(gain, predicted, out=np.zeros_like(gain), where=predicted > 0)
        mu[idx], nu[idx] = _damping(np.where, mus, nu[idx], accept, rho)
        # The Jacobian is only needed where the step is kept.
        st.accept(idx, accept, xn, rn, dn, fn, prob.jacobian(stack, kept, accept))
        st.stop_checks(idx, accept, gain, fs, dx, _damping_spent(np.where, mu[idx], curv[idx]))
        st.end_iteration(idx)


# What :func:`_dls_one` hands to a :class:`_State` when an attempt ends.
_ATTEMPT = ("x", "r", "J", "f", "dist", "status", "attempt_iter", "window_f", "fast_f", "gave_up", "curv", "mu", "nu")
_ONE = np.zeros(1, dtype=np.intp)


def _attempts_of_one(prob: _Problem, x0, first, kern: Kernel, tol, max_iter, restarts, seed) -> _State:
    """The :class:`_State` of a batch of one that :func:`_dls_one` hands its ended attempts to.

    It evaluates and resets a restarted attempt as :func:`_dls_one` does
    (``kern.evaluate`` on one problem, ``kern.curvature``), so a single
    solve's iterates do not depend on whether it restarted.  ``first`` is
    ``kern.evaluate(x0)``.
    """

    def batch_of_one(values):
        return tuple(np.asarray(v)[None] for v in values)

    st = _State(
        prob,
        np.array(x0, dtype=float)[None],
        tol,
        False,
        jac=True,
        max_iter=max_iter,
        restarts=restarts,
        seed=seed,
        first=batch_of_one(first),
        evaluate=lambda idx, x: batch_of_one(kern.evaluate(kern.native(x[0]))),
    )
    st.solver_arrays = {"curv": np.zeros(1), "mu": np.zeros(1), "nu": np.zeros(1)}

    def on_restart(idx):
        c = kern.curvature(kern.native(st.J[0]))
        status, mu, nu = _first_damping(_pick, int(st.status[0]), c)
        st.put(0, status=status, curv=c, mu=mu, nu=nu)

    st.on_restart = on_restart
    return st


def _evaluate_one(prob: _Problem, x: np.ndarray) -> tuple:
    """``(r, J, dist, f)`` of one problem at ``x``: :func:`_dls_one`'s evaluation."""
    r, J, dist = prob.one(x)
    return r, J, dist, 0.5 * float(r @ r)


def _curvature_one(J: np.ndarray) -> float:
    """The largest squared column norm of one Jacobian (what :func:`_first_damping` scales by)."""
    return float((J * J).sum(axis=0).max(initial=0.0))


def _numpy_kernel(prob: _Problem, tol: float) -> Kernel:
    """:func:`_dls_one`'s :class:`Kernel` on numpy arrays: the one-pose kinematics and 2-D products."""
    V, P = prob.model.n_vars, prob.model.n_params
    M = prob.stack.n_rows
    active = prob.stack.active[0]
    inactive = ~active
    small = M < P
    diagonal = slice(None, None, min(M, P) + 1)  # of the flattened normal matrix

    def step(x, r, J, mu):
        dx = _held_step(x, r, J, prob.lower, prob.upper, mu, small, diagonal, V)
        return dx, x + dx

    def linear_sq(r, J, dx):
        lin = r + J @ dx
        return float(lin @ lin)

    return Kernel(
        evaluate=functools.partial(_evaluate_one, prob),
        step=step,
        curvature=_curvature_one,
        native=np.asarray,
        linear_sq=linear_sq,
        norm=lambda v: math.sqrt(float(v @ v)),
        met=lambda dist: bool(_converged(dist, inactive, tol)),
        n_active=int(active.sum()),
    )


def _judged_step(kern: Kernel, now: tuple, xn, dx, then: tuple, mu: float, nu: float, curv: float):
    """Accept the step to ``xn`` or not, update the damping, and say how the attempt stands.

    ``now`` is ``(x, r, J, dist, f)`` before the step and ``then`` the
    evaluation ``(r, J, dist, f)`` at ``xn``.  Returns the state to go on
    from (``xn``'s when accepted), the damping ``mu, nu``, and the status.
    """
    x, r, J, dist, f = now
    rn, Jn, dn, fn = then
    predicted = f - 0.5 * kern.linear_sq(r, J, dx)
    gain = f - fn
    accept = gain > 0 and predicted > 0
    mu, nu = _damping(_pick, mu, nu, accept, gain / predicted if accept else 0.0)
    if accept:
        x, r, J, dist = xn, rn, Jn, dn
    status = _step_status(
        _pick,
        kern.met(dist),
        accept,
        gain,
        f,
        kern.norm(dx),
        kern.norm(x),
        _damping_spent(_pick, mu, curv),
    )
    return (x, r, J, dist, fn if accept else f), mu, nu, status


def _held_step(x, r, J, lower, upper, mu: float, small: bool, diagonal: slice, V: int) -> np.ndarray:
    """:func:`_dls_one`'s step from ``x``: damped, capped and projected into the bounds.

    Variables at a limit that the descent direction, then the step, pushes
    against are held.  Only a variable at a limit can be held, so while none
    is (most iterations) there is nothing to check.
    """
    at_lower, at_upper = x <= lower, x >= upper
    at_limit = bool(at_lower.any() or at_upper.any())
    if at_limit:
        g = J.T @ r
        free = ~((at_lower & (g > 0)) | (at_upper & (g < 0)))
    for _pass in range(3):
        Jf = J * free if at_limit else J
        if small:
            A = Jf @ Jf.T
            A.flat[diagonal] += mu
            dx = Jf.T @ np.linalg.solve(A, -r)
        else:
            A = Jf.T @ Jf
            A.flat[diagonal] += mu
            dx = -np.linalg.solve(A, Jf.T @ r)
        if not at_limit:
            break
        out = ((at_lower & (dx < 0)) | (at_upper & (dx > 0))) & free
        if not out.any():
            break
        free &= ~out
    big = float(np.abs(dx[:V]).max(initial=0.0))
    if big > MAXSTEP:
        dx = dx * (MAXSTEP / big)
    # The projection (np.minimum/maximum: np.clip's wrapper costs more than the clipping).
    xn = x + (np.where(free, dx, 0.0) if at_limit else dx)
    return np.minimum(np.maximum(xn, lower), upper) - x


def _next_attempt(st: _State, attempt: tuple, native: Callable) -> tuple[tuple, int]:
    """Hand an attempt that ended unconverged to the attempts' :class:`_State`: the attempt to go on with, restarts left."""
    st.put(0, **dict(zip(_ATTEMPT, attempt)))
    st.end_attempts(_ONE)
    values = st.get(0, *_ATTEMPT)
    return tuple(native(v) if isinstance(v, np.ndarray) else v for v in values), int(st.attempts_left[0])


def _dls_one(
    prob: _Problem, x: np.ndarray, tol: float, max_iter: int, restarts: int, seed: int, trace: bool
) -> SolveResult:
    """:func:`_dls` for a batch of one: the same step in 2-D arithmetic, the same rules and restarts.

    A single solve is a few dozen iterations on arrays of a handful of
    entries, where every numpy call costs far more than its arithmetic
    (through :func:`_dls` and :class:`_State`, about 2.8 times as long per
    solve on the benchmark's chains).  So the step (:func:`_held_step`,
    :func:`_judged_step`) is computed with 2-D products on the one problem,
    and the rules run on Python scalars.  An attempt that ends unconverged
    while restarts are in play is handed to a :class:`_State` of one
    element, which restarts or resumes it as for a batch and chooses the
    final attempt.  A batch of one thus ends where the batched loop ends it
    (same status and iterations, angles equal up to rounding).

    Parameters
    ----------
    prob : _Problem
        With a batch of one.
    x : numpy.ndarray, shape (P,)
        Start variables, within the bounds.
    tol, max_iter, restarts, seed, trace
        As for :func:`solve`.

    Returns
    -------
    SolveResult
        With a batch dimension of one, as :func:`solve` returns.
    """
    kern = float_kernel(prob, tol, MAXSTEP) or _numpy_kernel(prob, tol)
    V = prob.model.n_vars
    x0 = x
    x = kern.native(x)
    r, J, dist, f = first = kern.evaluate(x)
    status = CONVERGED if kern.met(dist) else RUNNING
    if max_iter <= 0 and status == RUNNING:
        status = LIMIT
    history = [np.array([f])] if trace else []
    iterations = attempt_iter = 0
    window_f = fast_f = f
    attempts_left = restarts if V else 0
    gave_up = False
    giveup_floor = float(_giveup_floor(_pick, tol, kern.n_active))
    curv = kern.curvature(J)
    status, mu, nu = _first_damping(_pick, status, curv)
    st = None  # the attempts' _State, from the first attempt that ends while restarts are in play

    while status == RUNNING:
        dx, xn = kern.step(x, r, J, mu)
        (x, r, J, dist, f), mu, nu, status = _judged_step(
            kern, (x, r, J, dist, f), xn, dx, kern.evaluate(xn), mu, nu, curv
        )
        iterations += 1
        attempt_iter += 1
        if trace:
            history.append(np.array([f]))
        status, window_f, fast_f, hopeless = _progress(
            _pick, status, attempt_iter, f, window_f, fast_f, max_iter, attempts_left > 0, giveup_floor
        )
        gave_up |= hopeless
        if (status == STALLED or status == LIMIT) and (attempts_left > 0 or st is not None):
            # An attempt ended unconverged with restarts in play (some left, or
            # some taken): _State restarts or resumes it, as for a batch.
            if st is None:
                st = _attempts_of_one(prob, x0, first, kern, tol, max_iter, restarts, seed)
            attempt = (x, r, J, f, dist, status, attempt_iter, window_f, fast_f, gave_up, curv, mu, nu)
            attempt, attempts_left = _next_attempt(st, attempt, kern.native)
            x, r, J, f, dist, status, attempt_iter, window_f, fast_f, gave_up, curv, mu, nu = attempt

    return _one_result(st, (x, f, dist, status, iterations), history)


def _one_result(st: _State | None, end: tuple, history: list) -> SolveResult:
    """:func:`_dls_one`'s result from its last attempt's ``(x, f, dist, status, iterations)``.

    With restarts in play, the attempts' :class:`_State` chooses the attempt.
    """
    x, f, dist, status, iterations = end
    if st is None:
        return SolveResult(
            np.array(x, dtype=float)[None],
            np.array([status]),
            np.array([iterations]),
            np.array([f]),
            np.array(dist, dtype=float)[None],
            history,
        )
    st.put(0, x=x, f=f, dist=dist, status=status, iterations=iterations)
    st.history = history
    return st.finish()


def _transpose(prob: _Problem, st: _State) -> None:
    """Jacobian transpose steps with Buss's step length, halved until the cost drops."""
    B, P = st.x.shape
    scale = np.ones(B)

    def reset(idx):
        scale[idx] = 1.0

    st.on_restart = reset
    st.solver_arrays = {"scale": scale}
    while True:
        idx = st.running()
        if idx.size == 0:
            break
        sel = slice(None) if idx.size == B else idx
        xs, rs, Js, fs = st.x[sel], st.r[sel], st.J[sel], st.f[sel].copy()
        g = np.einsum("bmp,bm->bp", Js, rs)  # gradient of f
        free = ~_held(prob, xs, -g)
        g = np.where(free, g, 0.0)
        Jg = np.einsum("bmp,bp->bm", Js, g)
        gg = np.einsum("bp,bp->b", g, g)
        JgJg = np.einsum("bm,bm->b", Jg, Jg)
        # Buss: the step length that minimises the linearised cost along -g.
        alpha = np.divide(gg, JgJg, out=np.zeros_like(gg), where=JgJg > 0)
        dx = _project(prob, xs, -(scale[idx] * alpha)[:, None] * g, free)
        xn = xs + dx
        stack = prob.stack.take(idx)
        rn, dn, kept = prob.trial(idx, stack, xn)
        fn = 0.5 * np.einsum("bm,bm->b", rn, rn)
        gain = fs - fn
        accept = gain > 0
        scale[idx] = np.where(accept, np.minimum(1.0, 2.0 * scale[idx]), 0.5 * scale[idx])
        st.accept(idx, accept, xn, rn, dn, fn, prob.jacobian(stack, kept, accept))
        st.stop_checks(idx, accept, gain, fs, dx)
        st.end_iteration(idx)


# ---------------------------------------------------------------- CCD

_GRID = 33  # samples of the 1-D cost per variable before Newton polishing


def _rotate(d: np.ndarray, w: np.ndarray, s: np.ndarray, cm: np.ndarray) -> np.ndarray:
    """Rodrigues: ``d`` turned about unit ``w`` by the angle with sine ``s``, ``1 - cos`` ``cm``."""
    from liganimate.runtime.ik.model import cross3

    wd = cross3(w, d)
    return d + s[..., None] * wd + cm[..., None] * cross3(w, wd)


def _trig_cost(C, s, cm):
    """The 1-D cost ``sum (a + b sin + c (1 - cos))^2`` from its six sums, any shape."""
    c0, cab, cac, cbb, ccc, cbc = (C[..., i] for i in range(6))
    return c0 + 2 * cab * s + 2 * cac * cm + cbb * s * s + ccc * cm * cm + 2 * cbc * s * cm


def _trig_minimum(C: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The angle in ``[lo, hi]`` minimising :func:`_trig_cost`, per batch element.

    Parameters
    ----------
    C : numpy.ndarray, shape (B, 6)
    lo, hi : numpy.ndarray, shape (B,)
        ``lo <= 0 <= hi``, within ``[-pi, pi]``.

    Returns
    -------
    numpy.ndarray, shape (B,)
        0 unless some angle lowers the cost.
    """
    u = np.linspace(0.0, 1.0, _GRID)
    grid = lo[:, None] + (hi - lo)[:, None] * u  # (B, N), includes both ends
    Cg = C[:, None, :]
    cost = _trig_cost(Cg, np.sin(grid), 1.0 - np.cos(grid))
    best = grid[np.arange(len(lo)), np.argmin(cost, axis=1)]
    c0, cab, cac, cbb, ccc, cbc = (C[:, i] for i in range(6))
    th = best
    for _ in range(3):
        # Newton on the derivative, kept inside the interval.
        s, c = np.sin(th), np.cos(th)
        cm = 1.0 - c
        d1 = 2 * (cab * c + cac * s + cbb * s * c + ccc * cm * s + cbc * (c * cm + s * s))
        d2 = 2 * (-cab * s + cac * c + cbb * (c * c - s * s) + ccc * (s * s + cm * c) + cbc * (-s * cm + 3 * s * c))
        step = np.divide(d1, d2, out=np.zeros_like(d1), where=d2 > 0)
        cand = np.clip(th - step, lo, hi)
        better = _trig_cost(C, np.sin(cand), 1.0 - np.cos(cand)) < _trig_cost(C, np.sin(th), 1.0 - np.cos(th))
        th = np.where(better, cand, th)
    keep = _trig_cost(C, np.sin(th), 1.0 - np.cos(th)) < c0
    return np.where(keep, th, 0.0)


def _ccd(prob: _Problem, st: _State) -> None:
    """Cyclic coordinate descent with exact 1-D minimisation (see module docstring)."""
    from liganimate.runtime.ik.model import cross3

    model = prob.model
    V = model.n_vars
    A = model.A
    while True:
        idx = st.running()
        if idx.size == 0:
            break
        stack = prob.stack.take(idx)
        xs = st.x[idx].copy()
        fs = st.f[idx]
        (cos, sin), R, p, t = prob.frames(idx, xs)
        omega, c = model.axes_trig(cos, sin, R, p)
        tw = t if t is not None else np.zeros((idx.size, 3))
        # Current goal points and link directions (model frame); each turn of
        # a variable rotates those it moves, so no kinematics is redone
        # within a sweep.
        yp = stack._link_points(R, p, stack.p_link, stack.p_local)
        yq = stack._link_points(R, p, stack.q_link, stack.q_local)
        vh = np.einsum("bhij,hj->bhi", R[:, stack.h_link], stack.h_local)
        wp = stack.row_weight[:, : 3 * len(stack.p_link)].reshape(idx.size, -1, 3)[..., 0]
        wq = stack.row_weight[:, 3 * len(stack.p_link) : 3 * len(stack.p_link) + len(stack.q_link)]
        wh = stack.row_weight[:, 3 * len(stack.p_link) + len(stack.q_link) :].reshape(idx.size, -1, 3)[..., 0]
        nvh = np.linalg.norm(vh @ A.T, axis=-1)  # |A v|, unchanged by turns when A is a similarity
        for v in range(V):
            w = omega[:, v]
            cv = c[:, v]
            C = np.zeros((idx.size, 6))
            mp = model.downstream[v, stack.p_link]
            if mp.any():
                d = yp[:, mp] - cv[:, None]
                wd = cross3(w[:, None], d)
                a = (yp[:, mp] @ A.T + model.b + tw[:, None] - stack.p_target[:, mp]) * wp[:, mp, None]
                b = (wd @ A.T) * wp[:, mp, None]
                g = (cross3(w[:, None], wd) @ A.T) * wp[:, mp, None]
                C += _sums(a.reshape(idx.size, -1), b.reshape(idx.size, -1), g.reshape(idx.size, -1))
            mq = model.downstream[v, stack.q_link]
            if mq.any():
                n = stack.q_normal[:, mq]
                d = yq[:, mq] - cv[:, None]
                wd = cross3(w[:, None], d)
                a = (
                    np.einsum("bqi,bqi->bq", n, yq[:, mq] @ A.T + model.b + tw[:, None] - stack.q_origin[:, mq])
                    * wq[:, mq]
                )
                b = np.einsum("bqi,bqi->bq", n, wd @ A.T) * wq[:, mq]
                g = np.einsum("bqi,bqi->bq", n, cross3(w[:, None], wd) @ A.T) * wq[:, mq]
                C += _sums(a, b, g)
            mh = model.downstream[v, stack.h_link]
            if mh.any():
                k = (stack.h_ell[mh] * wh[:, mh])[..., None] / nvh[:, mh, None]
                vv = vh[:, mh]
                wv = cross3(w[:, None], vv)
                a = (vv @ A.T) * k - stack.h_dir[:, mh] * (stack.h_ell[mh] * wh[:, mh])[..., None]
                b = (wv @ A.T) * k
                g = (cross3(w[:, None], wv) @ A.T) * k
                C += _sums(a.reshape(idx.size, -1), b.reshape(idx.size, -1), g.reshape(idx.size, -1))
            if not (mp.any() or mq.any() or mh.any()):
                continue
            lo = np.maximum(prob.lower[v] - xs[:, v], -np.pi)
            hi = np.minimum(prob.upper[v] - xs[:, v], np.pi)
            th = _trig_minimum(C, np.minimum(lo, 0.0), np.maximum(hi, 0.0))
            xs[:, v] = np.clip(xs[:, v] + th, prob.lower[v], prob.upper[v])
            s, cm = np.sin(th), 1.0 - np.cos(th)
            if mp.any():
                yp[:, mp] = cv[:, None] + _rotate(yp[:, mp] - cv[:, None], w[:, None], s[:, None], cm[:, None])
            if mq.any():
                yq[:, mq] = cv[:, None] + _rotate(yq[:, mq] - cv[:, None], w[:, None], s[:, None], cm[:, None])
            if mh.any():
                vh[:, mh] = _rotate(vh[:, mh], w[:, None], s[:, None], cm[:, None])
        if model.translate:
            _ccd_translation(prob, idx, stack, xs)
        _ccd_end_sweep(prob, st, idx, stack, xs, fs)


def _ccd_translation(prob: _Problem, idx: np.ndarray, stack, xs: np.ndarray) -> None:
    """Move the translation variables of ``xs`` (in place) to their best given the angles.

    The residuals are linear in the translation: one Gauss-Newton step on
    it alone is its exact minimiser.
    """
    V = prob.model.n_vars
    rt, Jt, _ = prob.evaluate(idx, stack, xs, jac=True)
    Jt = Jt[..., V:]
    H = np.swapaxes(Jt, 1, 2) @ Jt
    g = np.einsum("bmp,bm->bp", Jt, rt)
    # A whisker of damping keeps H invertible when the goals pin the
    # translation in fewer than three directions (plane goals only).
    H += (1e-12 * np.trace(H, axis1=1, axis2=2) + 1e-300)[:, None, None] * np.eye(3)
    dt = -np.linalg.solve(H, g[..., None])[..., 0]
    xs[:, V:] += dt


def _ccd_end_sweep(prob: _Problem, st: _State, idx: np.ndarray, stack, xs: np.ndarray, fs: np.ndarray) -> None:
    """Keep a CCD sweep's result and say which solves converged or stalled."""
    rn, _, dn = prob.evaluate(idx, stack, xs, jac=False)
    fn = 0.5 * np.einsum("bm,bm->b", rn, rn)
    gain = fs - fn
    # Every coordinate move was exact and kept only if it helped, so the
    # sweep can only lower f (up to rounding, which the check absorbs).
    accept = gain >= 0
    st.accept(idx, accept, xs, rn, dn, fn)
    conv = _converged(st.dist[idx], st.inactive[idx], st.tol)
    st.status[idx[conv]] = CONVERGED
    st.status[idx[~conv & (~accept | (gain <= FTOL * fs))]] = STALLED
    st.end_iteration(idx)


def _sums(a: np.ndarray, b: np.ndarray, g: np.ndarray) -> np.ndarray:
    """The six sums over rows of ``(a + b sin + g (1 - cos))^2``'s coefficients, shape (B, 6)."""
    return np.stack(
        [
            np.einsum("bm,bm->b", a, a),
            np.einsum("bm,bm->b", a, b),
            np.einsum("bm,bm->b", a, g),
            np.einsum("bm,bm->b", b, b),
            np.einsum("bm,bm->b", g, g),
            np.einsum("bm,bm->b", b, g),
        ],
        axis=1,
    )


# ---------------------------------------------------------------- the registry


@dataclass(frozen=True)
class Solver:
    """One solver: the one table that the compiler, :func:`solve` and ``reach`` read.

    Attributes
    ----------
    name : str
        The runtime's name (``solve(method=...)``, ``reach(solver=...)``).
    keyword : str
        The language's word for it (``SOLVER DLS`` in a STARTREACH block).
    run : callable
        Its batched loop, ``run(problem, state)``.
    jacobian : bool
        Whether its loop needs the goals' Jacobian.
    max_iterations : int
        Its default iteration limit per attempt (sweeps for CCD).
    """

    name: str
    keyword: str
    run: Callable[[_Problem, _State], None]
    jacobian: bool
    max_iterations: int


#: The solvers by name, in the order they are listed to users.
SOLVERS: Mapping[str, Solver] = MappingProxyType(
    {
        s.name: s
        for s in (
            Solver("dls", "DLS", _dls, jacobian=True, max_iterations=200),
            Solver("transpose", "TRANSPOSE", _transpose, jacobian=True, max_iterations=5000),
            Solver("ccd", "CCD", _ccd, jacobian=False, max_iterations=500),
        )
    }
)
#: The runtime's solver names.
SOLVER_NAMES: tuple[str, ...] = tuple(SOLVERS)
if dict(SOLVER_KEYWORDS) != {s.keyword: s.name for s in SOLVERS.values()} or list(SOLVER_KEYWORDS.values()) != list(
    SOLVER_NAMES
):
    # names.py is what the compiler checks programs against: it must name exactly these solvers.
    raise ImportError("runtime/ik/names.py SOLVER_KEYWORDS does not match the SOLVERS table")
