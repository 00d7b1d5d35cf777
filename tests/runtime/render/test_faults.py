"""Faults around rendering: bad output options, full disks, two runs on one folder, a killed run.

Signals during a render (SIGINT, SIGTERM, two SIGINTs at once) are tested
in test_render.py, next to the Ctrl-C test they extend.
"""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time

import pytest
from test_render import children, leftovers, pngs, program, run, wait_gone

from liganimate.runtime.errors import RenderError
from liganimate.runtime.render import frames as render
from liganimate.runtime.render import outputs
from liganimate.runtime.render.imagefiles import read_png
from liganimate.runtime.render.options import CLI_NAMES, KEYWORD_NAMES, RenderOptions

# --------------------------------------------------------------------------
# Output options are refused before the program is compiled


def tree(folder) -> list:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


BAD_OPTIONS = [
    (["--gif", "sub.gif"], "--gif sub.gif is a folder, not a file"),
    (["--gif", "missing/x.gif"], "--gif missing/x.gif cannot be written: the folder missing does not exist"),
    (["--mp4", "missing/x.mp4"], "--mp4 missing/x.mp4 cannot be written: the folder missing does not exist"),
    (["--poses", "missing/p.jsonl"], "--poses missing/p.jsonl cannot be written: the folder missing does not exist"),
    (["--poses", "{tmp}"], "--poses {tmp} is a folder, not a file"),
    (["--poses", "sub/"], "--poses sub/ is a folder, not a file"),
    (["-o", "bad.lig"], "-o bad.lig is a file, not a folder"),
    (["-o", "bad.lig/frames"], "-o bad.lig/frames cannot be created: {tmp}/bad.lig is a file, not a folder"),
    (["--gif", "a.gif", "--poses", "a.gif"], "--poses and --gif both name a.gif; give each its own file"),
    (["-o", "f.gif", "--gif", "f.gif"], "--gif f.gif is the frames folder (-o f.gif); give another file name"),
    (["--gif", "fifo.gif"], "--gif fifo.gif exists and is not a regular file"),
]

# A value no run could take is a usage error: exit 2, the usage line, then the sentence.
BAD_VALUES = [
    ([f"--fps={v}"], f"--fps {v} is not a usable frame rate; give a number of frames per second from 0.01 to 1000")
    for v in ["0", "-2", "nan", "inf", "-inf", "abc", "1e-9", "1e9"]
] + [
    (["--gif", "{tmp}"], "the file of --gif must end in .gif (it is a GIF), not '{tmp}'"),
    (["--gif", "out.png"], "the file of --gif must end in .gif (it is a GIF), not 'out.png'"),
]


def _bad_run_folder(tmp_path):
    """A program with an error on line 1, and the files the bad options name."""
    (tmp_path / "bad.lig").write_text("X = (1 +\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub.gif").mkdir()
    os.mkfifo(tmp_path / "fifo.gif")


@pytest.mark.parametrize("args, message", BAD_OPTIONS, ids=[" ".join(a) for a, _ in BAD_OPTIONS])
def test_bad_output_options_are_refused_before_compiling(tmp_path, args, message):
    # The program has an error on line 1: the option is refused first, so it was never compiled.
    _bad_run_folder(tmp_path)
    before = tree(tmp_path)
    r = run("run", "bad.lig", *[a.format(tmp=tmp_path) for a in args], cwd=tmp_path)
    assert r.returncode == 1, r.stderr
    assert r.stderr == f"liganimate: error: {message.format(tmp=tmp_path)}\n"
    assert tree(tmp_path) == before


@pytest.mark.parametrize("args, message", BAD_VALUES, ids=[" ".join(a) for a, _ in BAD_VALUES])
def test_bad_option_values_are_usage_errors(tmp_path, args, message):
    _bad_run_folder(tmp_path)
    before = tree(tmp_path)
    r = run("run", "bad.lig", *[a.format(tmp=tmp_path) for a in args], cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith("usage: liganimate run ")
    assert r.stderr.endswith(f"liganimate run: error: {message.format(tmp=tmp_path)}\n")
    assert tree(tmp_path) == before


def test_compiled_module_checks_its_options_too(tmp_path):
    src = program(tmp_path, 4)
    assert run("compile", str(src), "-o", "mod.py", cwd=tmp_path).returncode == 0
    r = subprocess.run(
        [sys.executable, "mod.py", "--gif", "missing/a.gif"], check=False, cwd=tmp_path, capture_output=True, text=True
    )
    assert r.returncode == 1
    assert r.stderr == "liganimate: error: --gif missing/a.gif cannot be written: the folder missing does not exist\n"
    assert not (tmp_path / "swing_frames").exists()


def test_an_unwritable_folder_is_refused(tmp_path, monkeypatch):
    # Root may write anywhere, so the refusal is seen through os.access itself.
    real = os.access
    locked = str(tmp_path / "ro")
    os.mkdir(locked)
    monkeypatch.setattr(outputs.os, "access", lambda p, mode: False if str(p) == locked else real(p, mode))
    with pytest.raises(RenderError, match=f"^--gif {locked}/a.gif cannot be written: permission denied for the folder"):
        outputs.check_outputs(RenderOptions(out=str(tmp_path / "out"), gif=f"{locked}/a.gif"), CLI_NAMES)
    with pytest.raises(RenderError, match=f"^-o {locked}/f cannot be written: permission denied for {locked}$"):
        outputs.check_outputs(RenderOptions(out=f"{locked}/f"), CLI_NAMES)


def test_an_unwritable_folder_is_refused_by_the_command(tmp_path):
    # The command itself, with os.access saying no for one folder (root could write there anyway).
    src = program(tmp_path, 4)
    (tmp_path / "ro").mkdir()
    code = (
        "import os, sys; real = os.access; "
        "os.access = lambda p, m, **kw: False if os.path.basename(str(p)) == 'ro' else real(p, m, **kw); "
        "from liganimate.cli import main; sys.exit(main(sys.argv[1:]))"
    )
    r = subprocess.run(
        [sys.executable, "-c", code, "run", str(src), "--gif", "ro/a.gif"],
        check=False,
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 1
    assert r.stderr == "liganimate: error: --gif ro/a.gif cannot be written: permission denied for the folder ro\n"
    assert sorted(os.listdir(tmp_path)) == ["ro", "swing.lig"]


def test_a_file_in_the_frames_folder_to_be_created_is_accepted(tmp_path):
    outputs.check_outputs(RenderOptions(out=str(tmp_path / "new"), poses=str(tmp_path / "new" / "p.jsonl")), CLI_NAMES)
    with pytest.raises(RenderError, match="the folder .*new/deeper does not exist"):
        outputs.check_outputs(
            RenderOptions(out=str(tmp_path / "new"), poses=str(tmp_path / "new" / "deeper" / "p.jsonl")), KEYWORD_NAMES
        )


def test_the_library_refuses_the_same_options_by_their_keyword_names(tmp_path):
    with pytest.raises(RenderError, match="^gif= .* is a folder, not a file$"):
        render.Renderer(RenderOptions(out=str(tmp_path / "out"), gif=str(tmp_path)))
    with pytest.raises(RenderError, match="^fps= 0 is not a usable frame rate"):
        render.Renderer(RenderOptions(out=str(tmp_path / "out"), fps=0))
    assert os.listdir(tmp_path) == []


# --------------------------------------------------------------------------
# A full disk: the temporary file goes, the message names the user's file

# Makes every os.write to the pose record's temporary file fail with ENOSPC,
# in the command's own process, then runs the command.
_ENOSPC_POSES = """
import errno, os, sys
from liganimate.runtime import files
real = os.write
def write(fd, data):
    if ".poses.jsonl." in os.readlink(f"/proc/self/fd/{fd}"):
        raise OSError(errno.ENOSPC, "No space left on device")
    return real(fd, data)
files.os.write = write
from liganimate.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_full_disk_with_poses_leaves_no_temporary_file(tmp_path):
    src = program(tmp_path, 600)  # a pose record of about 400 kB: more than the writer's buffer
    r = subprocess.run(
        [
            sys.executable,
            "-c",
            _ENOSPC_POSES,
            "run",
            str(src),
            "-o",
            "out",
            "--poses",
            "out/poses.jsonl",
            "--size",
            "64x48",
            "--quiet",
        ],
        check=False,
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 1, r.stderr
    assert r.stderr == "liganimate: error: no space left on device while writing out/poses.jsonl\n"
    assert leftovers(tmp_path) == []
    assert not (tmp_path / "out" / "poses.jsonl").exists()
    assert not (tmp_path / "out" / outputs.LOCK_NAME).exists()
    for p in pngs(tmp_path / "out"):
        assert read_png(p).shape == (48, 64)


def test_file_size_limit_is_a_real_write_failure(tmp_path):
    # No patching: RLIMIT_FSIZE makes the kernel refuse writes past 100 kB
    # (EFBIG, with SIGXFSZ ignored) as a full disk refuses them with ENOSPC.
    src = program(tmp_path, 600)
    code = (
        "import resource, signal, sys; signal.signal(signal.SIGXFSZ, signal.SIG_IGN); "
        "resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000)); "
        "from liganimate.cli import main; sys.exit(main(sys.argv[1:]))"
    )
    r = subprocess.run(
        [sys.executable, "-c", code, "run", str(src), "-o", "out", "--poses", "p.jsonl", "--size", "64x48", "--quiet"],
        check=False,
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 1, r.stderr
    assert r.stderr == "liganimate: error: the file grew larger than the system allows while writing p.jsonl\n"
    assert leftovers(tmp_path) == []
    assert not (tmp_path / "p.jsonl").exists()


# --------------------------------------------------------------------------
# Two runs, one output


def start(tmp_path, src, *args):
    return subprocess.Popen(
        [sys.executable, "-m", "liganimate", "run", str(src), "--size", "64x48", "--quiet", *args],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def wait_for_frames(proc, folder, n=20):
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()
        if folder.is_dir() and len(os.listdir(folder)) > n:
            return
        time.sleep(0.02)
    raise AssertionError("no frames appeared")


def stop(proc):
    os.kill(proc.pid, signal.SIGTERM)
    proc.communicate(timeout=120)


@pytest.mark.parametrize("second", [["-o", "out"], ["-o", "other", "--gif", "a.gif"]], ids=["folder", "gif"])
def test_a_second_run_on_the_same_output_is_refused(tmp_path, second):
    src = program(tmp_path, 100_000)
    first = start(tmp_path, src, "-o", "out", "--gif", "a.gif")
    try:
        wait_for_frames(first, tmp_path / "out" / "scene1")
        r = run("run", str(src), "--size", "64x48", "--quiet", *second, cwd=tmp_path, timeout=120)
        shown = "out/" if second[1] == "out" else "a.gif"
        assert r.returncode == 1
        assert r.stderr == (
            f"liganimate: error: {shown} is being written by another liganimate run (pid {first.pid}); "
            "wait for it to end or choose another output\n"
        )
        assert not (tmp_path / "other").exists()
    finally:
        stop(first)
    assert first.returncode == 143
    # The lock files go with the run that made them.
    assert not (tmp_path / "out" / outputs.LOCK_NAME).exists() and not (tmp_path / ".a.gif.liganimate.lock").exists()


def test_two_runs_started_together_never_share_a_folder(tmp_path):
    # Both may get past the early check; only one may render.
    src = program(tmp_path, 3000)
    a = start(tmp_path, src, "-o", "out", "--gif", "a.gif")
    b = start(tmp_path, src, "-o", "out", "--gif", "b.gif")
    errs = [p.communicate(timeout=300)[1] for p in (a, b)]
    codes = sorted(p.returncode for p in (a, b))
    assert codes == [0, 1], errs
    assert sum("is being written by another liganimate run" in e for e in errs) == 1
    assert len(pngs(tmp_path / "out")) == 3000


def test_a_killed_run_leaves_nothing_that_stops_the_next(tmp_path):
    src = program(tmp_path, 100_000)
    first = start(tmp_path, src, "-o", "out", "--poses", "p.jsonl")
    wait_for_frames(first, tmp_path / "out" / "scene1")
    workers = children(first.pid)
    assert len(workers) >= 1
    os.kill(first.pid, signal.SIGKILL)
    first.communicate(timeout=60)
    # The workers die with it (they used to wait for work, re-parented to PID 1, for good).
    assert wait_gone(workers, 10) == []
    # What a SIGKILL cannot clean: a temporary file, and the lock file (whose lock the kernel dropped).
    stale = tmp_path / "out" / "scene1" / ".99999.png.abcd1234.tmp"
    stale.write_bytes(b"half")
    assert (tmp_path / "out" / outputs.LOCK_NAME).exists()
    short = program(tmp_path, 10, "short")
    r = run("run", str(short), "-o", "out", "--poses", "p.jsonl", "--size", "64x48", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert leftovers(tmp_path) == []
    assert not (tmp_path / "out" / outputs.LOCK_NAME).exists()


def test_locks_exclude_within_one_process_and_are_released(tmp_path):
    out = tmp_path / "out"
    held = outputs.OutputLock(out, [str(tmp_path / "a.gif")])
    with pytest.raises(RenderError, match="is being written by another liganimate run"):
        outputs.OutputLock(out)
    with pytest.raises(RenderError, match="^.*a.gif is being written"):
        outputs.OutputLock(tmp_path / "elsewhere", [str(tmp_path / "a.gif")])
    assert not (tmp_path / "elsewhere").exists()  # a refused run leaves no folder behind
    held.release()
    held.release()
    again = outputs.OutputLock(out, [str(tmp_path / "a.gif")])
    again.release()
    assert os.listdir(out) == [] and sorted(os.listdir(tmp_path)) == ["out"]


def test_errno_words_keep_unknown_errors_readable():
    from liganimate.runtime.files import os_error_words

    assert os_error_words(OSError(errno.ENOSPC, "No space left on device")) == "no space left on device"
    assert os_error_words(OSError(errno.ENXIO, "No such device or address")) == "no such device or address"


# --------------------------------------------------------------------------
# Signals: the first stops, the rest are noted


def test_a_second_signal_during_cleanup_is_only_noted():
    # `timeout -s INT` sends two SIGINTs a millisecond apart; the second used to
    # raise KeyboardInterrupt inside the cleanup of the first and print a traceback.
    from liganimate.runtime import interrupts

    before = {s: signal.getsignal(s) for s in interrupts.SIGNALS}
    cleaned = []
    try:
        assert interrupts.stop_on_signals()
        with pytest.raises(interrupts.Interrupted) as info:
            try:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(10)  # the handler raises here
            finally:
                os.kill(os.getpid(), signal.SIGINT)
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(0.05)  # both handlers run now, inside the cleanup, and must not raise
                cleaned.append("done")
        assert info.value.signum == signal.SIGINT
        assert cleaned == ["done"]
        # A SIGTERM among them makes the stop a termination (exit status 143).
        assert interrupts.stopped_by() == signal.SIGTERM
    finally:
        for s, handler in before.items():
            signal.signal(s, handler)


def test_the_library_still_makes_the_pose_records_folder(tmp_path):
    # Program.render(poses=...) has always created the record's folder; the command line refuses a missing one.
    from liganimate.compiler import load_program

    prog, _ = load_program(str(program(tmp_path, 3)))
    prog.render(str(tmp_path / "frames"), size=(8, 6), poses=str(tmp_path / "new" / "p.jsonl"), quiet=True, workers=1)
    assert len((tmp_path / "new" / "p.jsonl").read_text().splitlines()) == 3
    with pytest.raises(
        RenderError,
        match=r"^poses= .*/swing.lig/x/y cannot be created: .*/swing.lig is a file, "
        "not a folder$",
    ):
        prog.render(str(tmp_path / "frames"), poses=str(tmp_path / "swing.lig" / "x" / "y" / "p.jsonl"), quiet=True)
    with pytest.raises(
        RenderError, match=r"^poses= .*/p.jsonl cannot be written: the folder .*swing.lig is not a folder$"
    ):
        prog.render(str(tmp_path / "frames"), poses=str(tmp_path / "swing.lig" / "p.jsonl"), quiet=True)
