"""REACH's options as one frozen value, in a module light enough for the host to import at start-up.

The generated module builds one :class:`ReachOptions` per STARTREACH block
(the solver's name and TRANSLATE INTO as literals, through ``repr()``; the
joints, chain, tolerance and iteration limit as the block's expressions),
and ``Runtime.reach``, ``ik.language.reach_block``, :func:`ik.reach.reach` /
:func:`ik.reach.reach_keyframes` and :func:`ik.reach.solve_pose` pass that
one object on. A new option is a field here.
"""

from __future__ import annotations

from liganimate.lang.node_methods import record
from liganimate.runtime.ik.names import DEFAULT_SOLVER


@record(frozen=True)
class ReachOptions:
    """How a pose is solved: the one value REACH, :func:`reach`, :func:`reach_keyframes` and :func:`solve_pose` pass on.

    Attributes
    ----------
    movable : None, int or tuple of int
        Which joints may turn: all (None), the ``n`` joints nearest each
        goal's link toward the main link (an int: a chain length), or joint
        ids.  The others keep their start angles, and so does every axis
        locked by its extremes (``min == max``).
    translate : bool
        Whether the whole figure may also move (POSIT's root translation).
    solver : str
        A name in :data:`solvers.SOLVER_NAMES`: "dls" (the default), "transpose" or "ccd".
    tolerance : float or None
        World units; default :data:`DEFAULT_TOLERANCE` times the figure's
        length.  The solve stops when every goal is this close (an axis goal
        counts its angle in radians times its link's length).
    max_iterations : int or None
        Default :data:`DEFAULT_MAX_ITERATIONS` for the solver.
    restarts : int
        When the goals are not met from the start pose (a local minimum,
        often against joint limits), try up to this many other start poses,
        drawn within the limits by a fixed-seed generator, and keep the
        first that meets them (see :func:`solvers.solve`).
    """

    movable: int | tuple[int, ...] | None = None
    translate: bool = False
    solver: str = DEFAULT_SOLVER
    tolerance: float | None = None
    max_iterations: int | None = None
    restarts: int = 0
