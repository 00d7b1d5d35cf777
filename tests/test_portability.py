"""The command line without the POSIX-only parts of Python: it renders, exports and views as on Windows.

A ``sitecustomize`` on the subprocess's path makes ``import fcntl`` (and
``msvcrt``, ``resource``, ``termios``, ``pwd``, ``grp``) fail and removes
``signal.pthread_sigmask`` and the ``os.O_*`` flags Windows lacks, before
liganimate is imported. Every output must then be what a normal run writes.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

BLOCKER = textwrap.dedent(
    """\
    import importlib.abc, os, signal, sys

    BLOCKED = {"fcntl", "msvcrt", "resource", "termios", "pwd", "grp"}
    for name in BLOCKED:
        sys.modules.pop(name, None)

    class Blocker(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name in BLOCKED:
                raise ModuleNotFoundError(f"No module named {name!r} (blocked by the portability test)", name=name)
            return None

    sys.meta_path.insert(0, Blocker())
    for attr in ("pthread_sigmask",):
        if hasattr(signal, attr):
            delattr(signal, attr)
    for attr in ("O_NOFOLLOW", "O_CLOEXEC", "O_DIRECTORY", "O_NOCTTY"):
        if hasattr(os, attr):
            delattr(os, attr)
    """
)

# Twenty images: enough for the pool of worker processes (their set-up without pthread_sigmask).
PROGRAM = """\
      LOAD HUMANOID, WALK FROM 'humanoid'
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 20
        ANIMATE HUMANOID FROM 0 TO 19 USING WALK
      ENDSCENE
      SHOOTSCENES
"""


def _run(args, cwd, env):
    return subprocess.run(
        [sys.executable, "-m", "liganimate", *args], cwd=cwd, env=env, capture_output=True, text=True, check=False
    )


@pytest.fixture()
def env_without_posix(tmp_path):
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(BLOCKER)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(site), *filter(None, [env.get("PYTHONPATH")])])
    return env


def test_the_blocker_blocks(tmp_path, env_without_posix):
    code = "import os, signal\ntry:\n    import fcntl\nexcept ImportError:\n    print('no fcntl')\n"
    code += "print(hasattr(signal, 'pthread_sigmask'), hasattr(os, 'O_NOFOLLOW'))\n"
    r = subprocess.run(
        [sys.executable, "-c", code], env=env_without_posix, capture_output=True, text=True, cwd=tmp_path
    )
    assert r.stdout == "no fcntl\nFalse False\n", r.stderr


def test_run_export_and_view_without_posix_modules(tmp_path, env_without_posix):
    work, plain = tmp_path / "work", tmp_path / "plain"
    for folder in (work, plain):
        folder.mkdir()
        (folder / "walk.lig").write_text(PROGRAM)
    commands = [
        ["run", "walk.lig", "-o", "frames", "--size", "64x48", "--gif", "walk.gif", "--poses", "walk.jsonl"],
        ["export", "walk.lig", "-o", "walk.glb"],
        ["view", "walk.lig", "-o", "walk.html"],
    ]
    for args in commands:
        r = _run(args, work, env_without_posix)
        assert r.returncode == 0, r.stderr
        assert "internal error" not in r.stderr and "Traceback" not in r.stderr
        assert _run(args, plain, None).returncode == 0
    written = sorted(os.listdir(work))
    assert written == ["frames", "walk.gif", "walk.glb", "walk.html", "walk.jsonl", "walk.lig"]
    assert len(os.listdir(work / "frames" / "scene1")) == 20  # and no lock file left behind
    assert not [n for n in os.listdir(work / "frames") if n != "scene1"]
    for name in ("walk.gif", "walk.glb", "walk.jsonl", "frames/scene1/00019.png"):
        assert (work / name).read_bytes() == (plain / name).read_bytes(), name


def test_the_lock_without_an_os_lock_refuses_a_second_run_and_takes_over_a_dead_ones(tmp_path, env_without_posix):
    # The lock file made by exclusive creation: a live holder's pid refuses; a dead one's is taken over.
    code = textwrap.dedent(
        """\
        import os, sys
        from liganimate.runtime.render import outputs
        from liganimate.runtime.errors import RenderError
        assert outputs.fcntl is None and outputs.msvcrt is None
        out = sys.argv[1]
        held = outputs.OutputLock(out)
        lock = os.path.join(out, outputs.LOCK_NAME)
        assert open(lock).read() == f"{os.getpid()}\\n"
        try:
            outputs.OutputLock(out)
        except RenderError as exc:
            print("refused:", exc)
        held.release()
        assert not os.path.exists(lock)
        with open(lock, "w") as fh:
            fh.write("999999999\\n")  # a pid no process has: a killed run's lock
        again = outputs.OutputLock(out)
        print("taken over:", open(lock).read().strip() == str(os.getpid()))
        again.release()
        """
    )
    r = subprocess.run(
        [sys.executable, "-c", code, str(tmp_path / "out")],
        env=env_without_posix,
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].startswith("refused: ") and "is being written by another liganimate run" in lines[0]
    assert lines[1] == "taken over: True"
