"""Mutated example programs for property tests, shared by the compiler and lexer tests.

The mutations live in benchmarks/fuzz_compile.py (which runs them at
scale); it is loaded once here, not once per test module.
"""

from __future__ import annotations

import importlib.util
import os

from hypothesis import strategies as st

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_spec = importlib.util.spec_from_file_location(
    "liganimate_fuzz_compile", os.path.join(ROOT, "benchmarks", "fuzz_compile.py")
)
fuzz = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(fuzz)

#: (file name, text) of every example program.
SOURCES = fuzz.example_sources()

_unit = st.floats(min_value=0.0, max_value=1.0, exclude_max=True, allow_nan=False)
#: One mutation: (kind, u, v, pick), as fuzz.mutate takes them.
mutation = st.tuples(st.sampled_from(fuzz.MUTATIONS), _unit, _unit, st.integers(0, 1 << 16))
#: Which example, and one to three mutations of it.
example = st.integers(0, len(SOURCES) - 1)
mutations = st.lists(mutation, min_size=1, max_size=3)


def mutated(index: int, steps) -> tuple[str, str]:
    """Example ``index`` after the mutations ``steps``: (its file name, the text)."""
    name, text = SOURCES[index]
    for kind, u, v, pick in steps:
        text = fuzz.mutate(text, kind, u, v, pick)
    return name, text
