"""Property: extreme numbers in every numeric slot are diagnosed or handled, never an internal error.

tests/fuzzgen.py has small complete programs (arithmetic, a figure, motions,
loops, STARTREACH, primitives, a scene) whose numeric slots -- vectors,
REAL(), BOX sizes, LIGHTNESS, TRANS, ROT, SCALE FRAMES/EXTREMES/MODEL, joint
extremes, FRAME numbers, ANIMATE FROM/TO, VIEW WIDTH/POINT, DO bounds,
keyframe indices, SAMEFRAME, LENGTH, REACH values -- get 1e308, 1e309,
-0.0, 5e-324, 2**63, 401- and 5,000-digit integers, and infinities and NaNs
made by arithmetic. Each case runs check and a 16x12 render
(tests/fuzzrun.py); only success and a positioned diagnostic pass.
"""

from __future__ import annotations

import re

import fuzzgen
import fuzzrun
from hypothesis import event

CASES = 600
WILD_CASES = 200


def test_every_template_runs_at_its_defaults():
    # Otherwise an extreme value would only ever meet an error made by the template.
    for name, template in fuzzgen.TEMPLATES.items():
        out = fuzzrun.run_case(fuzzgen.fill(template, {}))
        assert out.kind == "ok", (name, out)


def test_the_templates_cover_the_numeric_slots_the_issue_names():
    text = "".join(fuzzgen.TEMPLATES.values())
    for slot in (
        "REAL(«",
        "WIDTH «",
        "LIGHTNESS «",
        "TRANS «",
        "ROT X «",
        "SCALE FRAMES «",
        "SCALE EXTREMES «",
        "SCALE MODEL «",
        "«P:",
        "FRAME «",
        "FROM «",
        "TO «",
        "VIEW WIDTH = «",
        "VIEW POINT = «",
        "DO 10 I = «",
        "W[«",
        "SAMEFRAME «",
        "LENGTH «",
        "WEIGHT «",
        "ITERATIONS «",
    ):
        assert slot in text, slot
    for value in ("1e309", "-0.0", "5e-324", "9223372036854775808", "1" + "0" * 400, "1" * 5000, "1e308*10-1e308*10"):
        assert value in fuzzgen.EXTREMES, value


def test_a_filled_slot_changes_only_that_slot():
    template = fuzzgen.TEMPLATES["scene"]
    assert fuzzgen.slots(template)[3] == ("N", "0.5")  # G1's DEPTH
    before = re.findall(r"[^\s,]+", fuzzgen.fill(template, {}))
    after = re.findall(r"[^\s,]+", fuzzgen.fill(template, {3: "1e309"}))
    changed = [(a, b) for a, b in zip(before, after) if a != b]
    assert len(before) == len(after) and changed == [("0.5", "1e309")]


@fuzzrun.seeded_programs(CASES)
def test_extreme_numbers_are_diagnosed_or_handled(rng):
    out = fuzzrun.assert_runs_or_is_diagnosed(fuzzgen.number_program(rng))
    event(out.kind)


@fuzzrun.seeded_programs(WILD_CASES)
def test_extreme_numbers_anywhere_in_grammar_programs_are_diagnosed_or_handled(rng):
    # The templates put extremes where a program is known to work; here they
    # land wherever the grammar has a number, a quarter of the time.
    out = fuzzrun.assert_runs_or_is_diagnosed(fuzzgen.wild_program(rng))
    event(out.kind)
