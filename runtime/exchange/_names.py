"""The names a figure's links take in exported glTF files, and the root a source did not have.

A link imported from a capture keeps the name the capture gave it
(``Link.source``, from the library's name table: ``mixamorig:Hips``).  A
link made in LIG is called by its own name (the graphical variable it was
drawn from) where that is unique within the figure; otherwise, and when
unnamed, by that name (or ``SEGMENT``) with the id of the joint that
attached it.  So a bone reads ``R_THIGH`` or ``mixamorig:Hips`` in Blender
and three.js, as the program or the capture calls the segment.
"""

from __future__ import annotations

from liganimate.runtime.values import Graphical

__all__ = ["added_origin", "joint_names", "link_names", "own_names"]


def own_names(fig, spell, sep: str) -> list[str]:
    """Per link of ``fig``: its source's name, else ``spell(name)``, with the joint id where not unique.

    The rule every exporter follows (glTF with ``spell=str, sep=" "``, BVH
    with names cut to its alphabet and ``sep="_"``); the names are not made
    distinct (:func:`link_names` does that for glTF).

    Parameters
    ----------
    fig : Figure
    spell : callable
        A LIG link name to the exporter's spelling of it.
    sep : str
        What stands between a name and the id of the joint that attaches it
        (``ROOT`` for the original main link).

    Returns
    -------
    list of str
    """
    counts: dict = {}
    for l in fig.links:
        if l.name is not None:
            counts[l.name.upper()] = counts.get(l.name.upper(), 0) + 1
    names = []
    for i, l in enumerate(fig.links):
        if l.source is not None:
            names.append(l.source.name)
            continue
        named = l.name is not None and not l.name.startswith("<")
        base = spell(l.name) if named else "SEGMENT"
        if not named or counts.get(l.name.upper(), 0) > 1:
            up = fig.parent_joint_of(i)
            base = f"{base}{sep}{up.id}" if up is not None else f"{base}{sep}ROOT"
        names.append(base)
    return names


def link_names(fig) -> list[str]:
    """One distinct name per link of ``fig``, in link order.

    Parameters
    ----------
    fig : Figure

    Returns
    -------
    list of str
        The source's name of an imported link; else the link's name where
        no other link of the figure has it; else the
        name followed by `` <joint id>`` of the joint that attaches it (``ROOT``
        for the original main link); ``SEGMENT <joint id>`` for an unnamed link.
    """
    names = own_names(fig, str, " ")
    taken: set = set()
    for i, name in enumerate(names):
        # Two links called FOOT and a third called "FOOT 4" could still meet.
        unique, n = name, 2
        while unique in taken:
            unique, n = f"{name} ({n})", n + 1
        taken.add(unique)
        names[i] = unique
    return names


def joint_names(fig) -> list:
    """Per joint of ``fig``, the name its source gave it (a URDF joint's), or None.

    The name is the one the source gave the joint that attaches the joint's
    secondary link (``Link.source.joint``), whichever way FIGURE ... MAIN
    walks it.
    """
    out = []
    for j in fig.joints:
        source = fig.links[j.secondary].source
        out.append(None if source is None else getattr(source, "joint", None))
    return out


def added_origin(fig) -> bool:
    """Whether the current main link is a root that the figure's source did not have.

    ``liganimate import`` hangs a capture's ROOT under an empty ``ORIGIN``
    link; an exporter that folds it away writes the capture's own root
    again.  True when the main link is empty and has no source, some link
    has one, and the main link holds exactly one sourced link through a
    joint walked forwards.
    """
    main = fig.main
    if fig.links[main].source is not None or not any(l.source is not None for l in fig.links):
        return False
    shape = fig.links[main].shape
    if isinstance(shape, Graphical) and len(shape) > 0 or not fig.traversal:
        return False
    first = fig.traversal[0]
    return len(first.joints) == 1 and not first.reversed[0] and fig.links[first.children[0]].source is not None
