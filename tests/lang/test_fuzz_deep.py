"""Property (issue 24): deep and long constructs, and non-ASCII characters in real programs, run or are diagnosed.

tests/fuzzgen.py builds nesting (parentheses, negations, IF blocks, DO
loops, modifier chains), long sums and statement lists, JOINT chains and
motion sums at sizes around the nesting limit (100) and far past it; and it
puts letters of other scripts, marks, odd spaces, controls, terminal
escapes, emoji and lone surrogates into examples and splices. Each case runs
check and a 16x12 render (tests/fuzzrun.py); only success and a positioned
diagnostic pass.
"""

from __future__ import annotations

import random

import fuzzgen
import fuzzrun
from hypothesis import event

CASES = 60


def test_every_deep_construct_is_made_at_every_size():
    for build in fuzzgen.DEEP:
        for n in (1, 101):
            text = build(n)
            assert text.endswith("\n") and text.count("\n") >= 1, build.__name__
    assert fuzzgen._deep_parens(101).count("(") == 101
    assert fuzzgen._modifier_chain(200).count("<SCALE 1.0>") == 200


def test_unicode_programs_hold_characters_beyond_ascii():
    texts = [fuzzgen.unicode_program(random.Random(seed)) for seed in range(40)]
    assert all(any(ord(c) > 127 or (ord(c) < 32 and c != "\n") for c in t) for t in texts)


@fuzzrun.seeded_programs(CASES)
def test_deep_and_long_programs_run_or_are_diagnosed(rng):
    out = fuzzrun.assert_runs_or_is_diagnosed(fuzzgen.deep_program(rng), limit=5.0)
    event(out.kind)


@fuzzrun.seeded_programs(CASES)
def test_programs_with_unicode_put_in_run_or_are_diagnosed(rng):
    out = fuzzrun.assert_runs_or_is_diagnosed(fuzzgen.unicode_program(rng))
    event(out.kind)
