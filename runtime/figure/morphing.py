"""Morphing segments on a model: a motion's SCALE and SHAPE tracks applied to its links.

A motion names links (:mod:`liganimate.runtime.motion.morph`); here they
meet a model.  Both kinds change only what a segment looks like, in its own
coordinates: a scale multiplies the segment's shape along its own axes
(about its own origin), and a shape morph moves its triangles' corners
from the link's own shape towards the target shapes by their weights.  Joint
locations are the model's structure and do not move, so a figure stays
joined whatever its segments become, and re-rooting (FIGURE ... MAIN) does
not change a morph.  A link name that several links share morphs every one
of them.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from liganimate.lang.messages import did_you_mean
from liganimate.lang.numbers import GEOMETRY_MAX, magnitude
from liganimate.runtime.errors import LigError
from liganimate.runtime.figure import tree as F
from liganimate.runtime.motion import morph as mo
from liganimate.runtime.motion.keyframe import Keyframe
from liganimate.runtime.values import Graphical


def target(g: Graphical) -> mo.Target:
    """A shape as a SHAPE keyframe names it: keyed by its content, so equal shapes are one target.

    Parameters
    ----------
    g : Graphical

    Returns
    -------
    Target
    """
    h = hashlib.sha256()
    for a in (g.triangles, g.lightness, g.closed, g.colours()):
        h.update(np.ascontiguousarray(a).tobytes())
        h.update(b"|")
    return mo.Target(h.hexdigest()[:24], g, len(g))


def channels(entries, length: float, fail) -> mo.Morphs | None:
    """The morph channels of a STARTMOTION block, each bad value refused at its own line.

    Parameters
    ----------
    entries : list of (kind, link, start, keyframes, at)
        ``kind`` SCALE or SHAPE; ``keyframes`` as ``(frame, value, method, at)``
        (a value is three factors for SCALE, a Graphical for SHAPE).
    length : float
        The motion's length without them.
    fail : callable (at, message, hint)
        Raises the positioned diagnostic (the host's ``fail``).

    Returns
    -------
    Morphs or None
    """
    scales: dict = {}
    shapes: dict = {}
    for kind, link, start, kfs, jat in entries:
        if kind == mo.SCALE:
            scales[link] = (_factors(link, start, jat, fail, "start") if start is not None else None, [])
            for n, (frame, value, method, kat) in enumerate(kfs, start=1):
                factors = _factors(link, value, kat, fail, f"keyframe {n}")
                scales[link][1].append(Keyframe(frame, factors, method or "LINEAR"))
        else:
            first = None if start is None else target(start)
            keys = [mo.ShapeKey(frame, target(value), method or "LINEAR") for frame, value, method, _ in kfs]
            family = [(jat, first)] + [(k[3], key.target) for k, key in zip(kfs, keys)]
            _same_structure(link, [(at, t) for at, t in family if t is not None], fail)
            shapes[link] = (first, keys)
    from liganimate.runtime.motion.algebra import Motion

    return mo.build(scales, shapes, length, Motion)


def _factors(link: str, value, at, fail, which: str):
    try:
        return mo.check_scale(value, f"the scale of link {link}, {which}")
    except LigError as exc:
        fail(at, exc.message, exc.hint)


def _same_structure(link: str, family: list, fail) -> None:
    if not family:
        return
    first = family[0][1]
    for at, t in family[1:]:
        if t.triangles != first.triangles:
            fail(
                at,
                f"the shape of link {link} cannot in-between {_count(first.triangles)} and {_count(t.triangles)}",
                "a morph needs shapes of the same structure (the same triangles in the same order), "
                "as two BOX calls or two calls of one PRIMITIVE give",
            )


def _count(n: int) -> str:
    return f"a shape of {n} triangle{'s' if n != 1 else ''}"


@dataclass(frozen=True)
class Binding:
    """A motion's morphs matched to one model's links.

    Attributes
    ----------
    scales : tuple of (link indices, link name)
    shapes : tuple of (link indices, link name, targets' triangles in link coordinates per link index,
        which targets are the link's own shape per link index)
    """

    scales: tuple
    shapes: tuple


def bind(fig: F.Figure, morphs: mo.Morphs) -> Binding:
    """Match a motion's morph channels to a model's links.

    Raises
    ------
    LigError
        For a link the model has not (with its link names), or a shape
        whose structure is not the link's own.
    """
    names: dict = {}
    for i, each in enumerate(fig.links):
        if each.name is not None:
            names.setdefault(each.name.upper(), []).append(i)
    scales, shapes = [], []
    for kind in (mo.SCALE, mo.SHAPE):
        for link in morphs.links(kind):
            where = names.get(link)
            if where is None:
                known = sorted(names)
                hint = did_you_mean(link, known) or (
                    f"its links are {', '.join(known)}" if known else "its links have no names"
                )
                raise LigError(f"the motion's {kind} track morphs link {link}, which the model does not have", hint)
            if kind == mo.SCALE:
                scales.append((tuple(where), link))
            else:
                own = {i: _own(fig, i, morphs.shape(link, np.zeros(1))[0]) for i in where}
                shapes.append((tuple(where), link, _targets(fig, where, link, morphs), own))
    binding = Binding(tuple(scales), tuple(shapes))
    _within_limits(fig, binding, morphs)
    return binding


def _within_limits(fig: F.Figure, binding: Binding, morphs: mo.Morphs) -> None:
    """Refuse morphs that would draw beyond the geometry limit (as limits.check_figure measures a model)."""
    size = {
        i: abs(link.scale) * link.shape.extent()
        for i, link in enumerate(fig.links)
        if isinstance(link.shape, Graphical)
    }
    for where, _link, targets, _own in binding.shapes:
        for i in where:
            size[i] = max([size.get(i, 0.0)] + [abs(fig.links[i].scale) * float(np.max(np.abs(t))) for t in targets[i]])
    for where, link in binding.scales:
        factor = morphs.largest_scale(link)
        for i in where:
            size[i] = size.get(i, 0.0) * factor
    p = np.asarray(fig.placement, dtype=np.float64)
    with np.errstate(all="ignore"):
        joints = sum(float(np.max(np.abs(j.loc1))) + float(np.max(np.abs(j.loc2))) for j in fig.joints)
        reach = np.sqrt(3.0) * (joints + max(size.values(), default=0.0))
        far = float(np.linalg.norm(p[:3, :3]) * reach + np.max(np.abs(p[:3, 3])))
    if not far <= GEOMETRY_MAX:
        raise LigError(
            f"with its morphed segments the model can reach {magnitude(far)} units from the origin, beyond the "
            f"limit of {magnitude(GEOMETRY_MAX)} for anything drawn",
            "keep the SCALE LINK factors and SHAPE LINK shapes smaller",
        )


def _own(fig: F.Figure, i: int, targets: list) -> np.ndarray:
    """Which targets are link ``i``'s own shape (equal triangles, lightness and colour)."""
    shape = fig.links[i].shape
    key = target(shape).key if isinstance(shape, Graphical) else None
    return np.array([t.key == key for t in targets], dtype=bool)


def _targets(fig: F.Figure, where: list, link: str, morphs: mo.Morphs) -> dict:
    targets, _ = morphs.shape(link, np.zeros(1))
    out = {}
    for i in where:
        own = fig.links[i].shape
        n = len(own) if isinstance(own, Graphical) else 0
        rows = []
        for t in targets:
            if t.triangles != n:
                raise LigError(
                    f"link {link} has a shape of {n} triangles, so it cannot morph into {_count(t.triangles)}",
                    "a morph needs shapes of the same structure as the link's own segment "
                    "(the same triangles in the same order), as two BOX calls or two calls of one PRIMITIVE give",
                )
            tris = t.shape.triangles
            rows.append(tris[:, ::-1, :] if fig.links[i].scale < 0 else tris)
        out[i] = np.stack(rows) if rows else np.zeros((0, n, 3, 3))
    return out


def apply(binding: Binding, morphs: mo.Morphs, frames, X: np.ndarray, table) -> tuple[np.ndarray, np.ndarray | None]:
    """Link transforms and link-space triangles with the morphs at ``frames``.

    Parameters
    ----------
    binding : Binding
    morphs : Morphs
    frames : ndarray, shape (T,)
    X : ndarray, shape (T, L, 4, 4)
        Shape-to-world transforms (:func:`~.pose.world_transforms`); not changed.
    table : MeshTable

    Returns
    -------
    X : ndarray, shape (T, L, 4, 4)
        ``X @ diag(sx, sy, sz, 1)`` on the scaled links.
    triangles : ndarray, shape (T, M, 3, 3), or None
        The mesh table's triangles, morphed, per frame; None without SHAPE tracks.
    """
    t = np.asarray(frames, dtype=np.float64).reshape(-1)
    if binding.scales:
        X = X.copy()
        for where, link in binding.scales:
            s = morphs.scale(link, t)  # (T, 3)
            X[:, list(where), :3, :3] *= s[:, None, None, :]
    if not binding.shapes:
        return X, None
    local = np.broadcast_to(table.triangles, (len(t), *table.triangles.shape)).copy()
    for where, link, targets, _own in binding.shapes:
        _, w = morphs.shape(link, t)  # (T, K)
        for i in where:
            rows = np.flatnonzero(table.link == i)
            base = table.triangles[rows]
            delta = targets[i] - base[None]  # (K, R, 3, 3)
            local[:, rows] += np.einsum("tk,krij->trij", w, delta)
    return X, local


def record(binding: Binding, morphs: mo.Morphs, frames) -> list[dict]:
    """What ``--poses`` writes for morphed links, per frame: ``{link index: {"scale": [...], "shape": [own]}}``.

    ``own`` is how much of the drawn shape is the segment's own: 1 where it
    shows its own shape (or a shape equal to it), 0 where it shows only
    other shapes.
    """
    t = np.asarray(frames, dtype=np.float64).reshape(-1)
    out: list[dict] = [{} for _ in t]
    for where, link in binding.scales:
        s = morphs.scale(link, t)
        for n in range(len(t)):
            for i in where:
                out[n].setdefault(i, {})["scale"] = s[n].tolist()
    for where, link, _targets, own in binding.shapes:
        _, w = morphs.shape(link, t)
        for i in where:
            mine = 1.0 - w[:, ~own[i]].sum(axis=1)
            for n in range(len(t)):
                out[n].setdefault(i, {})["shape"] = [float(mine[n])]
    return out
