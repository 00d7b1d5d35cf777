"""Issue 24: building a model one JOINT at a time does Python work linear in its joints.

A loop ``M :- JOINT I, M, ...`` used to measure the whole model again on
every pass (limits.figure_reach) and re-walk its tree (Figure._check_tree):
``check`` took 25 s at 1,200 joints and did not finish 3,000 in a minute.
The work is counted, not timed: every Python function call and generator
step (``sys.setprofile``) while the program's module runs.
"""

from __future__ import annotations

import sys

import pytest

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.runtime import limits
from liganimate.runtime.figure.tree import Figure

CHAIN = """\
      GRAPHICAL G
      MODEL M
      INTEGER I
      G :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      M :- JOINT 0, G, (0.0, 1.0, 0.0), G, (0.0, 0.0, 0.0), (-10, 10)
      DO 10 I = 1, {n}
        M :- JOINT I, M, (0.0, 1.0, 0.0), G, (0.0, 0.0, 0.0), (-10, 10)
 10   CONTINUE
"""


def _calls_to_build(n: int) -> tuple[int, object]:
    """Python calls made while a program builds an ``n + 1``-joint chain, and the model it built."""
    program, _ = load_program(text=CHAIN.format(n=n), name="chain.lig")
    calls = 0

    def count(frame, event, arg):
        nonlocal calls
        if event == "call":
            calls += 1

    sys.setprofile(count)
    try:
        rt = program.execute("check")
    finally:
        sys.setprofile(None)
    return calls, rt.variables["M"]


def test_a_chain_built_one_joint_at_a_time_costs_the_same_per_joint_at_any_length():
    small, _ = _calls_to_build(2_000)
    large, _ = _calls_to_build(4_000)
    # Linear: the second 2,000 joints cost what the first 2,000 did (quadratic
    # work makes them cost about three times as much).
    assert large - small < 1.1 * small, (small, large)


def test_a_20000_joint_chain_is_built_within_a_bound_of_calls_per_joint():
    calls, model = _calls_to_build(20_000)
    assert model.n_joints == 20_001
    assert [j.id for j in model.joints[:3]] == [0, 1, 2]
    assert calls < 150 * 20_000, calls  # about 106 a joint


def test_the_memoised_reach_of_a_chain_equals_a_fresh_measurement():
    _, model = _calls_to_build(300)
    fresh = Figure(model.links, model.joints)  # the same structure, measured from nothing
    assert limits.figure_reach(model) == limits.figure_reach(fresh)
    assert limits.figure_reach(model) > 300  # every joint location counts


def test_a_repeated_joint_identifier_is_still_refused_when_grafting():
    with pytest.raises(LigDiagnostics) as info:
        program, _ = load_program(text=CHAIN.format(n=3).replace("JOINT I,", "JOINT 1 + I MOD 2,"), name="c.lig")
        program.check()
    assert "joint identifier 2 is used twice in one model" in info.value.diagnostics[0].message


def test_a_model_over_the_joint_budget_is_refused_at_the_joint_that_grows_it(monkeypatch):
    monkeypatch.setenv("LIGANIMATE_MAX_MODEL_JOINTS", "50")
    program, _ = load_program(text=CHAIN.format(n=60), name="chain.lig")
    with pytest.raises(LigDiagnostics) as info:
        program.execute("check")
    d = info.value.diagnostics[0]
    assert d.pos.line == 7  # the JOINT inside the loop
    assert "51 joints, over the limit of 50 joints" in d.message
    assert "LIGANIMATE_MAX_MODEL_JOINTS=51" in d.hint
    monkeypatch.setenv("LIGANIMATE_MAX_MODEL_JOINTS", "61")
    program.execute("check")  # 61 joints: within the raised budget


def test_a_model_block_over_the_joint_budget_is_refused_at_the_block(monkeypatch):
    monkeypatch.setenv("LIGANIMATE_MAX_MODEL_JOINTS", "2")
    text = """\
      GRAPHICAL A, B, C, D
      MODEL M
      A :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      B :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      C :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      D :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      STARTMODEL M
        JOINT 1, A, (0.0, 0.0, 0.0), B, (0.0, 0.0, 0.0), (-10, 10)
        JOINT 2, B, (0.0, 1.0, 0.0), C, (0.0, 0.0, 0.0), (-10, 10)
        JOINT 3, C, (0.0, 1.0, 0.0), D, (0.0, 0.0, 0.0), (-10, 10)
      ENDMODEL
"""
    program, _ = load_program(text=text, name="block.lig")
    with pytest.raises(LigDiagnostics) as info:
        program.execute("check")
    d = info.value.diagnostics[0]
    assert d.pos.line == 7 and "3 joints, over the limit of 2" in d.message
