"""Property: programs expanded from lang/lig.lark run or are diagnosed, never an internal error.

tests/fuzzgrammar.py expands the grammar at random, steered so that many
programs parse, pass the checker and reach the runtime. Each case runs what
``liganimate check`` and ``liganimate run`` run (tests/fuzzrun.py): load,
check, then render at 16x12. Only success and a positioned diagnostic pass.
A failure prints the minimised program, then the generated one.

Derandomized: the same cases every run. ``python benchmarks/fuzz.py``
runs the same generator at scale.
"""

from __future__ import annotations

import random

import fuzzgen
import fuzzgrammar
import fuzzrun
from hypothesis import event

from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.lang.parser import parse

CASES = 400


def test_the_grammar_is_read_with_its_keywords_and_terminals():
    g = fuzzgrammar.grammar()
    assert {"statement", "scene_block", "modifier", "reach_block"} <= set(g.rules)
    assert g.terminals["ENDSCENE"].pattern.value == "ENDSCENE"
    rng = random.Random(3)
    spellings = {fuzzgrammar.sample_regex(g.terminals["SYNCHRONIZE"].pattern.value, rng) for _ in range(40)}
    assert spellings == {"SYNCHRONIZE", "SYNCHRONISE"}
    assert fuzzgrammar.sample_regex(g.terminals["TYPE_KW"].pattern.value, rng) in (
        "REAL",
        "INTEGER",
        "VECTOR",
        "GRAPHICAL",
        "MODEL",
        "MOTION",
    )


def test_most_generated_programs_parse_and_many_run():
    # A generator that drifted from the grammar would only test the parser's errors.
    parsed = ran = 0
    n = 60
    for seed in range(n):
        text = fuzzgen.grammar_program(random.Random(seed))
        try:
            parse(text, "g.lig")
            parsed += 1
        except LigDiagnostics:
            pass
        ran += fuzzrun.run_case(text).kind == "ok"
    assert parsed >= 0.85 * n, parsed
    assert ran >= 0.12 * n, ran


@fuzzrun.seeded_programs(CASES)
def test_grammar_programs_run_or_are_diagnosed(rng):
    out = fuzzrun.assert_runs_or_is_diagnosed(fuzzgen.grammar_program(rng))
    event(out.kind)
