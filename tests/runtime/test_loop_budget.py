"""Issue 24: a DO loop's passes are counted before its first, and a loop over the budget is refused at its DO."""

from __future__ import annotations

import pytest

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.runtime import arithmetic


def refused(text: str):
    with pytest.raises(LigDiagnostics) as info:
        program, _ = load_program(text=text, name="t.lig")
        program.check()
    return info.value.diagnostics[0]


def test_a_real_loop_that_would_never_end_is_refused_at_its_do(monkeypatch):
    monkeypatch.delenv(arithmetic.LOOP_TRIPS_ENV, raising=False)
    d = refused("      REAL R\n      DO 10 R = 0.0, 1E18, 1E-300\n 10   CONTINUE\n")
    assert d.pos.line == 2
    assert (
        d.message == "this DO loop would make endlessly many passes, over the budget of 100000000 passes for one loop"
    )
    assert arithmetic.LOOP_TRIPS_ENV in d.hint


def test_an_integer_loop_over_the_budget_is_refused_and_the_budget_can_be_changed(monkeypatch):
    text = (
        "      INTEGER I, N\n      N = 0\n      DO 10 I = 1, 1000\n        N = N + 1\n 10   CONTINUE\n      PRINT N\n"
    )
    monkeypatch.setenv(arithmetic.LOOP_TRIPS_ENV, "999")
    d = refused(text)
    assert d.message == "this DO loop would make 1000 passes, over the budget of 999 passes for one loop"
    monkeypatch.setenv(arithmetic.LOOP_TRIPS_ENV, "1000")
    program, _ = load_program(text=text, name="t.lig")
    program.check()


@pytest.mark.parametrize(
    ("start", "stop", "step", "passes"),
    [(1, 10, 1, 10), (10, 1, -3, 4), (1, 0, 1, 0), (0.0, 1.0, 0.25, 5), (0.0, 1e18, 1e-300, float("inf"))],
)
def test_the_count_agrees_with_the_passes_made(start, stop, step, passes):
    assert arithmetic._trips(start, stop, step) == passes
    if passes != float("inf"):
        values = (
            range(start, stop + (1 if step > 0 else -1), step)
            if isinstance(start, int)
            else list(arithmetic._real_steps(start, stop, step))
        )
        assert len(values) == passes
