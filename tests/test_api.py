"""The public Python API: load/loads, one exception type, typed for users' checkers, its reference current."""

from __future__ import annotations

import gc
import importlib.resources
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from paths import ROOT_DIR

import liganimate
from liganimate.lang.diagnostics import LigDiagnostics

ROOT = Path(ROOT_DIR)
SCENE = """\
      LOAD HUMANOID, WALK FROM 'humanoid'
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 3
        ANIMATE HUMANOID FROM 0 TO 2 USING WALK
      ENDSCENE
      SHOOTSCENES
"""


def test_every_public_name_is_importable_from_liganimate():
    for name in liganimate.__all__:
        assert getattr(liganimate, name) is not None, name
    with pytest.raises(AttributeError):
        liganimate.Renderer  # noqa: B018 - not public
    # The scene and pose types are the exchange package's public ones, not a private module's.
    from liganimate.runtime import exchange, render

    assert liganimate.SceneTake is exchange.SceneTake and liganimate.ModelTake is exchange.ModelTake
    assert liganimate.RenderOptions is render.options.RenderOptions


def test_load_takes_a_path_and_loads_takes_text(tmp_path):
    path = tmp_path / "walk.lig"
    path.write_text(SCENE)
    by_path, by_text = liganimate.load(path), liganimate.loads(SCENE, name="walk")
    assert by_path.name == str(path) and by_text.name == "walk"
    assert [t.id for t in by_path.scenes()] == [t.id for t in by_text.scenes()] == [1]
    assert by_path.scenes()[0].models[0].angles.tolist() == by_text.scenes()[0].models[0].angles.tolist()
    # A path that happens not to exist is a missing file, never taken for program text.
    with pytest.raises(FileNotFoundError):
        liganimate.load(str(tmp_path / "X = 1"))
    with pytest.raises(TypeError, match="loads"):
        liganimate.load(SCENE)


def test_one_exception_type_for_everything_wrong_with_a_program_or_an_option(tmp_path):
    cases = {
        "compile": lambda: liganimate.loads("      X = (1,\n"),
        "run": lambda: liganimate.loads("      X = 1 / 0\n").check(),
        "no scene": lambda: liganimate.loads("      X = 1\n").export(tmp_path / "a.glb"),
        "format": lambda: liganimate.loads(SCENE).export(tmp_path / "a.obj"),
        "export option": lambda: liganimate.loads(SCENE).export(tmp_path / "a.bvh", size=(1, 1)),
        "render option": lambda: liganimate.loads(SCENE).render(tmp_path / "f", fps=0),
        "output": lambda: liganimate.loads(SCENE).render(tmp_path / "f", gif=str(tmp_path / "no" / "a.gif")),
        "scene id": lambda: liganimate.loads(SCENE).view(scene=9),
    }
    for what, action in cases.items():
        with pytest.raises(liganimate.LigProgramError) as info:
            action()
        err = info.value
        assert isinstance(err, ValueError) and isinstance(err, LigDiagnostics), what
        assert str(err) and "Traceback" not in str(err), what
    assert sorted(os.listdir(tmp_path)) == []
    with pytest.raises(liganimate.LigProgramError) as info:
        liganimate.loads(SCENE).export(tmp_path / "a.obj")
    from liganimate.runtime.exchange import EXPORT_FORMATS

    suffixes = [s for f in EXPORT_FORMATS for s in f.suffixes]
    assert str(info.value) == (
        f"cannot tell the format of {tmp_path / 'a.obj'} from its extension.\n"
        f"  hint: write to a file ending in {', '.join(suffixes[:-1])} or {suffixes[-1]}"
    )


def test_loading_leaves_the_calling_process_as_it_was():
    gc.unfreeze()
    before = gc.isenabled()
    liganimate.loads(SCENE).scenes()
    assert gc.get_freeze_count() == 0 and gc.isenabled() == before


def test_py_typed_is_shipped():
    assert importlib.resources.files("liganimate").joinpath("py.typed").is_file()
    assert '"liganimate" = ["py.typed"]' in (ROOT / "pyproject.toml").read_text()


def _installed_layout(folder: Path) -> Path:
    """liganimate as a wheel installs it (src/liganimate, with lang/ compiler/ runtime/ stdlib/ inside)."""
    package = folder / "liganimate"
    package.mkdir(parents=True)
    for entry in (ROOT / "src" / "liganimate").iterdir():
        (package / entry.name).symlink_to(entry)
    for sub in ("lang", "compiler", "runtime", "stdlib"):
        (package / sub).symlink_to(ROOT / sub)
    return folder


def test_a_users_type_checker_sees_the_api_typed(tmp_path):
    pytest.importorskip("mypy")
    user = tmp_path / "user.py"
    user.write_text(
        textwrap.dedent(
            """\
            import liganimate

            film = liganimate.load("scene.lig")
            reveal_type(film)
            reveal_type(liganimate.loads)
            film.render("frames", options=liganimate.RenderOptions(size=(64, 48)))
            paths: list[str] = film.export("a.glb", fps=30)
            liganimate.load(42)
            """
        )
    )
    env = dict(os.environ, MYPYPATH=str(_installed_layout(tmp_path / "site")))
    r = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--follow-imports=silent", "--cache-dir", str(tmp_path / "cache")]
        + [str(user)],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
    )
    out = r.stdout
    assert 'Revealed type is "liganimate.api.LoadedProgram"' in out, out
    assert 'Revealed type is "def (text: str, name: str =) -> liganimate.api.LoadedProgram"' in out, out
    # The one error: a number is not a path (the API is not Any to the checker).
    errors = [line for line in out.splitlines() if ": error:" in line]
    assert len(errors) == 1 and "user.py:8:" in errors[0] and '"load" has incompatible type "int"' in errors[0], out


def test_the_api_reference_is_what_the_docstrings_say():
    r = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "api_reference.py"), "--check"], capture_output=True, text=True
    )
    assert r.returncode == 0, r.stderr
    page = (ROOT / "docs" / "api.md").read_text()
    for name in liganimate.__all__:
        if not name.startswith("_"):
            assert f"liganimate.{name}(" in page, name


def test_the_reference_check_fails_on_a_stale_page(tmp_path, monkeypatch):
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import api_reference
    finally:
        sys.path.remove(str(ROOT / "tools"))
    stale = tmp_path / "api.md"
    stale.write_text(api_reference.page().replace("Compile the LIG ANIMATE program in a file.", "Old words."))
    monkeypatch.setattr(api_reference, "PAGE", str(stale))
    assert api_reference.main(["--check"]) == 1
    assert api_reference.main([]) == 0 and api_reference.main(["--check"]) == 0
    assert "Compile the LIG ANIMATE program in a file." in stale.read_text()
