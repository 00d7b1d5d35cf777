"""Property: a mutated example program compiles and checks, or is diagnosed.

Mutations (benchmarks/fuzz_compile.py): delete, duplicate or swap lines,
delete characters, insert a character or a LIG token, replace a word with a
token, truncate. Each case runs in process what ``liganimate check`` runs:
parse, check, lower, execute the module text, ``program.check()``. The only
acceptable outcomes are success and LigDiagnostics; anything else (a
RecursionError, a NameError from generated code, a Python SyntaxError...)
is a bug. A case still running after a few seconds is skipped over, not
failed: a mutation can legitimately make a scene a million ticks long.

The run is derandomized (the same cases every time) and takes about 15 s.
``python benchmarks/fuzz_compile.py`` runs the same mutations at scale.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, event, given, settings
from mutations import SOURCES, example, fuzz, mutated, mutations

from liganimate.lang.diagnostics import LigDiagnostics

EXAMPLES = 600


def test_the_examples_are_there_and_pass_unmutated():
    names = [name for name, _ in SOURCES]
    assert {"appendix_a.lig", "clock.lig"} <= set(names)
    for name, text in SOURCES:
        # The example's own path, so that a LOAD of a library beside it
        # (robot_arm.lig's 'robots/gantry.lig') resolves as `liganimate check` resolves it.
        fuzz.compile_and_check(text, os.path.join(fuzz.EXAMPLES, name))


def test_mutations_change_the_text():
    text = SOURCES[0][1]
    for kind in fuzz.MUTATIONS:
        assert fuzz.mutate(text, kind, 0.5, 0.25, 7) != text, kind


def test_a_crash_is_reported_as_a_crash():
    # The classifier itself must be able to fail the property.
    outcome, exc = fuzz.classify("      X = 1\n      PRINT X\n")
    assert outcome == "ok"
    outcome, exc = fuzz.classify("      X = \n")
    assert outcome == "diagnostics" and isinstance(exc, LigDiagnostics)
    original = fuzz.compile_and_check
    try:
        fuzz.compile_and_check = lambda text, filename="fuzz.lig": {}["boom"]
        outcome, exc = fuzz.classify("      X = 1\n")
    finally:
        fuzz.compile_and_check = original
    assert outcome == "crash" and isinstance(exc, KeyError)


@settings(
    max_examples=EXAMPLES,
    derandomize=True,
    deadline=None,
    database=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(index=example, steps=mutations)
def test_mutated_programs_compile_or_are_diagnosed(index, steps):
    name, text = mutated(index, steps)
    outcome, exc = fuzz.classify(text, limit=3.0)
    event(outcome)
    if outcome == "crash":
        raise AssertionError(
            f"{name} mutated by {steps} raised {type(exc).__name__}: {exc}\n--- program ---\n{text}"
        ) from exc
    assert outcome in ("ok", "diagnostics", "slow")
