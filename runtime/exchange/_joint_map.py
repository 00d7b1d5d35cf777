"""Which joint of a capture drives which link of a figure: automatic maps for common skeletons, and map files.

Both sides are described by *roles* (``hips``, ``spine``, ``chest``,
``neck``, ``head``, and per side ``upperleg``, ``lowerleg``, ``foot``,
``toe``, ``clavicle``, ``upperarm``, ``forearm``, ``hand``).  A *profile*
names the joints of one family of skeletons by role; a skeleton takes the
profile that names most of its joints.  Names are compared without case,
without a ``prefix:`` (``mixamorig:Hips``) and without characters other
than letters and digits (``thigh.L`` is ``thighl``, ``L_THIGH`` is
``lthigh``).  A role that only one side has is left out and reported.

A map file (``--map FILE``) names the pairs itself, one a line::

    # capture joint = figure link
    Hips = TOP
    LeftUpLeg = L_THIGH

Blank lines and ``#`` comments are ignored; the capture's joint is its name
in the BVH file, the link a segment name of the figure.  Every name must
exist: an unknown one is an error at its line and column.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from liganimate.lang.ast import Pos
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics
from liganimate.runtime.errors import LigError

__all__ = ["JointMap", "auto_map", "normalized", "read_map"]

SIDES = ("L", "R")
LIMB_ROLES = ("upperleg", "lowerleg", "foot", "toe", "clavicle", "upperarm", "forearm", "hand")
LEG = ("upperleg", "lowerleg", "foot")


def _sided(left: dict, right: dict) -> dict:
    out = {}
    for role, names in left.items():
        out[("L", role)] = names
    for role, names in right.items():
        out[("R", role)] = names
    return out


def _limbs(fmt_left: str, fmt_right: str, names: dict) -> dict:
    """Roles of both sides from one pattern per side: ``names`` role -> list of spellings of the limb."""
    left = {role: [fmt_left.format(n) for n in spellings] for role, spellings in names.items()}
    right = {role: [fmt_right.format(n) for n in spellings] for role, spellings in names.items()}
    return _sided(left, right)


#: name -> {role: [normalized spellings, best first]}
PROFILES: dict = {
    # The CMU database's BVH conversions and bvhtoolbox's mocapbank take (Hips, Chest, LeftHip, LeftKnee...).
    "CMU/mocapbank": {
        "hips": ["hips"],
        "spine": ["chest", "lowerback", "spine"],
        "chest": ["chest2", "chest3", "spine1"],
        "neck": ["neck", "neck1"],
        "head": ["head"],
        **_limbs(
            "left{}",
            "right{}",
            {
                "upperleg": ["hip", "upleg"],
                "lowerleg": ["knee", "leg"],
                "foot": ["ankle", "foot"],
                "toe": ["toe", "toebase", "toes"],
                "clavicle": ["collar"],
                "upperarm": ["shoulder"],
                "forearm": ["elbow"],
                "hand": ["wrist", "hand"],
            },
        ),
    },
    # Mixamo (mixamorig:LeftUpLeg...) and the ASF-style names of many other exporters.
    "Mixamo": {
        "hips": ["hips"],
        "spine": ["spine"],
        "chest": ["spine2", "spine1"],
        "neck": ["neck"],
        "head": ["head"],
        **_limbs(
            "left{}",
            "right{}",
            {
                "upperleg": ["upleg"],
                "lowerleg": ["leg"],
                "foot": ["foot"],
                "toe": ["toebase", "toe"],
                "clavicle": ["shoulder"],
                "upperarm": ["arm"],
                "forearm": ["forearm"],
                "hand": ["hand"],
            },
        ),
    },
    # Blender's Rigify and its metarig (pelvis or hips, spine.001, thigh.L, shin.L...).
    "Rigify": {
        "hips": ["pelvis", "hips", "root"],
        "spine": ["spine"],
        "chest": ["spine003", "spine002", "spine001", "chest"],
        "neck": ["neck", "spine004"],
        "head": ["head", "face", "spine006"],
        **_limbs(
            "{}l",
            "{}r",
            {
                "upperleg": ["thigh"],
                "lowerleg": ["shin"],
                "foot": ["foot"],
                "toe": ["toe"],
                "clavicle": ["shoulder"],
                "upperarm": ["upperarm"],
                "forearm": ["forearm"],
                "hand": ["hand"],
            },
        ),
    },
    # The standard library's HUMANOID (stdlib/humanoid.lig) and figures built like it.
    "liganimate humanoid": {
        "hips": ["top", "pelvis"],
        "spine": ["spine"],
        "neck": ["neck"],
        "head": ["head"],
        **_limbs(
            "l{}",
            "r{}",
            {
                "upperleg": ["thigh"],
                "lowerleg": ["shin"],
                "foot": ["foot"],
                "upperarm": ["upperarm"],
                "forearm": ["forearm"],
                "hand": ["hand"],
            },
        ),
    },
}


def normalized(name: str) -> str:
    """A joint name as profiles spell it: no ``prefix:``, lower case, letters and digits only."""
    return re.sub(r"[^a-z0-9]", "", name.rsplit(":", 1)[-1].lower())


def role_of(names: list) -> tuple:
    """``(profile name, {role: index into names})`` of the profile that names most of ``names``."""
    keys = [normalized(n) for n in names]
    best: tuple = ("", {})
    for profile, roles in PROFILES.items():
        found = {}
        for role, spellings in roles.items():
            for s in spellings:
                if s in keys:
                    found[role] = keys.index(s)
                    break
        if len(found) > len(best[1]):
            best = (profile, found)
    return best


@dataclass(frozen=True)
class JointMap:
    """Pairs of (capture joint index, figure link index), in the capture's order, and what was left out.

    Attributes
    ----------
    pairs : tuple of (int, int)
    source_profile, target_profile : str
        The profiles chosen ("map file" for a map file).
    unmapped_source : tuple of str
        Capture joints that drive nothing.
    unmapped_target : tuple of str
        Figure links with a joint that nothing drives (they stay at neutral).
    feet : dict
        ``{side: (source upperleg, lowerleg, foot joints), (figure upperleg, lowerleg, foot links)}``
        of each side whose leg both have.
    """

    pairs: tuple
    source_profile: str
    target_profile: str
    unmapped_source: tuple
    unmapped_target: tuple
    feet: dict


def auto_map(source_names: list, target_names: list, target_links_with_joints: list) -> JointMap:
    """The automatic map between a capture and a figure.

    Parameters
    ----------
    source_names : list of str
        The capture's joints.
    target_names : list of (list of str)
        Each figure link's names (its LIG name and its source name).
    target_links_with_joints : list of int
        The links that have a joint (the ones a motion can turn).

    Raises
    ------
    LigError
        When either side has no two legs that the profiles recognize.
    """
    s_profile, s_roles = role_of(source_names)
    t_roles: dict = {}
    t_profile = ""
    for variant in range(max(len(n) for n in target_names)):
        names = [n[min(variant, len(n) - 1)] for n in target_names]
        profile, roles = role_of(names)
        if len(roles) > len(t_roles):
            t_profile, t_roles = profile, roles
    _need_legs(s_roles, "capture", "its hips, thighs, shins and feet")
    _need_legs(t_roles, "figure", "links for the hips, thighs, shins and feet")
    if "chest" not in t_roles and "chest" in s_roles:
        # One spine link on the figure: it follows the top of the capture's spine.
        s_roles = dict(s_roles, spine=s_roles["chest"])
        del s_roles["chest"]
    pairs = sorted((s_roles[r], t_roles[r]) for r in s_roles if r in t_roles)
    return _finish(pairs, s_profile, t_profile, source_names, target_names, target_links_with_joints, s_roles, t_roles)


def _need_legs(roles: dict, side: str, what: str) -> None:
    missing = [f"{s} {r}" for s in SIDES for r in LEG if (s, r) not in roles] + (
        ["hips"] if "hips" not in roles else []
    )
    if missing:
        raise LigError(
            f"the {side} has no legs that liganimate recognizes (no {', '.join(missing[:4])}).",
            f"retargeting needs {what}; name them in a map file given with --map (see docs/exchange.md)",
        )


def _finish(pairs, s_profile, t_profile, source_names, target_names, driven, s_roles, t_roles) -> JointMap:
    used_s = {s for s, _ in pairs}
    used_t = {t for _, t in pairs}
    feet = {}
    for side in SIDES:
        if all((side, r) in s_roles and (side, r) in t_roles for r in LEG):
            feet[side] = (tuple(s_roles[(side, r)] for r in LEG), tuple(t_roles[(side, r)] for r in LEG))
    return JointMap(
        pairs=tuple(pairs),
        source_profile=s_profile,
        target_profile=t_profile,
        unmapped_source=tuple(n for i, n in enumerate(source_names) if i not in used_s),
        unmapped_target=tuple(target_names[i][0] for i in driven if i not in used_t),
        feet=feet,
    )


def read_map(path: str, source_names: list, target_names: list, target_links_with_joints: list) -> JointMap:
    """A map file's pairs (see the module's docstring), checked against both skeletons.

    Raises
    ------
    LigDiagnostics
        At the line and column of a malformed line or an unknown name.
    OSError
        If the file cannot be read.
    """
    with open(path, encoding="utf-8", errors="replace") as fh:
        text = fh.read()
    s_index = {n: i for i, n in enumerate(source_names)}
    t_index: dict = {}
    for i, names in enumerate(target_names):
        for n in names:
            t_index.setdefault(n.upper(), i)
    pairs = []

    def fail(line: int, col: int, width: int, message: str, hint: str) -> LigDiagnostics:
        pos = Pos(line, col, line, col + max(width, 1))
        return LigDiagnostics([Diagnostic(path, pos, message, hint, source=text)])

    for number, raw in enumerate(text.split("\n"), start=1):
        body = raw.split("#", 1)[0]
        if not body.strip():
            continue
        left, eq, right = body.partition("=")
        if not eq or not left.strip() or not right.strip():
            col = len(raw) - len(raw.lstrip()) + 1
            raise fail(
                number, col, len(body.strip()), "a map line is 'capture joint = figure link'", "see docs/exchange.md"
            )
        s_name, t_name = left.strip(), right.strip()
        if s_name not in s_index:
            close = _closest(s_name, source_names)
            raise fail(number, raw.index(s_name) + 1, len(s_name), f"the capture has no joint called {s_name}", close)
        if t_name.upper() not in t_index:
            close = _closest(t_name, [n[0] for n in target_names])
            col = len(left) + 1 + right.index(t_name) + 1
            raise fail(number, col, len(t_name), f"the figure has no link called {t_name}", close)
        pairs.append((s_index[s_name], t_index[t_name.upper()]))
    if not pairs:
        raise LigError(f"{path} maps no joint.", "write one 'capture joint = figure link' a line")
    s_roles = role_of(source_names)[1]
    by_target = {t: s for s, t in pairs}
    t_roles = {role: t for role, t in role_of([n[0] for n in target_names])[1].items() if t in by_target}
    s_roles = {role: by_target[t] for role, t in t_roles.items()} | {
        r: i for r, i in s_roles.items() if r not in t_roles
    }
    return _finish(
        sorted(pairs), "map file", "map file", source_names, target_names, target_links_with_joints, s_roles, t_roles
    )


def _closest(name: str, names: list) -> str:
    import difflib

    close = difflib.get_close_matches(name, names, n=1, cutoff=0.5)
    return f"did you mean {close[0]}?" if close else "names are as the BVH file and the figure's library spell them"
