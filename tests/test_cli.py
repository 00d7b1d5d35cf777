"""The command line as a user meets it: exit codes, files, no tracebacks."""

from __future__ import annotations

import json
import pathlib
import sys

import pytest
from commands import liganimate as run
from commands import python

from liganimate.compiler import compile_file

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
GOLDEN_COMPILE = ROOT / "tests" / "golden" / "compile"


def test_run_appendix_a_writes_one_image_and_poses(tmp_path):
    r = run("run", str(EXAMPLES / "appendix_a.lig"), "--size", "160x120", "--poses", "p.jsonl", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in (tmp_path / "appendix_a_frames" / "scene1").iterdir()) == ["00000.png"]
    records = [json.loads(line) for line in (tmp_path / "p.jsonl").read_text().splitlines()]
    assert [rec["tick"] for rec in records] == [0, 1, 2, 3, 4, 5]
    assert {rec["image"] for rec in records} == {0}
    # The main link is a FOOT: its matrix differs between ticks only by the host's TRANS.
    feet = [next(s for s in rec["segments"] if s["link"] == "FOOT" and s["joint"] == 4) for rec in records]
    xs = [f["matrix"][3] for f in feet]
    assert xs == pytest.approx([-3.0 + 1.2 * t for t in range(6)])
    assert all(f["matrix"][7] == pytest.approx(0.0) for f in feet)
    torso_y = [next(s for s in rec["segments"] if s["link"] == "TORSO")["matrix"][7] for rec in records]
    assert all(b < a for a, b in zip(torso_y, torso_y[1:])), "the torso sinks during the squat"


def test_bad_program_exits_1_with_a_diagnostic_and_writes_nothing(tmp_path):
    bad = tmp_path / "bad.lig"
    bad.write_text("MODEL M\nMOTION W\nX = 1 / 0\nSHOOTSCENES\n")
    r = run("run", str(bad), "--poses", "p.jsonl", cwd=tmp_path)
    assert r.returncode == 1
    assert "Traceback" not in r.stderr
    assert f"{bad}:3:7: error: division by zero" in r.stderr
    assert "    X = 1 / 0" in r.stderr and "      ^" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.lig"]


def test_check_runs_scenes_without_rendering(tmp_path):
    r = run("check", str(EXAMPLES / "appendix_a.lig"), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "warning: 2 links are named FOOT" in r.stderr
    assert list(tmp_path.iterdir()) == []


def test_compiled_module_renders_like_run(tmp_path):
    r = run("compile", str(EXAMPLES / "appendix_a.lig"), "-o", "appendix.py", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    p = python("appendix.py", "-o", "mod", "--size", "160x120", "--quiet", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    r2 = run("run", str(EXAMPLES / "appendix_a.lig"), "-o", "cli", "--size", "160x120", "--quiet", cwd=tmp_path)
    assert r2.returncode == 0
    assert (tmp_path / "mod/scene1/00000.png").read_bytes() == (tmp_path / "cli/scene1/00000.png").read_bytes()
    text = (tmp_path / "appendix.py").read_text()
    imports = [line for line in text.splitlines() if line.startswith(("import ", "from "))]
    assert imports == ["from liganimate.runtime import host as _host"]


def test_imported_module_hands_the_program_to_python(tmp_path):
    r = run("compile", str(EXAMPLES / "clock.lig"), "-o", "clockmod.py", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    sys.path.insert(0, str(tmp_path))
    try:
        import clockmod  # noqa: PLC0415

        rt = clockmod.program.execute("check")
        assert rt.variables["CLOCK"].joint_ids == (1, 2)
        assert rt.variables["TIME"] is not None
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("clockmod", None)


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.lig")), ids=lambda p: p.stem)
def test_compile_output_is_stable(path, regen_golden):
    first = compile_file(str(path)).python
    second = compile_file(str(path)).python
    assert first == second
    stored = GOLDEN_COMPILE / (path.stem + ".py.txt")
    # Paths differ between machines; the stored text uses the example's relative name.
    normalised = first.replace(str(path), f"examples/{path.name}")
    if regen_golden:
        stored.parent.mkdir(parents=True, exist_ok=True)
        stored.write_text(normalised)
        return
    assert stored.exists(), "run with --regen-golden to store the compiled module"
    assert normalised == stored.read_text()


def test_plot_draws_a_motion_deterministically(tmp_path):
    import numpy as np
    from PIL import Image

    for out in ("a.png", "b.png"):
        r = run("plot", str(EXAMPLES / "appendix_a.lig"), "squat", "-o", out, cwd=tmp_path)
        assert r.returncode == 0, r.stderr
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    img = np.asarray(Image.open(tmp_path / "a.png").convert("RGB"))
    # One panel per joint of SQUAT (8 joints): a tall figure, with the blue Z curve drawn.
    assert img.shape[0] > img.shape[1] > 500
    blue = (abs(img[..., 0].astype(int) - 0x2C) < 12) & (abs(img[..., 2].astype(int) - 0xA8) < 12)
    assert blue.sum() > 1000


def test_plot_of_an_unknown_motion_is_an_error_and_writes_nothing(tmp_path):
    r = run("plot", str(EXAMPLES / "appendix_a.lig"), "SQAT", "-o", "x.png", cwd=tmp_path)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert "the program has no motion called SQAT" in r.stderr and "did you mean SQUAT?" in r.stderr
    r = run("plot", str(EXAMPLES / "appendix_a.lig"), "HUMAN", "-o", "x.png", cwd=tmp_path)
    assert r.returncode == 1 and "HUMAN is not a MOTION" in r.stderr
    assert list(tmp_path.iterdir()) == []


def test_print_labels_whole_calls_and_nint_rounds_like_fortran(tmp_path):
    prog = tmp_path / "p.lig"
    prog.write_text("PRINT MOD(-7, 3), NINT(-2.5), NINT(2.5), NINT(-2.4), MAX(ABS(-2), 1)\n")
    r = run("run", str(prog), "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == [
        "MOD(-7, 3) = 2",
        "NINT(-2.5) = -3",
        "NINT(2.5) = 3",
        "NINT(-2.4) = -2",
        "MAX(ABS(-2), 1) = 2",
    ]


def test_command_line_errors_escape_control_characters_in_paths(tmp_path):
    # An OSError path and a LigError message can quote a file name the user
    # (or an attacker) chose; a raw ESC would drive the terminal.
    r = run("check", "missing\x1b[31mred.lig", cwd=tmp_path)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert "\x1b" not in r.stderr and "missing\\x1b[31mred.lig" in r.stderr
    r = run("run", str(EXAMPLES / "appendix_a.lig"), "--gif", "no\x1bdir/x.gif", cwd=tmp_path)
    assert r.returncode == 1 and "\x1b" not in r.stderr and "no\\x1bdir" in r.stderr


@pytest.mark.parametrize("command", ["export", "import", "view", "studio"])
def test_every_tool_is_a_subcommand_of_liganimate(command):
    r = run(command, "--help")
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(f"usage: liganimate {command}")


def test_names_a_library_may_define_exclude_every_grammar_keyword():
    # Library writers (import, the studio's Save) ask compiler.names; its
    # keywords come from the grammar's own terminals, so a keyword added to
    # lig.lark can never become a generated MODEL or MOTION name.
    from liganimate.compiler.names import definable, reserved

    for word in ("STARTMOTION", "ENDMOTION", "SYNCHRONISE", "FRAMES", "SIN", "BOX", "HEIGHT"):
        assert word in reserved() and not definable(word.lower())
    # REACH's words are keywords only where no assignment follows: definable.
    assert "MOVE" in reserved() and definable("Move") and definable("endreach")
    assert definable("walk_2") and not definable("2walk") and not definable("a-b")
    r = run("import", "nothing.bvh", "--model", "animate")
    assert r.returncode == 2 and "not a LIG name" in r.stderr


def test_check_prints_what_print_asks_for_and_run_prints_it_once(tmp_path):
    # The thesis' preprocessor printed its tables when it read the program.
    prog = tmp_path / "p.lig"
    prog.write_text("X = 2 + 3\nPRINT 'hello', X\n")
    r = run("check", str(prog), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["hello", "X = 5"]
    r = run("run", str(prog), "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["hello", "X = 5"]
