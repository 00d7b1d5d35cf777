"""The document's outline (models, motions, scenes, primitives, variables) and its folding ranges.

Symbols come from the syntax tree: each STARTMODEL, STARTMOTION,
STARTREACH, scene and PRIMITIVE with the span of its block, and every
other variable of the main program at its first definition, with the
kind its type gives it. Folding comes from the tolerant scan, so blocks
fold while the text is broken too.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

from liganimate.lang import ast as A

from . import index as I
from . import scan
from .analysis import Analysis
from .text import Text


@dataclass
class Symbol:
    """One entry of the outline: offsets of the whole construct and of its name."""

    name: str
    kind: str  # model, motion, scene, primitive, variable, number, vector, graphical
    detail: str
    start: int
    end: int
    name_start: int
    name_end: int
    children: list = field(default_factory=list)


_BLOCK_KIND = {A.ModelBlock: "model", A.MotionBlock: "motion", A.ReachBlock: "motion"}


def symbols(a: Analysis) -> list:
    """The outline of an analysis whose text parsed (empty otherwise)."""
    if a.program is None or a.index is None:
        return []
    text = a.text
    out: list = []
    seen: set = set()
    for s in a.program.body:
        start, end = text.offset_of(s.pos.line, s.pos.column), text.offset_of(s.pos.end_line, s.pos.end_column)
        kind = _BLOCK_KIND.get(type(s))
        if kind is not None:
            n = s.name
            ns = text.offset_of(n.pos.line, n.pos.column)
            detail = {A.ModelBlock: "STARTMODEL", A.MotionBlock: "STARTMOTION", A.ReachBlock: "STARTREACH"}[type(s)]
            out.append(Symbol(n.name, kind, detail, start, end, ns, ns + len(n.name)))
            seen.add(n.name)
        elif isinstance(s, A.Scene):
            ident = a.text.source[s.scene_id.pos.start : s.scene_id.pos.end] or "?"
            out.append(Symbol(f"SCENE {ident}", "scene", "INITIALIZE ... ENDSCENE", start, end, start, start))
        elif isinstance(s, A.PrimitiveDef):
            n = s.name
            ns = text.offset_of(n.pos.line, n.pos.column)
            out.append(Symbol(n.name, "primitive", "PRIMITIVE", start, end, ns, ns + len(n.name)))
            seen.add(n.name)
    types = a.checked.main.types if a.checked is not None else {}
    for (scope, name), occs in a.index.by_key.items():
        if scope != I.MAIN or name in seen:
            continue
        first = next((o for o in occs if o.role in ("declaration", "assignment", "load")), None)
        if first is None:
            continue
        kind = (types.get(name) or "variable").lower()
        detail = types.get(name, "") + (" (loaded)" if first.role == "load" else "")
        out.append(Symbol(name, kind, detail.strip(), first.start, first.end, first.start, first.end))
    out.sort(key=lambda s: s.start)
    return out


@dataclass(frozen=True)
class Fold:
    """A range of lines (0-based, inclusive) that may be folded; ``comment`` for comments."""

    start_line: int
    end_line: int
    comment: bool = False


def folds(source: str) -> list:
    """The folding ranges of ``source``: blocks that close, multi-line comments and runs of C comment lines."""
    toks = scan.tokens(source)
    starts = Text(source).starts

    def line(offset: int) -> int:
        return bisect.bisect_right(starts, offset) - 1

    out = []
    for b in scan.blocks(toks):
        if b.end is None:
            continue
        first, last = line(b.start), line(b.end)
        if last - 1 > first:
            out.append(Fold(first, last - 1))  # the closing word stays visible
    run_start = run_end = None
    for t in toks:
        if t.kind != "comment":
            continue
        first, last = line(t.start), line(t.end)
        if last > first:
            out.append(Fold(first, last, True))
        if run_end is not None and first == run_end + 1 and source[t.start : t.start + 1] in "Cc":
            run_end = last
            continue
        if run_start is not None and run_end is not None and run_end > run_start:
            out.append(Fold(run_start, run_end, True))
        run_start, run_end = (first, last) if source[t.start : t.start + 1] in "Cc" else (None, None)
    if run_start is not None and run_end is not None and run_end > run_start:
        out.append(Fold(run_start, run_end, True))
    return sorted(set(out), key=lambda f: (f.start_line, f.end_line))


__all__ = ["Fold", "Symbol", "folds", "symbols"]
