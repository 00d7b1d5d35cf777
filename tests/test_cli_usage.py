"""The command line's manners: usage errors, help for every option, a program with no scene, completion, fmt.

Usage errors (a wrong option value, a file whose suffix is not its
format's) exit with status 2 and print the usage line, as argparse does
for its own. A program that shoots no scene writes nothing (not even an
empty folder), asked for an output or not: it runs for its PRINTs, says so
in a warning and exits 0.
"""

from __future__ import annotations

import argparse
import os
import shutil
import stat
import subprocess
from pathlib import Path

import pytest
from commands import liganimate as run

from liganimate.cli import build_parser

ROOT = Path(__file__).resolve().parent.parent

SCENE = "INITIALIZE SCENE 1\nSTARTSCENE LENGTH 1\nENDSCENE\nSHOOTSCENES\n"


def _subparsers(parser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            yield from action.choices.items()


def test_every_option_and_argument_of_every_command_has_help():
    missing = []
    commands = dict(_subparsers(build_parser()))
    assert {"run", "check", "compile", "plot", "fmt", "view", "export", "completion"} <= set(commands)
    for name, sub in commands.items():
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            if not action.help or action.help == argparse.SUPPRESS:
                missing.append(f"{name} {'/'.join(action.option_strings) or action.dest}")
    assert missing == []


@pytest.mark.parametrize(
    "args, words",
    [
        (("--aa", "9"), "--aa 9"),
        (("--size", "640"), "640x480"),
        (("--fps", "0"), "--fps"),
        (("--crf", "99"), "--crf"),
        (("--gif", "out.png"), "must end in .gif"),
        (("--mp4", "film.gif"), "must end in .mp4"),
    ],
)
def test_a_wrong_option_is_a_usage_error_with_status_2_and_the_usage_line(tmp_path, args, words):
    (tmp_path / "s.lig").write_text(SCENE)
    r = run("run", "s.lig", *args, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith("usage: liganimate run"), r.stderr
    assert words in r.stderr and "Traceback" not in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.lig"]


@pytest.mark.parametrize(
    "args",
    [("compile", "s.lig", "-o", "s.txt"), ("plot", "s.lig", "M", "-o", "m.gif"), ("archive", "s.lig", "-o", "l.txt")],
)
def test_an_output_file_of_the_wrong_kind_is_a_usage_error(tmp_path, args):
    (tmp_path / "s.lig").write_text(SCENE)
    r = run(*args, cwd=tmp_path)
    assert r.returncode == 2 and "usage: liganimate" in r.stderr and "must end in" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.lig"]


NO_SCENE = {
    "library": "REAL X\nX = 1\nPRINT X\n",
    "empty": "",
    "no-shootscenes": "INITIALIZE SCENE 1\nSTARTSCENE LENGTH 2\nENDSCENE\n",
}


@pytest.mark.parametrize("text", NO_SCENE.values(), ids=NO_SCENE.keys())
@pytest.mark.parametrize("asked", [(), ("-o", "frames"), ("--gif", "m.gif"), ("--poses", "p.jsonl")])
def test_a_program_that_shoots_no_scene_runs_for_its_prints_says_so_and_writes_nothing(tmp_path, text, asked):
    (tmp_path / "p.lig").write_text(text)
    r = run("run", "p.lig", *asked, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "liganimate: warning: the program shoots no scene, so there is nothing to render" in r.stderr
    assert "frames written" not in r.stderr
    assert r.stdout == ("X = 1\n" if "PRINT" in text else "")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.lig"]


def test_check_accepts_a_library_without_scenes(tmp_path):
    (tmp_path / "p.lig").write_text("REAL X\nX = 1\n")
    assert run("check", "p.lig", cwd=tmp_path).returncode == 0


@pytest.mark.skipif(shutil.which("bash") is None, reason="bash is not installed")
def test_bash_completes_commands_and_options_with_the_printed_script(tmp_path):
    r = run("completion", "bash", cwd=tmp_path)
    assert r.returncode == 0
    (tmp_path / "c.sh").write_text(r.stdout)
    script = (
        "source c.sh\n"
        'COMP_WORDS=(liganimate f); COMP_CWORD=1; _shtab_liganimate liganimate f liganimate; echo "${COMPREPLY[@]}"\n'
        'COMP_WORDS=(liganimate run --a); COMP_CWORD=2; _shtab_liganimate liganimate --a run; echo "${COMPREPLY[@]}"\n'
    )
    out = subprocess.run(["bash", "-c", script], capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert out.stdout.split("\n")[:2] == ["fmt", "--aa"], out.stderr


def test_zsh_completion_is_a_zsh_function():
    r = run("completion", "zsh")
    assert r.returncode == 0 and r.stdout.startswith("#compdef liganimate")


# ------------------------------------------------------------ liganimate fmt


def test_fmt_check_names_the_files_that_would_change_and_writes_nothing(tmp_path):
    (tmp_path / "a.lig").write_text("real x;x=1\n")
    (tmp_path / "b.lig").write_text("REAL X\nX = 1\n")
    r = run("fmt", "--check", ".", cwd=tmp_path)
    assert r.returncode == 1
    assert "would reformat ./a.lig" in r.stderr and "b.lig" not in r.stderr.split("\n")[0]
    assert (tmp_path / "a.lig").read_text() == "real x;x=1\n"


def test_fmt_diff_prints_the_change_and_writes_nothing(tmp_path):
    (tmp_path / "a.lig").write_text("real x;x=1\n")
    r = run("fmt", "--diff", "a.lig", cwd=tmp_path)
    assert r.returncode == 0
    assert "-real x;x=1\n+REAL x\n+x = 1\n" in r.stdout
    assert (tmp_path / "a.lig").read_text() == "real x;x=1\n"


def test_fmt_rewrites_in_place_keeping_the_mode_and_goes_on_past_a_broken_file(tmp_path):
    (tmp_path / "a.lig").write_text("real x;x=1\n")
    (tmp_path / "bad.lig").write_text("X = = 1\n")
    os.chmod(tmp_path / "a.lig", 0o640)
    r = run("fmt", "bad.lig", "a.lig", cwd=tmp_path)
    assert r.returncode == 1
    assert r.stderr.startswith("bad.lig:1:5: error:")
    assert (tmp_path / "a.lig").read_text() == "REAL x\nx = 1\n"
    assert stat.S_IMODE(os.stat(tmp_path / "a.lig").st_mode) == 0o640
    assert (tmp_path / "bad.lig").read_text() == "X = = 1\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.lig", "bad.lig"]  # no temporary file left
    assert run("fmt", "--check", "a.lig", cwd=tmp_path).returncode == 0


# ------------------------------------------------------------ liganimate plot


def test_plot_names_each_curve_by_the_link_its_joint_moves_and_the_title_clears_the_legend():
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from liganimate.compiler import load_program
    from liganimate.runtime.render.plot import joint_links, plot_motion_figure

    program, _ = load_program(str(ROOT / "examples" / "appendix_a.lig"))
    rt = program.execute("check")
    squat = rt.variables["SQUAT"]
    links, model = joint_links(rt.variables, squat.joints)
    assert model == "HUMAN"
    assert links == {1: "FARM", 2: "FARM", 3: "FLEG", 4: "FOOT", 5: "FLEG", 6: "FOOT", 9: "BLEG", 10: "BLEG"}
    fig = plot_motion_figure(squat, "SQUAT", links, model)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    axes = fig.axes
    assert [a.get_ylabel().split("\n")[0] for a in axes] == [links[j] for j in squat.joints]
    title = axes[0].title.get_window_extent(renderer)
    legend = axes[0].get_legend().get_window_extent(renderer)
    assert not title.overlaps(legend), (title, legend)
    assert title.y0 >= axes[0].get_window_extent(renderer).y1 - 1, "the title sits above the first panel"
