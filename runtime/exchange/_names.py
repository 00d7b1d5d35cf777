"""The names a figure's links and joints take in exported files.

A link's own name (the graphical variable it was drawn from) where it is
unique within the figure; otherwise, and for unnamed links, that name (or
``SEGMENT``) with the id of the joint that attached the link.  These are
the names the glTF rigs give bones and segment nodes, so a bone reads
``R_THIGH`` in Blender and three.js, as the program calls the segment.
"""

from __future__ import annotations

__all__ = ["link_names"]


def link_names(fig) -> list[str]:
    """One distinct name per link of ``fig``, in link order.

    Parameters
    ----------
    fig : Figure

    Returns
    -------
    list of str
        The link's name where no other link of the figure has it; else the
        name followed by `` <joint id>`` of the joint that attaches it (``ROOT``
        for the original main link); ``SEGMENT <joint id>`` for an unnamed link.
    """
    counts: dict = {}
    for l in fig.links:
        if l.name is not None:
            counts[l.name.upper()] = counts.get(l.name.upper(), 0) + 1
    names = []
    for i, l in enumerate(fig.links):
        named = l.name is not None and not l.name.startswith("<")
        base = l.name if named else "SEGMENT"
        if not named or counts.get(l.name.upper(), 0) > 1:
            up = fig.parent_joint_of(i)
            base = f"{base} {up.id}" if up is not None else f"{base} ROOT"
        names.append(base)
    taken: set = set()
    for i, name in enumerate(names):
        # Two links called FOOT and a third called "FOOT 4" could still meet.
        unique, n = name, 2
        while unique.upper() in taken:
            unique, n = f"{name} ({n})", n + 1
        taken.add(unique.upper())
        names[i] = unique
    return names
