"""The Generator of the posing thesis (chapter IV): nine candidates, crossover by the user, mutation.

A run goes like this (chapter IV, 4 and 5):

1. **First generation.**  The seed pose is the figure standing (every
   angle neutral, clamped into its extremes).  For every joint (gene) the
   alternatives within its extremes are gathered level by level from the
   tessellated sphere (or circle), coarsest first, until there are at
   least nine (Fig. IV.9); candidate ``i`` takes each gene's ``i``-th
   alternative, so the nine poses differ strongly and their order is the
   alternatives' order, never shuffled.
2. **Crossover by the user.**  The user takes a limb from any candidate:
   that joint's three angles go into the current pose.
3. **Next generation.**  The current pose is the seed.  Each gene's
   alternatives are the points within the *maximum distance* the intensity
   slider sets (``intensity * 180`` degrees between directions or twists),
   again coarsest level first.  The extremes no longer bound them (the
   thesis lets animators reach uncommon poses), but a locked axis stays
   locked.  Flexion & pivot and twist are mutated separately: the mode says
   which.  Frozen joints (the thesis' mutation mask) keep the seed's angles.

Randomness: when the last level needed holds more alternatives than the
slots left, which of them fill the slots is drawn from a generator seeded
with :attr:`Generator.seed`; they are still shown in order.  The same seed
and the same choices give the same candidates.
"""

from __future__ import annotations

import copy

import numpy as np

from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure.pose import world_transforms

from ._genes import alternatives, joint_axes

__all__ = ["HISTORY_MAX", "KEPT_MAX", "POPULATION", "Generator"]

# "Nine poses was found to be an ideal number" (chapter IV, 5.1).
POPULATION = 9
MODES = ("flexion", "twist")
SEED_MAX = 2**32 - 1
#: Actions :meth:`Generator.undo` can go back (older ones are forgotten): the history's memory is bounded.
HISTORY_MAX = 500
#: Kept poses at most: a Save's compile time and the page's state grow with them (200 save in about 0.2 s of CPU).
KEPT_MAX = 200


class Generator:
    """An interactive posing run for one figure.

    Parameters
    ----------
    figure : Figure
        The model to pose.  It needs at least one joint.
    seed : int
        0 .. 2**32 - 1; decides which alternatives fill the last slots.
    intensity : float
        0 .. 1, the mutation intensity (see :meth:`set_intensity`).
    mode : {"flexion", "twist"}
        What the next generation mutates.

    Attributes
    ----------
    current : ndarray, shape (J, 3)
        The pose being built, in the figure's joint order.
    candidates : ndarray, shape (9, J, 3)
        The current population.
    levels : ndarray of int, shape (9, J)
        The tessellation level each candidate's gene came from (-1: the
        gene kept the seed's configuration).
    generation : int
        1 for the first population.
    kept : list of ndarray, shape (J, 3)
        Poses kept as keyframes, in order.
    kept_frames : list of int
        The frame of each kept pose in the motion Save writes: 0 for the
        first (the motion's starting position), increasing.
    frozen : ndarray of bool, shape (J,)
        Joints that mutation leaves alone.
    """

    def __init__(self, figure, seed: int = 1, intensity: float = 0.25, mode: str = "flexion"):
        if figure.n_joints == 0:
            raise ValueError("the model has no joints, so there is nothing to pose")
        self.figure = figure
        self.axes = joint_axes(figure)
        self.neutral = K.clamp(figure, np.zeros((figure.n_joints, 3)))
        self.current = self.neutral.copy()
        self.kept: list = []
        self.kept_frames: list = []
        self.frozen = np.zeros(figure.n_joints, dtype=bool)
        self.intensity = 0.25
        self.mode = "flexion"
        self.set_intensity(intensity)
        self.set_mode(mode)
        self._history: list = []
        self._restart(seed)

    # ------------------------------------------------------------ settings
    def set_intensity(self, value: float) -> None:
        """Set the mutation intensity, 0 .. 1: the maximum distance is ``180 * value`` degrees."""
        v = float(value)
        if not 0.0 <= v <= 1.0:
            raise ValueError(f"the intensity must be between 0 and 1, not {value!r}")
        self.intensity = v

    def set_mode(self, mode: str) -> None:
        """Choose what the next generation mutates: ``"flexion"`` (flexion & pivot) or ``"twist"``."""
        if mode not in MODES:
            raise ValueError(f"the mode must be 'flexion' or 'twist', not {mode!r}")
        self.mode = mode

    @property
    def max_distance(self) -> float:
        """Degrees: how far a later generation's alternatives may be from the seed pose."""
        return 180.0 * self.intensity

    # -------------------------------------------------------------- actions
    def set_seed(self, seed: int) -> None:
        """Start over at generation 1 with a new seed (the current pose and kept poses stay)."""
        seed = self._valid_seed(seed)
        self._push()
        self._restart(seed)

    def next_generation(self) -> None:
        """Mutate the current pose into nine new candidates."""
        self._push()
        self._generate()

    def take(self, candidate: int, joint: int) -> None:
        """Crossover: joint ``joint``'s angles of candidate ``candidate`` into the current pose.

        Parameters
        ----------
        candidate : int
            0 .. 8.
        joint : int
            Index in the figure's joint order.
        """
        candidate, joint = self._check_index(candidate, POPULATION, "candidate"), self._check_joint(joint)
        self._push()
        self.current = self.current.copy()
        self.current[joint] = self.candidates[candidate, joint]

    def toggle_frozen(self, joint: int) -> None:
        """Let mutation move a joint again, or stop it from moving (the thesis' mask)."""
        joint = self._check_joint(joint)
        self._push()
        self.frozen = self.frozen.copy()
        self.frozen[joint] = not self.frozen[joint]

    def stand(self) -> None:
        """Put the current pose back to standing (neutral)."""
        self._push()
        self.current = self.neutral.copy()

    def keep(self, spacing: int = 24) -> None:
        """Append the current pose to the kept poses (the next keyframe, ``spacing`` frames after the last).

        Raises
        ------
        ValueError
            When :data:`KEPT_MAX` poses are kept already.
        """
        if len(self.kept) >= KEPT_MAX:
            raise ValueError(f"at most {KEPT_MAX} poses may be kept")
        self._push()
        self.kept = self.kept + [self.current.copy()]
        self.kept_frames = self.kept_frames + [self.kept_frames[-1] + spacing if self.kept_frames else 0]

    def set_angles(self, joint: int, angles) -> None:
        """Set one joint's three angles in the current pose, clamped into its extremes (a direct edit)."""
        joint = self._check_joint(joint)
        a = np.asarray(angles, dtype=np.float64).reshape(-1)
        if a.shape != (3,) or not np.isfinite(a).all():
            raise ValueError("the angles must be three finite numbers")
        ext = np.asarray(self.figure.extremes[joint], dtype=np.float64).reshape(3, 2)
        self._push()
        self.current = self.current.copy()
        self.current[joint] = np.clip(a, ext[:, 0], ext[:, 1])

    def recall(self, k: int) -> None:
        """Make kept pose ``k`` the current pose again (to edit it, or keep a variation)."""
        k = self._check_index(k, len(self.kept), "kept pose")
        self._push()
        self.current = self.kept[k].copy()

    def delete_kept(self, k: int) -> None:
        """Remove kept pose ``k``; the poses after it keep their frames (the first, if removed, gives 0 to the next)."""
        k = self._check_index(k, len(self.kept), "kept pose")
        self._push()
        self.kept = self.kept[:k] + self.kept[k + 1 :]
        frames = self.kept_frames[:k] + self.kept_frames[k + 1 :]
        self.kept_frames = [0] + frames[1:] if frames else []

    def move_kept(self, k: int, to: int) -> None:
        """Move kept pose ``k`` to place ``to``; the frames stay where they are, the poses change places."""
        k = self._check_index(k, len(self.kept), "kept pose")
        to = self._check_index(to, len(self.kept), "place")
        self._push()
        kept = list(self.kept)
        kept.insert(to, kept.pop(k))
        self.kept = kept

    def set_kept_frame(self, k: int, frame: int) -> None:
        """Give kept pose ``k`` (not the first, whose frame is 0) the frame ``frame``, between its neighbours'."""
        k = self._check_index(k, len(self.kept), "kept pose")
        lo = self.kept_frames[k - 1] + 1 if k > 0 else 0
        hi = self.kept_frames[k + 1] - 1 if k + 1 < len(self.kept) else 10**6
        if k == 0 and frame != 0:
            raise ValueError("the first kept pose is the motion's starting position, at frame 0")
        if isinstance(frame, bool) or not isinstance(frame, (int, np.integer)) or not lo <= frame <= hi:
            raise ValueError(f"kept pose {k + 1}'s frame must be a whole number from {lo} to {hi}")
        self._push()
        self.kept_frames = self.kept_frames[:k] + [int(frame)] + self.kept_frames[k + 1 :]

    def undo(self) -> bool:
        """Go back one action (take, set, generation, seed, freeze, stand, keep, an edit of the kept poses); False if none."""
        if not self._history:
            return False
        (
            self.current,
            self.candidates,
            self.levels,
            self.generation,
            state,
            self.kept,
            self.kept_frames,
            self.frozen,
            self.seed,
        ) = self._history.pop()
        self._rng.bit_generator.state = state
        return True

    @property
    def can_undo(self) -> bool:
        """Whether :meth:`undo` has something to undo."""
        return bool(self._history)

    # --------------------------------------------------------------- poses
    def transforms(self, angles: np.ndarray) -> np.ndarray:
        """Segment matrices of poses, exactly as the renderer computes them (no clamping).

        Parameters
        ----------
        angles : ndarray, shape (N, J, 3)

        Returns
        -------
        ndarray, shape (N, L, 4, 4)
        """
        angles = np.asarray(angles, dtype=np.float64)
        placements = np.broadcast_to(np.eye(4), (len(angles), 4, 4))
        return world_transforms(self.figure, angles, placements)

    def joint_of_link(self, link: int):
        """The joint index that moves link ``link``, or None for the main link."""
        parent = self.figure.parent_joint_of(self._check_index(link, self.figure.n_links, "link"))
        return None if parent is None else self.figure.joint_index(parent.id)

    # ------------------------------------------------------------- private
    @staticmethod
    def _valid_seed(seed) -> int:
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) <= SEED_MAX:
            raise ValueError(f"the seed must be a whole number from 0 to {SEED_MAX}, not {seed!r}")
        return int(seed)

    def _restart(self, seed) -> None:
        self.seed = self._valid_seed(seed)
        self._rng = np.random.Generator(np.random.PCG64(self.seed))
        self.generation = 0
        self._generate()

    def _generate(self) -> None:
        self.generation += 1
        first = self.generation == 1
        J = self.figure.n_joints
        out = np.broadcast_to(self.current, (POPULATION, J, 3)).copy()
        levels = np.full((POPULATION, J), -1, dtype=np.int64)
        for ax in self.axes:
            if self.frozen[ax.index]:
                continue
            alt = alternatives(ax, self.current[ax.index], self.mode, first, self.max_distance, POPULATION)
            n = len(alt.values)
            if n == 0:
                continue
            pick = self._fill(alt.level)
            cols = list(alt.axes)
            for i in range(POPULATION):
                k = pick[i % len(pick)]
                out[i, ax.index, cols] = alt.values[k]
                levels[i, ax.index] = alt.level[k]
        self.candidates = out
        self.levels = levels

    def _fill(self, level: np.ndarray) -> np.ndarray:
        """Indices of the alternatives shown, coarsest levels first, in order (Fig. IV.9).

        Whole levels are taken until there are nine; the last level needed
        gives only as many as are missing, drawn by the seeded generator
        and kept in order.
        """
        chosen: list = []
        for lev in np.unique(level):
            idx = np.flatnonzero(level == lev)
            missing = POPULATION - len(chosen)
            if len(idx) <= missing:
                chosen.extend(idx.tolist())
            else:
                chosen.extend(np.sort(self._rng.choice(idx, size=missing, replace=False)).tolist())
            if len(chosen) >= POPULATION:
                break
        return np.asarray(chosen, dtype=np.int64)

    def _push(self) -> None:
        self._history.append(
            (
                self.current,
                self.candidates,
                self.levels,
                self.generation,
                copy.deepcopy(self._rng.bit_generator.state),
                self.kept,
                self.kept_frames,
                self.frozen,
                self.seed,
            )
        )
        if len(self._history) > HISTORY_MAX:
            del self._history[0]

    def _check_joint(self, joint) -> int:
        return self._check_index(joint, self.figure.n_joints, "joint")

    @staticmethod
    def _check_index(value, size: int, what: str) -> int:
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 0 <= int(value) < size:
            raise ValueError(f"the {what} must be a whole number from 0 to {size - 1}, not {value!r}")
        return int(value)
