"""Issue 24: a scene's work (joint-ticks, frames) is estimated when its ticks begin and refused over budget;
a long check shows progress when asked and stops at once on Ctrl-C."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.runtime import budgets

WALK = """\
LOAD HUMANOID, WALK FROM 'humanoid'
INITIALIZE SCENE 1
STARTSCENE LENGTH {n}
ANIMATE HUMANOID FROM 0 TO {last} USING WALK REPEAT
ENDSCENE
SHOOTSCENES
"""


def walk(n: int) -> str:
    return WALK.format(n=n, last=n - 1)


@pytest.fixture(autouse=True)
def _default_budgets(monkeypatch):
    monkeypatch.delenv(budgets.JOINT_TICKS_ENV, raising=False)
    monkeypatch.delenv(budgets.FRAMES_ENV, raising=False)


def refused(text: str, render_to=None):
    with pytest.raises(LigDiagnostics) as info:
        program, _ = load_program(text=text, name="walk.lig")
        if render_to is None:
            program.check()
        else:
            program.render(str(render_to), size=(8, 6), quiet=True, workers=1)
    return info.value.diagnostics[0]


def test_the_longest_humanoid_walk_is_refused_at_its_length_before_hours_of_work():
    start = time.process_time()
    d = refused(walk(10_000_000))
    assert time.process_time() - start < 30  # it used to check for about three hours
    assert (d.pos.line, d.pos.column) == (3, 19)  # the LENGTH
    assert d.message == (
        "this scene of 10,000,000 ticks poses about 20 joints a tick, some 200,000,000 joint-ticks of work, "
        "over the budget of 50,000,000 joint-ticks for one scene"
    )
    assert f"{budgets.JOINT_TICKS_ENV}=200000000" in d.hint


def test_the_joint_tick_budget_is_raised_or_lowered_by_its_variable(monkeypatch):
    monkeypatch.setenv(budgets.JOINT_TICKS_ENV, "1999")
    assert "over the budget of 1,999 joint-ticks" in refused(walk(100)).message
    monkeypatch.setenv(budgets.JOINT_TICKS_ENV, "2000")
    program, _ = load_program(text=walk(100), name="walk.lig")
    program.check()
    monkeypatch.setenv(budgets.JOINT_TICKS_ENV, "lots")
    assert (
        refused(walk(100)).message
        == f"{budgets.JOINT_TICKS_ENV}='lots' is not a budget; give a whole number such as 50000000"
    )


def test_an_animate_that_starts_late_is_counted_when_it_starts(monkeypatch):
    monkeypatch.setenv(budgets.JOINT_TICKS_ENV, "1000000")
    text = (
        "LOAD HUMANOID, WALK FROM 'humanoid'\nINTEGER K\nK = 0\nINITIALIZE SCENE 1\nSTARTSCENE LENGTH 100000\n"
        "K = K + 1\nIF K > 50000 THEN ANIMATE HUMANOID FROM 0 TO 99999 USING WALK REPEAT\nENDSCENE\nSHOOTSCENES\n"
    )
    d = refused(text)
    assert "joint-ticks of work, over the budget of 1,000,000" in d.message


def test_frames_over_the_budget_are_refused_before_any_is_drawn(tmp_path, monkeypatch):
    monkeypatch.setenv(budgets.FRAMES_ENV, "10")
    text = walk(21).replace("STARTSCENE LENGTH 21", "STARTSCENE LENGTH 21 SAMEFRAME 2")
    d = refused(text, tmp_path / "out")
    assert d.message == "this scene would draw 11 frames, over the budget of 10 frames for one scene"
    assert f"{budgets.FRAMES_ENV}=11" in d.hint
    assert not (tmp_path / "out").exists()  # refused by the check, before the folder is made
    monkeypatch.setenv(budgets.FRAMES_ENV, "11")
    program, _ = load_program(text=text, name="walk.lig")
    program.render(str(tmp_path / "out"), size=(8, 6), quiet=True, workers=1)
    assert len(list((tmp_path / "out").rglob("*.png"))) == 11


def _start(args, cwd, env=None):
    """``python -m liganimate ARGS`` with SIGINT at its default (a background shell's children inherit it ignored)."""
    return subprocess.Popen(
        [sys.executable, "-m", "liganimate", *args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, **(env or {})},
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )


def test_a_long_check_shows_progress_when_asked_and_stops_at_once_on_ctrl_c(tmp_path):
    (tmp_path / "walk.lig").write_text(walk(5_000_000))
    proc = _start(["check", "--progress", "walk.lig"], tmp_path, {budgets.JOINT_TICKS_ENV: str(10**9)})
    first = proc.stderr.readline()  # stderr is a pipe, not a terminal: shown because asked
    assert first.startswith("checking scene 1: ") and first.endswith("/5,000,000 ticks\n"), first
    os.killpg(proc.pid, signal.SIGINT)
    stopped = time.monotonic()
    _, rest = proc.communicate(timeout=60)
    assert time.monotonic() - stopped < 5
    assert proc.returncode == 130
    lines = [line for line in rest.splitlines() if line and not line.startswith("checking scene")]
    assert lines == ["liganimate: interrupted; every file already written is complete"], rest


def test_no_progress_is_shown_when_not_asked_and_not_a_terminal(tmp_path):
    (tmp_path / "walk.lig").write_text(walk(48))
    proc = _start(["check", "walk.lig"], tmp_path)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0 and err == ""
