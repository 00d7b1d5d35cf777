"""PRIMITIVE invocation patterns and matching calls against them.

A pattern such as Appendix A's::

    BOX ::= 'BOX' [ 'AT' CENTRE ',' ] <CENTRE = (0.0, 0.0, 0.0)>
            'WIDTH' WIDTH ',' 'HEIGHT' HEIGHT ',' 'DEPTH' DEPTH
            [ ',' 'LIGHTNESS' LIGHT ] <LIGHT = 40.0> ;

is read as a series of *slots*, each a keyword followed by a parameter,
some grouped as optional with defaults. Commas in the pattern separate
slots; a call writes its slots in the same order, separated by commas.
"""

from __future__ import annotations

from dataclasses import field

from liganimate.lang import ast as A
from liganimate.lang.diagnostics import did_you_mean
from liganimate.lang.node_methods import record

from . import types as T


@record
class Slot:
    keyword: str
    param: str
    group: int | None  # None when required, else the optional group's number


@record
class Signature:
    """What a primitive call must look like, and the defaults of its optional parts."""

    name: str
    slots: list
    defaults: dict = field(default_factory=dict)  # param -> expr node (or a Python constant)
    param_types: dict = field(default_factory=dict)  # keyword -> type

    @property
    def params(self) -> list:
        """Parameter names in slot order."""
        return [s.param for s in self.slots]

    def usage(self) -> str:
        """A one-line reminder of the call syntax."""
        out = [self.name]
        for s in self.slots:
            piece = f"{s.keyword} {s.param.lower()}"
            if s.group is not None:
                piece = f"[{piece}]"
            out.append(piece)
        return out[0] + " " + ", ".join(out[1:])

    def match(self, call: A.PrimCall) -> list:
        """Match a call's clauses; return (node, message, hint) for each problem."""
        problems = []
        clauses = list(call.clauses)
        i = 0
        slots = self.slots
        k = 0
        seen = set()
        while k < len(slots):
            slot = slots[k]
            if slot.group is not None:
                group = [s for s in slots[k:] if s.group == slot.group]
                present = i < len(clauses) and clauses[i].keyword == group[0].keyword
                if present:
                    for s in group:
                        if i < len(clauses) and clauses[i].keyword == s.keyword:
                            seen.add(s.keyword)
                            i += 1
                        else:
                            at = clauses[i] if i < len(clauses) else call
                            problems.append((at, f"{self.name} expects {s.keyword} here", self.usage()))
                            return problems
                k += len(group)
                continue
            if i < len(clauses) and clauses[i].keyword == slot.keyword:
                seen.add(slot.keyword)
                i += 1
            else:
                at = clauses[i] if i < len(clauses) else call
                if i < len(clauses) and any(s.keyword == clauses[i].keyword for s in slots):
                    msg = f"{self.name} expects {slot.keyword} before {clauses[i].keyword}"
                elif i < len(clauses):
                    msg = f"{self.name} expects {slot.keyword} here, not {clauses[i].keyword}"
                else:
                    msg = f"{self.name} needs {slot.keyword}"
                problems.append((at, msg, self.usage()))
                return problems
            k += 1
        if i < len(clauses):
            extra = clauses[i]
            known = [s.keyword for s in slots]
            if extra.keyword in seen:
                problems.append((extra, f"{self.name} takes {extra.keyword} only once", self.usage()))
            elif extra.keyword in known:
                problems.append((extra, f"{extra.keyword} is out of order in this {self.name} call", self.usage()))
            else:
                hint = did_you_mean(extra.keyword, known) or self.usage()
                problems.append((extra, f"{self.name} has no {extra.keyword}", hint))
        return problems


def signature_from_pattern(name: str, pattern: A.PatternDef):
    """Read a pattern into a Signature; also return (node, message) problems."""
    problems = []
    items = list(pattern.items)
    if not items or not isinstance(items[0], A.PatWord) or items[0].word != name:
        problems.append((pattern, f"the pattern of {name} must begin with '{name}'"))
    else:
        items = items[1:]
    slots, defaults = [], {}
    group_no = 0

    def walk(seq, group):
        pending = None
        for it in seq:
            if isinstance(it, A.PatWord):
                if it.word == ",":
                    if pending is not None:
                        problems.append((it, f"'{pending.word}' needs a parameter name after it"))
                        pending = None
                    continue
                if pending is not None:
                    problems.append((it, f"'{pending.word}' needs a parameter name after it"))
                pending = it
            elif isinstance(it, A.PatParam):
                if pending is None:
                    problems.append((it, f"parameter {it.name} needs a quoted keyword before it"))
                    continue
                slots.append(Slot(pending.word, it.name, group))
                pending = None
            elif isinstance(it, A.PatOptional):
                nonlocal group_no
                if group is not None:
                    problems.append((it, "optional parts cannot be nested"))
                    continue
                group_no += 1
                walk(it.items, group_no)
                for dname, dexpr in it.defaults:
                    defaults[dname.name] = dexpr
        if pending is not None:
            problems.append((pending, f"'{pending.word}' needs a parameter name after it"))

    walk(items, None)
    return Signature(name, slots, defaults), problems


def builtin_signatures() -> dict:
    """Signatures of the primitives every program knows (BOX, with Appendix A's syntax)."""
    box = Signature(
        "BOX",
        [
            Slot("AT", "CENTRE", 1),
            Slot("WIDTH", "WIDTH", None),
            Slot("HEIGHT", "HEIGHT", None),
            Slot("DEPTH", "DEPTH", None),
            Slot("LIGHTNESS", "LIGHT", 2),
        ],
        {"CENTRE": (0.0, 0.0, 0.0), "LIGHT": 40.0},
        {"AT": T.VECTOR, "WIDTH": T.REAL, "HEIGHT": T.REAL, "DEPTH": T.REAL, "LIGHTNESS": T.REAL},
    )
    return {"BOX": box}
