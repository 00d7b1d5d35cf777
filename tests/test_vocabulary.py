"""The vocabulary tables (lang/vocabulary.py) agree with the grammar and the runtime."""

from __future__ import annotations

import pathlib
import re

import pytest
from paths import ROOT_DIR

from liganimate.lang import vocabulary as V
from liganimate.lang.transform import ToAst
from liganimate.runtime.host import Runtime

GRAMMAR = (pathlib.Path(ROOT_DIR) / "lang" / "lig.lark").read_text(encoding="utf-8")


def test_every_grammar_modifier_is_in_the_table_and_back():
    in_grammar = set(re.findall(r"->\s*mod_(\w+)", GRAMMAR))
    assert in_grammar == set(V.MODIFIERS)


@pytest.mark.parametrize("kind", sorted(V.MODIFIERS))
def test_every_modifier_has_a_transformer_rule_and_a_runtime_method_per_target(kind):
    spec = V.MODIFIERS[kind]
    assert callable(getattr(ToAst, "mod_" + kind))
    for target in spec.targets:
        assert callable(getattr(Runtime, spec.runtime_name(target), None)), spec.runtime_name(target)


@pytest.mark.parametrize("name", sorted(V.FUNCTIONS))
def test_every_builtin_function_is_implemented(name):
    assert callable(getattr(Runtime, "f_" + name, None))


def test_no_runtime_function_is_missing_from_the_table():
    implemented = {n[2:] for n in dir(Runtime) if n.startswith("f_") and n[2:].isupper()}
    assert implemented == set(V.FUNCTIONS)


def test_block_words_are_the_grammars_keywords():
    for block in V.BLOCKS:
        for word in (block.opener, block.closer):
            assert re.search(rf'"{word}"i?|\b{word}\b', GRAMMAR), word


def test_a_modifier_on_the_wrong_type_is_worded_from_the_table():
    from liganimate.compiler import compile_text
    from liganimate.lang.diagnostics import LigDiagnostics

    with pytest.raises(LigDiagnostics) as info:
        compile_text("MOTION M\nX = 1\nY = X <SCALE FRAMES 2>\n")
    assert "SCALE FRAMES applies to motions; this is an INTEGER" in str(info.value)
