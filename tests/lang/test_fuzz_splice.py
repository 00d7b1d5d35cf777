"""Property: lines and blocks spliced across examples/*.lig and stdlib/*.lig run or are diagnosed.

tests/fuzzgen.py takes whole statements, blocks and DO loops (now and then
a few lines in a row) from one example or library and puts them into
another, between its statements or in place of one; scene lengths are cut
to a few ticks. Each case runs check and a 16x12 render (tests/fuzzrun.py);
only success and a positioned diagnostic pass.
"""

from __future__ import annotations

import random

import fuzzgen
import fuzzrun
from hypothesis import event

CASES = 600


def test_the_corpus_has_the_examples_and_libraries_and_their_blocks():
    names = [name for name, _ in fuzzgen.corpus()]
    assert "examples/clock.lig" in names and "stdlib/humanoid.lig" in names
    lines = dict(fuzzgen.corpus())["examples/clock.lig"]
    spans = fuzzgen.units(lines)
    whole = ["\n".join(lines[a:b]) for a, b in spans]
    assert any(t.lstrip().startswith("INITIALIZE") and t.rstrip().endswith("ENDSCENE") for t in whole)
    assert any(t.lstrip().startswith("DO 10") and t.rstrip().endswith("CONTINUE") for t in whole)
    # A statement written over three lines is one unit.
    assert any(t.lstrip().startswith("clock :- JOINT 1") and t.rstrip().endswith("(0°, 360°)") for t in whole)


def test_splices_change_the_text_and_keep_scenes_short():
    for seed in range(30):
        text = fuzzgen.splice_program(random.Random(seed))
        assert text not in ["\n".join(lines) for _, lines in fuzzgen.corpus()]
        for m in fuzzgen._LENGTH.finditer(text):
            assert int(m.group(2)) <= fuzzgen.MAX_LENGTH


@fuzzrun.seeded_programs(CASES)
def test_spliced_programs_run_or_are_diagnosed(rng):
    out = fuzzrun.assert_runs_or_is_diagnosed(fuzzgen.splice_program(rng))
    event(out.kind)
