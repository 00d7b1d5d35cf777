"""check and run agree: whatever makes ``run`` fail makes ``check`` fail first, at a position.

Each program shoots a sound scene 1 before the faulty part, so a run that
found the fault only while rendering would already have written frames.
Both commands must print the same positioned diagnostic, no traceback, no
numpy warning, no array in the sentence, and ``run`` must write nothing.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

PROLOGUE = """\
LOAD HUMANOID, WALK FROM 'humanoid'
GRAPHICAL FLOOR
MODEL M
MOTION W
INITIALIZE SCENE 1
STARTSCENE LENGTH 3
ANIMATE HUMANOID FROM 0 TO 2 USING WALK
ENDSCENE
"""

SCENE2 = """\
INITIALIZE SCENE 2
{init}
STARTSCENE LENGTH {length}
ANIMATE HUMANOID FROM 0 TO 2 USING {motion}
{body}
ENDSCENE
SHOOTSCENES
END
"""

# name -> (the part after the prologue, line of the fault (prologue is 8 lines), words)
CASES = {
    "non-finite VIEW POINT in a later scene": ({"init": "VIEW POINT = (1e308 * 10, 0.8, 7.0)"}, 10, "REAL overflow"),
    "far VIEW POINT in a later scene": ({"init": "VIEW POINT = (1e200, 0.8, 7.0)"}, 10, "VIEW POINT"),
    "tiny VIEW WIDTH in a later scene": ({"init": "VIEW WIDTH = 1e-300"}, 10, "VIEW WIDTH"),
    "BACKGROUND box of infinite width": (
        {"init": "FLOOR = BOX WIDTH 1e308 * 10, HEIGHT 0.06, DEPTH 2.4\nBACKGROUND FLOOR"},
        10,
        "REAL overflow",
    ),
    "BACKGROUND box of huge width": (
        {"init": "FLOOR = BOX WIDTH 1e300, HEIGHT 0.06, DEPTH 2.4\nBACKGROUND FLOOR"},
        10,
        "BOX",
    ),
    "WALK <SCALE FRAMES 1e-300>": ({"init": "W = WALK <SCALE FRAMES 1e-300>", "motion": "W"}, 10, "SCALE FRAMES"),
    "HUMANOID <TRANS (1e308*10,0,0)>": ({"body": "HUMANOID :- HUMANOID <TRANS (1e308*10,0,0)>"}, 13, "REAL overflow"),
    "HUMANOID <TRANS (1e300,0,0)>": ({"body": "HUMANOID :- HUMANOID <TRANS (1e300,0,0)>"}, 13, "limit"),
    "HUMANOID <SCALE MODEL 1e300>": ({"body": "HUMANOID :- HUMANOID <SCALE MODEL 1e300>"}, 13, "limit"),
    "a scene beyond the longest length": ({"length": "100000000000"}, 11, "longer than the longest"),
    "keyframes too close, used in a later scene": (
        {"init": "W[1, 1] = FRAME 1e-200 POSITION 0, 0, 10\nW[1, 2] = FRAME 1 POSITION 0, 0, 20", "motion": "W"},
        10,
        "too close",
    ),
    "PRINT of a model without a value": ({"body": "PRINT $M"}, 13, "before it has a value"),
}


def _program(parts: dict) -> str:
    fill = {"init": "", "length": "3", "motion": "WALK", "body": ""}
    fill.update(parts)
    return PROLOGUE + SCENE2.format(**fill)


def _cli(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "liganimate", *args], capture_output=True, text=True, cwd=cwd, check=False, timeout=300
    )


def _clean(stderr: str) -> None:
    for bad in ("Traceback", "internal error", "RuntimeWarning", "site-packages", "array(", "nan", " inf"):
        assert bad not in stderr, stderr


@pytest.mark.parametrize("name", CASES)
def test_check_finds_what_run_would_fail_on(tmp_path, name):
    parts, line, words = CASES[name]
    (tmp_path / "f.lig").write_text(_program(parts), encoding="utf-8")
    checked = _cli("check", "f.lig", cwd=tmp_path)
    assert checked.returncode == 1, checked.stderr
    _clean(checked.stderr)
    first = checked.stderr.splitlines()[0]
    assert first.startswith(f"f.lig:{line}:") and ": error: " in first and words in first, first
    out = tmp_path / "out"
    ran = _cli(
        "run",
        "f.lig",
        "-o",
        str(out),
        "--quiet",
        "--size",
        "64x48",
        "--poses",
        "p.jsonl",
        "--gif",
        "a.gif",
        cwd=tmp_path,
    )
    assert ran.returncode == 1
    _clean(ran.stderr)
    assert ran.stderr.splitlines()[0] == first
    written = [p for p in tmp_path.rglob("*") if p.is_file() and p.name != "f.lig"]
    assert written == [], written


def test_the_sound_program_renders(tmp_path):
    # The prologue alone is sound, so the cases above fail for their fault only.
    (tmp_path / "f.lig").write_text(_program({}), encoding="utf-8")
    ran = _cli("run", "f.lig", "-o", "out", "--quiet", "--size", "64x48", cwd=tmp_path)
    assert ran.returncode == 0, ran.stderr
    assert len(list((tmp_path / "out" / "scene1").iterdir())) == 3
    assert len(list((tmp_path / "out" / "scene2").iterdir())) == 3
