"""Morphing segments in glTF: a motion's SCALE and SHAPE tracks as scale channels and morph targets.

What a drawn model's morphs are, tick by tick (:func:`link_morphs`), and the
morph targets that carry them:

* ``nodes`` rig: a morphed segment's mesh hangs on a *shape node* of its
  own under the segment node (so that its scale does not reach the joints
  below); a SCALE track is that node's ``scale`` channel and a SHAPE track
  the mesh's morph targets (``target_k - own``) with a ``weights`` channel;
* ``skin`` rig: one mesh for the whole figure, whose bones' scale would
  reach their children, so both are morph targets of the skinned mesh
  (:func:`skin_targets`): ``diag(s) (S + sum w_k D_k)`` is
  ``S + sum w_k D_k + sum_c (s_c - 1) S_c + sum_c sum_k (s_c - 1) w_k D_kc``,
  linear in those weights (``S_c``: the own shape's ``c`` coordinates alone).
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.figure.pose import morph_binding

__all__ = ["LinkMorph", "link_morphs", "skin_targets"]


class LinkMorph:
    """One segment's morphs over a take's ticks.

    Attributes
    ----------
    scale : ndarray, shape (T, 3), or None
        Its scale factors, None when no tick scales it.
    targets : list of ndarray, shape (R, 3, 3)
        Target shapes in the segment's coordinates (mesh table order).
    weights : ndarray, shape (T, K)
    """

    def __init__(self, ticks: int):
        self.scale: np.ndarray | None = None
        self.keys: list = []
        self.targets: list = []
        self.weights = np.zeros((ticks, 0))
        self._ticks = ticks

    def scaled(self, rows, s) -> None:
        if self.scale is None:
            self.scale = np.ones((self._ticks, 3))
        self.scale[rows] = s

    def column(self, key: str, triangles: np.ndarray) -> int:
        if key not in self.keys:
            self.keys.append(key)
            self.targets.append(triangles)
            self.weights = np.concatenate([self.weights, np.zeros((self._ticks, 1))], axis=1)
        return self.keys.index(key)


def link_morphs(model) -> dict[int, LinkMorph]:
    """The morphed segments of a drawn model (a ModelTake), by link index; empty when its motions morph nothing."""
    out: dict[int, LinkMorph] = {}
    T = len(model.ticks)
    for rows, fig, motion, frames in model.sources:
        morphs = motion.morphs
        if morphs is None:
            continue
        binding = morph_binding(fig, morphs)
        for where, link in binding.scales:
            s = morphs.scale(link, frames)
            for i in where:
                out.setdefault(i, LinkMorph(T)).scaled(rows, s)
        for where, link, targets, _own in binding.shapes:
            named, w = morphs.shape(link, frames)
            for i in where:
                entry = out.setdefault(i, LinkMorph(T))
                for k, t in enumerate(named):
                    col = entry.column(t.key, targets[i][k])  # (may widen entry.weights)
                    entry.weights[rows, col] = w[:, k]
    return out


def skin_targets(morphs: dict[int, LinkMorph], table, factor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Morph targets of a figure's one skinned mesh, and their weights per tick.

    Parameters
    ----------
    morphs : dict of int to LinkMorph
    table : MeshTable
    factor : ndarray, shape (L,)
        Each link's SCALE MODEL factor (the mesh's coordinates are scaled by it).

    Returns
    -------
    targets : ndarray, shape (N, M, 3, 3)
        Displacements of the mesh table's triangles.
    weights : ndarray, shape (T, N)
    """
    targets, weights = [], []
    M = len(table.triangles)
    for i, m in sorted(morphs.items()):
        rows = table.link == i
        own = table.triangles[rows] * factor[i]
        deltas = [t * factor[i] - own for t in m.targets]

        def put(d, w, rows=rows):
            full = np.zeros((M, 3, 3))
            full[rows] = d
            targets.append(full)
            weights.append(w)

        for k, d in enumerate(deltas):
            put(d, m.weights[:, k])
        if m.scale is not None:
            for c in range(3):
                grow = m.scale[:, c] - 1.0
                only = np.zeros_like(own)
                only[..., c] = own[..., c]
                put(only, grow)
                for k, d in enumerate(deltas):
                    part = np.zeros_like(d)
                    part[..., c] = d[..., c]
                    put(part, grow * m.weights[:, k])
    if not targets:
        return np.zeros((0, M, 3, 3)), np.zeros((0, 0))
    return np.stack(targets), np.stack(weights, axis=1)
