"""Static checks: names, kinds and types, statement placement.

:func:`check` takes a parsed :class:`~liganimate.lang.ast.Program` and returns
a :class:`Checked` program (the symbol tables and the type of every
expression) or raises :class:`~liganimate.lang.diagnostics.LigDiagnostics`
with every error it found. Checks that depend on values (a FIGURE naming a
link the model lacks, overlapping SYNCHRONIZE...) happen when the program
runs, still before anything is rendered.

The checker is split by concern, as Jinja2 and CPython split symbol
tracking from code generation; this module only orders the passes:

* :mod:`.loads`: what the LOAD statements bring, before anything else;
* :mod:`.scopes`: scopes and the rules that bind a name to a type;
* :mod:`.expressions`: the type of every expression (operators from the
  table in ``lang/vocabulary.py``);
* :mod:`.statements`: what each statement needs and where it may stand;
* :mod:`.reports`: where diagnostics go, one collector per pass.

Variables need no declaration: the first assignment declares them with the
type of its value, and an implicit number assigned a REAL anywhere is REAL.
So a scope is walked until its types settle; only the last walk reports.
"""

from __future__ import annotations

from dataclasses import field

from liganimate.lang import ast as A
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.lang.node_methods import record

from . import scopes as S
from . import types as T
from .expressions import ExpressionTyper, expr_type
from .loads import load_libraries
from .primitives import builtin_signatures, signature_from_pattern
from .reports import MAX_ERRORS, SILENT, Report, TooMany
from .scopes import SceneInfo, Scope
from .statements import StatementChecker

__all__ = ["MAX_ERRORS", "Checked", "SceneInfo", "Scope", "check", "expr_type"]

#: Silent passes over a PRIMITIVE before the reporting one (its types settle within them).
PRIMITIVE_PASSES = 3
#: Reporting passes over the main program at most (see :func:`_settle`).
MAIN_PASSES = 4


@record
class Checked:
    """A program that passed the static checks, with what lowering needs."""

    program: A.Program
    main: Scope
    primitives: dict  # NAME -> (PrimitiveDef | None, Signature, Scope | None)
    types: dict  # id(expr node) -> type, literals aside (see expr_type)
    scenes: dict  # id(Scene node) -> SceneInfo
    warnings: list
    libraries: list = field(default_factory=list)  # Library objects, in order of first LOAD
    loads: dict = field(default_factory=dict)  # id(Load node) -> (library index, [names])
    loaded_names: dict = field(default_factory=dict)  # NAME -> library index (values and primitives)
    loaded_primitives: dict = field(default_factory=dict)  # NAME -> library index


def _signatures(program: A.Program, report: Report) -> tuple:
    """The signature of every primitive in force: built-in, then the program's own (from their patterns)."""
    sigs = builtin_signatures()
    primitives: dict = {}
    for p in program.primitives:
        if p.pattern is None:
            report.error(
                p.name,
                f"PRIMITIVE {p.name.name} has no invocation pattern",
                f"add a line such as {p.name.name} ::= '{p.name.name}' 'SIZE' S;",
            )
            continue
        sig, problems = signature_from_pattern(p.name.name, p.pattern)
        for node, message in problems:
            report.error(
                node, message, "a pattern is a series of 'KEYWORD' VALUE pairs separated by ',' (optional parts in [ ])"
            )
        sigs[p.name.name] = sig
        primitives[p.name.name] = (p, sig, None)
    for name, sig in sigs.items():
        if name not in primitives:
            primitives[name] = (None, sig, None)
    return sigs, primitives


class _Passes:
    """The walks over one program's scopes, sharing one :class:`~.scopes.State`."""

    def __init__(self, program: A.Program, sigs: dict, primitives: dict, top_loads: set, report: Report):
        self.program, self.primitives, self.report = program, primitives, report
        self.st = S.State(sigs)
        self.typer = ExpressionTyper(self.st)
        self.stmts = StatementChecker(self.st, self.typer, top_loads)
        self.calls: dict | None = None  # PRIMITIVE -> the primitives it calls (scopes.call_graph)

    def walk(self, body: list, scope: Scope, primitive, out) -> None:
        self.st.enter(scope, primitive, out)
        self.stmts.stmts(body, context="top")

    def primitive(self, p: A.PrimitiveDef) -> None:
        """A PRIMITIVE: silent passes settle its types, then one reports; its parameters get their types."""
        prim, sig, _ = self.primitives[p.name.name]
        scope = S.primitive_scope(p, sig)
        for _ in range(PRIMITIVE_PASSES):
            self.walk(p.body, scope, p, SILENT)
        self.walk(p.body, scope, p, self.report)
        for default in sig.defaults.values():
            if isinstance(default, A.Node):
                self.typer.expr(default)
        if self.calls is None:  # once per check: walking every body for every PRIMITIVE was quadratic
            self.calls = S.call_graph(self.program)
        S.recursion(self.calls, p, self.report)
        for slot in sig.slots:
            sig.param_types[slot.keyword] = scope.types.get(slot.param, T.REAL)
        self.primitives[p.name.name] = (prim, sig, scope)

    def main(self, main: Scope) -> None:
        """The main program: one silent pass, then reporting passes until the types settle.

        A pass can widen an implicit INTEGER to REAL that an earlier line
        already used; only a pass that changes no type has trustworthy
        reports. Big programs usually settle at once, so this costs one pass
        where a fixed count of passes cost three.
        """
        body = self.program.body
        self.walk(body, main, None, SILENT)
        for attempt in range(MAIN_PASSES):
            before = dict(main.types)
            trial = self.report.trial()
            try:
                self.walk(body, main, None, trial)
            except TooMany:
                if main.types == before or attempt == MAIN_PASSES - 1:
                    self.report.absorb(trial)
                    raise
                continue
            if main.types == before or attempt == MAIN_PASSES - 1:
                self.report.absorb(trial)  # the last pass reports even if types still moved
                return


def check(program: A.Program, path: str | None = None, stack: tuple = (), opened: dict | None = None) -> Checked:
    """Check a parsed program; raise LigDiagnostics listing every error found.

    ``path`` is the program's file (relative LOADs start from its folder);
    ``stack`` the libraries being loaded around it; ``opened`` the libraries
    this compile has already opened (see ``library.open_library``).
    """
    report = Report(program)
    main = Scope("main program")
    try:
        sigs, primitives = _signatures(program, report)
        loaded = load_libraries(
            program,
            main,
            sigs,
            primitives,
            report,
            path=path if path is not None else program.filename,
            stack=stack,
            opened={} if opened is None else opened,
        )
    except TooMany:
        raise LigDiagnostics(report.errors) from None
    passes = _Passes(program, sigs, primitives, loaded.top, report)
    try:
        for p in program.primitives:
            if primitives.get(p.name.name, (None,))[0] is not None:  # one without a pattern is already reported
                passes.primitive(p)
        passes.main(main)
    except TooMany:
        pass
    if report.errors:
        raise LigDiagnostics(report.errors)
    return Checked(
        program,
        main,
        primitives,
        passes.st.types,
        passes.st.scenes,
        report.warnings,
        loaded.libraries,
        loaded.loads,
        loaded.names,
        loaded.primitives,
    )
