"""LOAD: finding, compiling, caching and importing libraries, and every way it can go wrong."""

from __future__ import annotations

import pathlib
import textwrap

import numpy as np
import pytest
from commands import liganimate as cli
from commands import python

from liganimate.compiler import compile_file, compile_text, library
from liganimate.lang.diagnostics import LigDiagnostics

SHAPES = """\
{@ PRISM: a square drawn by a primitive of the library }
PRIMITIVE PRISM
  REAL S, L
  PRISM ::= 'PRISM' 'SIZE' S [ ',' 'LIGHTNESS' L ] <L = 30.0> ;
  DRAW WITH <LIGHTNESS L>
  DRAW POLY FROM (0, 0, 0) TO (S, 0, 0) TO (S, S, 0) TO (0, S, 0)
  DRAW WITH <LIGHTNESS 1.0 / (S - 2)>
  RETURN
END
{@ CUBE: a unit cube }
CUBE :- BOX WIDTH 1, HEIGHT 1, DEPTH 1
K = 3
"""

ARM = """\
LOAD PRISM FROM 'shapes.lig'
G :- PRISM SIZE 3
{@ ARM: a two-segment arm }
ARM :- JOINT 1, G, (0, 0, 0), G, (0, 1, 0), (0, 90)
{@ WAVE: lifts the arm }
WAVE[1, 0] := FRAME 0 POSITION 0, 0, 0
WAVE[1, 1] := FRAME 10 POSITION 45, 0, 0
"""


@pytest.fixture
def libs(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "shapes.lig").write_text(SHAPES)
    (tmp_path / "lib" / "arm.lig").write_text(ARM)
    library.forget()
    return tmp_path


def write(folder: pathlib.Path, text: str, name: str = "prog.lig") -> str:
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return str(path)


def execute(path: str) -> dict:
    from liganimate.compiler import load_program

    program, _ = load_program(path)
    return program.execute("check").variables


def errors(path: str) -> list:
    with pytest.raises(LigDiagnostics) as info:
        compile_file(path)
    return info.value.diagnostics


def test_named_values_and_primitives_arrive(libs):
    path = write(
        libs,
        """\
        LOAD 'lib/shapes'
        LOAD ARM, WAVE FROM 'lib/arm.lig'
        X :- (PRISM SIZE 3) + CUBE
    """,
    )
    v = execute(path)
    assert len(v["CUBE"]) == 12  # a box: 6 faces of 2 triangles
    assert len(v["X"]) == 12 + 2
    assert v["ARM"].n_joints == 1 and v["ARM"].joint_ids == (1,)
    assert v["WAVE"].length == 10
    # LOAD 'library' brings models, motions, graphics and primitives, not helper numbers.
    assert "K" not in v


def test_load_all_is_the_documented_default_set(libs):
    lib = library.load("lib/shapes", library.resolve("lib/shapes", str(libs / "p.lig")))
    assert lib.default_names() == ["PRISM", "CUBE"]
    assert lib.descriptions == {"PRISM": "a square drawn by a primitive of the library", "CUBE": "a unit cube"}
    # A helper number still comes when named.
    v = execute(write(libs, "LOAD K FROM 'lib/shapes.lig'\nY = K * 2\n"))
    assert v["Y"] == 6


def test_a_library_exports_only_its_own_definitions(libs):
    lib = library.load("lib/arm.lig", library.resolve("lib/arm.lig", str(libs / "p.lig")))
    assert "PRISM" not in lib.types and "PRISM" not in lib.signatures
    assert {"G", "ARM", "WAVE"} <= set(lib.types)


def test_compiled_module_is_standalone(libs, tmp_path_factory):
    path = write(
        libs,
        """\
        LOAD ARM, WAVE FROM 'lib/arm.lig'
        VIEW POINT = (0, 0, 6)
        INITIALIZE SCENE 1
        STARTSCENE LENGTH 2
        ANIMATE ARM FROM 0 TO 1 USING WAVE
        ENDSCENE
        SHOOTSCENES
    """,
    )
    module = compile_file(path).python
    elsewhere = tmp_path_factory.mktemp("elsewhere")
    (elsewhere / "prog.py").write_text(module)
    for f in (libs / "lib").iterdir():
        f.unlink()  # the module must not need the library files any more
    r = python("prog.py", "-o", "out", "--size", "80x60", "--quiet", cwd=elsewhere)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in (elsewhere / "out" / "scene1").iterdir()) == ["00000.png", "00001.png"]


def test_error_inside_a_library_primitive_points_into_the_library(libs):
    path = write(libs, "LOAD PRISM FROM 'lib/shapes.lig'\nX :- PRISM SIZE 2\n")
    from liganimate.compiler import load_program

    program, _ = load_program(path)
    with pytest.raises(LigDiagnostics) as info:
        program.execute("check")
    d = info.value.diagnostics[0]
    assert d.filename == "lib/shapes.lig"
    assert (d.pos.line, d.pos.column) == (7, 28)  # the '/'
    assert d.message == "division by zero"


def test_library_not_found_suggests_the_standard_ones(libs):
    (d,) = errors(write(libs, "LOAD 'humanod'\n"))
    assert (d.pos.line, d.pos.column) == (1, 6)
    assert d.message.startswith("there is no library 'humanod'")
    assert "a file of your own is named by a path" in d.hint


def test_missing_file_names_where_it_looked(libs):
    (d,) = errors(write(libs, "LOAD 'lib/nothere.lig'\n"))
    assert str(libs / "lib" / "nothere.lig") in d.message


def test_a_library_with_errors_shows_them_and_the_load(libs):
    write(libs / "lib", "X = 1 +\nY = 2\n", "bad.lig")
    first, last = errors(write(libs, "LOAD 'lib/bad.lig'\n"))
    assert first.filename == "lib/bad.lig" and first.pos.line == 2
    assert (last.pos.line, last.pos.column) == (1, 6)
    assert last.message == "the library 'lib/bad.lig' has errors (shown above)"


def test_libraries_loading_each_other_is_a_cycle(libs):
    write(libs / "lib", "LOAD 'c2.lig'\n", "c1.lig")
    write(libs / "lib", "LOAD 'c1.lig'\n", "c2.lig")
    diags = errors(write(libs, "LOAD 'lib/c1.lig'\n"))
    assert diags[0].message == "libraries load each other in a circle: c1.lig -> c2.lig -> c1.lig"


def test_a_program_with_scenes_is_not_a_library(libs):
    write(libs / "lib", "INITIALIZE SCENE 1\nSTARTSCENE LENGTH 1\nENDSCENE\n", "scene.lig")
    (d,) = errors(write(libs, "LOAD 'lib/scene.lig'\n"))
    assert d.message == "lib/scene.lig defines scenes, so it is a program, not a library"


def test_unknown_name_in_a_library(libs):
    (d,) = errors(write(libs, "LOAD ARN FROM 'lib/arm.lig'\n"))
    assert (d.pos.line, d.pos.column, d.message, d.hint) == (1, 6, "lib/arm.lig has no ARN", "did you mean ARM?")


def test_loading_over_a_definition_is_an_error(libs):
    (d,) = errors(write(libs, "ARM = 1\nLOAD ARM FROM 'lib/arm.lig'\n"))
    assert (d.pos.line, d.pos.column) == (2, 6)
    assert d.message == "ARM is already defined at line 1, so loading it would overwrite it"


def test_two_libraries_defining_one_name_is_an_error(libs):
    write(libs / "lib", "{@ CUBE: another cube }\nCUBE :- BOX WIDTH 2, HEIGHT 2, DEPTH 2\n", "other.lig")
    (d,) = errors(write(libs, "LOAD CUBE FROM 'lib/shapes.lig'\nLOAD 'lib/other.lig'\n"))
    assert (d.pos.line, d.message) == (2, "CUBE is already loaded from another library at line 1")


def test_loading_a_library_twice_warns_and_changes_nothing(libs):
    compiled = compile_file(write(libs, "LOAD 'lib/shapes.lig'\nLOAD 'lib/shapes.lig'\n"))
    messages = [w.message for w in compiled.warnings]
    assert "PRISM is already loaded from lib/shapes.lig at line 1; this LOAD of it does nothing" in messages
    assert "CUBE is already loaded from lib/shapes.lig at line 1; this LOAD of it does nothing" in messages


def test_load_belongs_at_the_top_level(libs):
    (d,) = errors(write(libs, "DO 10 I = 1, 2\nLOAD 'lib/shapes.lig'\n10 CONTINUE\n"))
    assert (d.pos.line, d.pos.column) == (2, 1)
    assert d.message.startswith("LOAD belongs at the top level")


def test_load_is_still_a_variable_name():
    v = compile_text("LOAD = 3\nX = LOAD + 1\n")
    assert "LOAD = 3" in v.python and "LOAD + 1" in v.python


def test_disk_cache_spares_the_parse_and_notices_edits(libs, monkeypatch):
    prog = write(libs, "LOAD ARM FROM 'lib/arm.lig'\n")
    compile_file(prog)  # fills the disk cache
    library.forget()
    import liganimate.compiler as C

    parsed = []
    real = C.parse_source
    monkeypatch.setattr(C, "parse_source", lambda src, *a, **k: parsed.append(src.filename) or real(src, *a, **k))
    compile_file(prog)
    assert parsed == [prog], "the libraries came from the disk cache"
    # Editing a library that arm.lig loads makes arm.lig's entry stale too.
    (libs / "lib" / "shapes.lig").write_text(SHAPES.replace("<L = 30.0>", "<L = 20.0>"))
    library.forget()
    parsed.clear()
    compile_file(prog)
    assert sorted(parsed) == sorted([prog, "lib/arm.lig", "shapes.lig"])


def test_compile_output_does_not_depend_on_the_cache(libs):
    prog = write(libs, "LOAD ARM FROM 'lib/arm.lig'\n")
    first = compile_file(prog).python
    library.forget()
    assert compile_file(prog).python == first


def test_library_values_are_shared_not_aliased(libs):
    # Two programs loading one library get equal values; changing one's copy
    # (here: a new joint on ARM) leaves the library's own value alone.
    v1 = execute(write(libs, "LOAD ARM FROM 'lib/arm.lig'\nARM :- ARM <SCALE MODEL 2>\n", "a.lig"))
    v2 = execute(write(libs, "LOAD ARM FROM 'lib/arm.lig'\n", "b.lig"))
    s1 = v1["ARM"].locations[1]
    s2 = v2["ARM"].locations[1]
    assert np.allclose(s1, 2 * s2)


def test_archive_writes_a_library_that_loads_back(libs):
    write(
        libs,
        """\
        LOAD ARM, WAVE FROM 'lib/arm.lig'
        {@ BIGARM: the arm, twice as big }
        BIGARM :- ARM <SCALE MODEL 2>
        W2 = 1000000000 * WAVE
        INITIALIZE SCENE 1
        STARTSCENE LENGTH 2
        ANIMATE BIGARM FROM 0 TO 1 USING W2
        ENDSCENE
        IF 1 > 0 THEN SHOOTSCENES
    """,
        "scene.lig",
    )
    (libs / "out").mkdir()
    r = cli("archive", "scene.lig", "-o", "out/mine.lig", cwd=libs)
    assert r.returncode == 0, r.stderr
    text = (libs / "out" / "mine.lig").read_text()
    assert "LOAD ARM, WAVE FROM '../lib/arm.lig'" in text  # re-aimed from the archive's folder
    assert "STARTSCENE" not in text and "SHOOTSCENES" not in text
    assert "{@ W2: MOTION defined in scene.lig }" in text
    v = execute(write(libs, "LOAD 'out/mine.lig'\n", "user.lig"))
    assert v["W2"].length == 10 * 1000000000
    assert np.allclose(
        v["BIGARM"].locations[1],
        2 * execute(write(libs, "LOAD ARM FROM 'lib/arm.lig'\n", "u2.lig"))["ARM"].locations[1],
    )
    r = cli("lib", "out/mine.lig", cwd=libs)
    assert r.returncode == 0, r.stderr
    assert "BIGARM  MODEL      the arm, twice as big" in r.stdout


def test_archive_of_a_bad_program_writes_nothing(libs):
    write(libs, "X = 1 +\n", "bad.lig")
    r = cli("archive", "bad.lig", "-o", "bad_lib.lig", cwd=libs)
    assert r.returncode == 1 and "bad.lig:1:8: error" in r.stderr
    assert not (libs / "bad_lib.lig").exists()


def test_lib_lists_the_standard_library(libs):
    r = cli("lib", cwd=libs)
    assert r.returncode == 0, r.stderr
    for name in library.stdlib_names():
        assert f"{name}  (stdlib/{name}.lig)" in r.stdout
    r = cli("lib", "nope", cwd=libs)
    assert r.returncode == 1 and "there is no library 'nope'" in r.stderr and "Traceback" not in r.stderr


def test_a_missing_standard_library_does_not_quote_where_the_package_lives(tmp_path):
    # The install folder (site-packages/...) means nothing to the user; the
    # hint lists the standard libraries instead. A path LOAD still says where it looked.
    r = cli("check", str(write(tmp_path, "LOAD 'nowhere'\n", "p.lig")), cwd=tmp_path)
    assert r.returncode == 1 and "there is no library 'nowhere' in the standard library" in r.stderr
    assert "stdlib" not in r.stderr.split("hint:")[0] and "humanoid" in r.stderr
    r = cli("check", str(write(tmp_path, "LOAD 'lib/nowhere.lig'\n", "q.lig")), cwd=tmp_path)
    assert r.returncode == 1 and "looked for " in r.stderr and "nowhere.lig" in r.stderr


def test_each_load_is_resolved_and_loaded_once_per_compile(monkeypatch):
    # The lexer needs the loaded primitives before parsing and the checker
    # reports at the LOAD line after: both read library.open_library's result.
    calls = []
    real = library.load
    monkeypatch.setattr(library, "load", lambda *a, **k: calls.append(a[0]) or real(*a, **k))
    compile_text("LOAD ARM FROM 'arm'\nLOAD ARM FROM 'arm'\nX = 1\n")
    assert calls == ["arm"]


def test_a_failing_library_is_reported_once_at_its_load():
    with pytest.raises(LigDiagnostics) as info:
        compile_text("LOAD X FROM 'no_such_library'\nY = 1\n")
    found = [d for d in info.value.diagnostics if "no_such_library" in d.message]
    assert len(found) == 1 and found[0].pos.line == 1


def test_a_library_from_the_cache_lowers_as_one_compiled_afresh(tmp_path):
    # robot_arm.lig LOADs a URDF import whose name table has rows with and
    # without joint columns; read back from the cache, a row without them
    # used to gain three Nones, so the module changed with the cache's state.
    import os

    example = pathlib.Path(__file__).resolve().parents[2] / "examples" / "robot_arm.lig"
    env = {**os.environ, "LIGANIMATE_CACHE": str(tmp_path / "cache")}
    texts = []
    for run in ("miss", "hit", "no cache"):
        if run == "no cache":
            env["LIGANIMATE_CACHE"] = ""
        out = tmp_path / f"{run.replace(' ', '_')}.py"
        r = cli("compile", str(example), "-o", str(out), env=env)
        assert r.returncode == 0, r.stderr
        texts.append(out.read_text())
        if run == "miss":
            assert any((tmp_path / "cache").rglob("*.json")), "the first compile stores the library"
    assert texts[0] == texts[1] == texts[2]
    assert "'RAIL': ('rail', (), None)," in texts[0]
