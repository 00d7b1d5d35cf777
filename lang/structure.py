"""Block structure the grammar cannot express: DO loops closed by labels.

``DO 10 I = 1, 5 ... 10 CONTINUE`` is FORTRAN's loop; the label ties the two
together, which a context-free grammar cannot check, so the parser yields a
flat :class:`~liganimate.lang.ast.DoHeader` and :class:`~liganimate.lang.ast.Continue`
and :func:`group_blocks` nests them. It also refuses absurdly deep nesting
before any recursive pass could overflow Python's stack.
"""

from __future__ import annotations

from . import ast as A
from .diagnostics import error
from .visitor import BLOCKS, children, too_deep

#: Deeper syntax trees are refused with a diagnostic (no RecursionError may escape).
MAX_DEPTH = 100


class _ModifierLevel:
    """The first ``count`` modifiers of a modifier chain, as one level of nesting.

    ``A <M1> <M2> <M3>`` is one ``Modified`` node, but its lowering nests one
    call per modifier (``m3(m2(m1(A)))``), so a long chain is as deep as a
    deeply nested expression: the depth check walks it as such levels.
    """

    __slots__ = ("node", "count", "pos")

    def __init__(self, node: A.Modified, count: int) -> None:
        self.node, self.count = node, count
        self.pos = node.modifiers[count - 1].pos


def _levels(node) -> list:
    """The nodes one level below ``node`` as the compiled program nests them (modifier chains unrolled)."""
    if type(node) is A.Modified and len(node.modifiers) > 1:
        node = _ModifierLevel(node, len(node.modifiers))
    if type(node) is _ModifierLevel:
        chain, k = node.node, node.count
        below = chain.target if k == 1 else _ModifierLevel(chain, k - 1)
        return [below, chain.modifiers[k - 1]]
    return children(node)


def check_depth(roots: list, source) -> None:
    """Refuse trees deeper than MAX_DEPTH, iteratively, pointing at the deepest place.

    A chain of modifiers counts one level per modifier, as it nests in the
    compiled program.
    """
    node = too_deep(roots, MAX_DEPTH, inner=_levels)
    if node is not None:
        raise error(
            source.filename,
            node.pos,
            f"this is nested more than {MAX_DEPTH} levels deep",
            "split it into several statements with variables in between",
            source=source.text,
        )


#: Blocks (DO, IF, scenes) nested deeper than this are refused: Python, which
#: runs the compiled program, allows only 20 statically nested blocks.
MAX_BLOCKS = 15


def group_blocks(body: list, source, fresh: list | None = None) -> list:
    """Check nesting depth, then nest DO loops in every statement list.

    ``fresh``, when given, are the only statements of ``body`` whose depth
    is checked: the others are known to pass (lang/incremental.py). The
    error is the same, since a statement that passes holds no node the
    check could report.
    """
    check_depth(body if fresh is None else fresh, source)
    grouped = _group_list(body, source)
    _check_blocks(grouped, source)
    return grouped


def _check_blocks(body: list, source) -> None:
    node = too_deep([s for s in body if type(s) in BLOCKS], MAX_BLOCKS, _inner_blocks, ())
    if node is not None:
        raise error(
            source.filename,
            node.pos,
            f"blocks (DO, IF, scenes) are nested more than {MAX_BLOCKS} deep here",
            "move the inner part into a loop of its own or a PRIMITIVE",
            source=source.text,
        )


def _inner_blocks(node) -> list:
    """The blocks directly inside block ``node``, in source order."""
    return [s for name in BLOCKS[type(node)] for s in getattr(node, name) or () if type(s) in BLOCKS]


# Statements that hold statements before DO loops are grouped (the parser makes no Do).
_INNER = tuple(kind for kind in BLOCKS if kind is not A.Do)


def _group_list(stmts: list, source) -> list:
    out: list = []
    open_dos: list = []  # (header, index in out where its body starts)
    closed: dict = {}  # label -> (DO line, CONTINUE line) of the last loop it closed, for hints
    for stmt in stmts:
        if isinstance(stmt, _INNER):
            _group_inner(stmt, source)
        if isinstance(stmt, A.DoHeader):
            open_dos.append((stmt, len(out)))
            continue
        if isinstance(stmt, A.Continue):
            if not any(h.label == stmt.label for h, _ in open_dos):
                if stmt.label in closed:
                    do_line, end_line = closed[stmt.label]
                    hint = (
                        f"the DO {stmt.label} at line {do_line} was already closed "
                        f"by the {stmt.label} CONTINUE at line {end_line}"
                    )
                else:
                    hint = f"a loop is opened with DO {stmt.label} var = first, last in the same block"
                raise error(
                    source.filename, stmt.pos, f"{stmt.label} CONTINUE closes no DO loop", hint, source=source.text
                )
            # FORTRAN lets nested loops share one terminal label: close them all.
            while open_dos and open_dos[-1][0].label == stmt.label:
                header, start = open_dos.pop()
                closed[stmt.label] = (header.pos.line, stmt.pos.line)
                loop = A.Do(
                    header.pos, header.label, header.var, header.start, header.stop, header.step, out[start:], stmt.pos
                )
                del out[start:]
                out.append(loop)
            if open_dos and any(h.label == stmt.label for h, _ in open_dos):
                inner = open_dos[-1][0]
                raise error(
                    source.filename,
                    stmt.pos,
                    f"{stmt.label} CONTINUE closes a DO loop while the inner DO {inner.label} is still open",
                    f"close DO {inner.label} (line {inner.pos.line}) with {inner.label} CONTINUE first",
                    source=source.text,
                )
            continue
        out.append(stmt)
    if open_dos:
        header = open_dos[0][0]
        raise error(
            source.filename,
            header.pos,
            f"DO {header.label} is never closed by {header.label} CONTINUE",
            f"add '{header.label} CONTINUE' after the last statement of the loop",
            source=source.text,
        )
    return out


def _group_inner(stmt, source) -> None:
    for name in BLOCKS[type(stmt)]:
        stmts = getattr(stmt, name)
        if stmts is not None:
            setattr(stmt, name, _group_list(stmts, source))
