"""Positions (lang/ast.py's Pos): the character offsets they carry beside lines and columns."""

import copy
import pickle
import random

import pytest

from liganimate.lang.ast import NOWHERE, Pos, token_pos

# Inside the packed layout, at its limits, and beyond them (stored unpacked).
CASES = [
    (1, 1, 1, 2, 0, 1),
    (3, 5, 3, 9, 40, 44),
    (16_777_215, 4095, 16_777_215 + 4095, 4095, (1 << 32) - 1, (1 << 32) - 1 + (1 << 28) - 1),
    (2, 1, 2, 3, 1 << 32, (1 << 32) + 2),  # start beyond 32 bits
    (2, 1, 9, 3, 10, 10 + (1 << 28)),  # length beyond 28 bits
    (4, 2, 4, 3, 9, 7),  # end before start: never made by the parser, still kept exactly
    (-1, -2, -3, -4, -5, -6),
]


@pytest.mark.parametrize("numbers", CASES)
def test_a_position_keeps_its_six_numbers(numbers):
    line, column, end_line, end_column, start, end = numbers
    p = Pos(*numbers)
    assert (p.line, p.column, p.end_line, p.end_column, p.start, p.end) == numbers
    assert p == Pos(*numbers) and hash(p) == hash(Pos(*numbers))
    assert p != Pos(line, column, end_line, end_column, start, end + 1)
    assert p != Pos(line, column, end_line, end_column)
    assert repr(p) == (
        f"Pos(line={line}, column={column}, end_line={end_line}, end_column={end_column}, start={start}, end={end})"
    )
    assert pickle.loads(pickle.dumps(p)) == p and copy.deepcopy(p) == p
    if line == end_line:
        assert token_pos(line, column, end_column, start, end) == p


def test_a_synthetic_position_has_offsets_zero_and_prints_as_before():
    p = Pos(7, 3, 9, 12)
    assert (p.start, p.end) == (0, 0)
    assert repr(p) == "Pos(line=7, column=3, end_line=9, end_column=12)"
    assert (NOWHERE.start, NOWHERE.end) == (0, 0)


def test_to_takes_the_start_of_one_and_the_end_of_the_other():
    rng = random.Random(5)
    for _ in range(2000):
        a = [rng.choice([1, 2, 4095, 4096, 1 << 24, rng.randrange(1, 1 << 40)]) for _ in range(6)]
        b = [rng.choice([1, 2, 4095, 4096, 1 << 24, rng.randrange(1, 1 << 40)]) for _ in range(6)]
        p, q = Pos(*a), Pos(*b)
        assert p.to(q) == Pos(a[0], a[1], b[2], b[3], a[4], b[5])


def test_widened_moves_the_text_and_keeps_the_caret():
    p = token_pos(3, 8, 9, 20, 21)  # "A" in "X = (A)"
    w = p.widened(19, 22)
    assert (w.line, w.column, w.end_line, w.end_column) == (3, 8, 3, 9)
    assert (w.start, w.end) == (19, 22)
    assert w.without_offsets() == Pos(3, 8, 3, 9) == p.without_offsets()
    big = Pos(2, 1, 9, 3, 1 << 33, (1 << 33) + 5)
    assert big.without_offsets() == Pos(2, 1, 9, 3)
