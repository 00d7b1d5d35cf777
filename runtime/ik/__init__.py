"""Goal-directed posing: weighted goals, the solvers, and REACH.

Owns :mod:`.model` (a figure as the solvers see it), :mod:`.goals` (goal
kinds, residuals, Jacobians), :mod:`.solvers` (damped least squares, Jacobian
transpose, cyclic coordinate descent), :mod:`.entrywise` (point goals'
kinematics entry by entry: in floats for one solve, in arrays for a batch)
and :mod:`.reach` (poses and motions
that meet goals) and :mod:`.language` (the STARTREACH block: GOAL lines
into goals, the solve checked, warnings by goal).

May import: :mod:`liganimate.runtime.errors`, :mod:`liganimate.runtime.figure`,
:mod:`liganimate.runtime.motion` and its own modules.
"""
