"""LIG variables named after Python keywords, builtins, modules and the
generated module's own machinery compile, run, render, and survive
``liganimate compile`` into a standalone module."""

from __future__ import annotations

import importlib.util
import subprocess
import sys

import numpy as np
import pytest

from liganimate.compiler import compile_text, load_program
from liganimate.lang.diagnostics import LigDiagnostics

# class, None, self ... as GRAPHICAL objects, MODELs, MOTIONs, INTEGERs,
# REALs and a VECTOR. (print is tested on its own below: it is also a LIG
# statement keyword. _host is not a LIG name at all: names begin with a letter.)
NAMES = """\
C Variables named after Python keywords, builtins and modules, and after
C the names the generated module uses itself.

      GRAPHICAL class, None, host
      MODEL self, os, sys
      MOTION np, lambda, program
      INTEGER liganimate, def, main
      REAL rt, True
      VECTOR import

      liganimate = 1
      def = liganimate + 1
      rt = 0.5
      True = rt * 2.0
      import = (0.0, True, 0.0)

      class :- BOX WIDTH 0.4, HEIGHT 1.0, DEPTH 0.4, LIGHTNESS 30.0
      None :- BOX WIDTH 0.3, HEIGHT 0.8, DEPTH 0.3, LIGHTNESS 20.0
      host :- BOX AT (0.0, -1.6, 0.0), WIDTH 6.0, HEIGHT 0.1, DEPTH 2.0,
                  LIGHTNESS 60.0

      self :- JOINT liganimate, class, (0.0, -0.5, 0.0),
                    None, (0.0, 0.4, 0.0),
                    (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)
      os :- self <TRANS JOINTS BY def>
      sys :- JOINT 5, self, (0.0, 0.5, 0.0), os, (0.0, 0.5, 0.0),
                   (0.0, 0.0), (0.0, 0.0), (-180.0, 180.0)

      STARTMOTION np
        JOINT 1
          FRAME 6 POSITION 0.0, 0.0, 60.0 INTERPOLATE ACCDCC
        ENDJOINT
      ENDMOTION
      lambda[3, 1] := FRAME 4 POSITION import INTERPOLATE LINEAR
      lambda = def * lambda <SCALE EXTREMES 30.0>
      program := SYNCHRONIZE np, lambda
      main = NINT(LEN(program))

      PRINT self, $sys, program, rt, class

      INITIALIZE SCENE 1
          VIEW POINT = (1.0, 1.0, 6.0)
          VIEW WIDTH = 4.0
          BACKGROUND host
      STARTSCENE LENGTH 2
          ANIMATE sys FROM 0 TO main USING program REPEAT
      ENDSCENE
      SHOOTSCENES
      END
"""


def program_of(text: str, name: str = "names.lig"):
    return load_program(text=text, name=name)


def check_values(variables):
    assert variables["LIGANIMATE"] == 1
    assert variables["DEF"] == 2
    assert variables["RT"] == 0.5
    assert variables["TRUE"] == 1.0
    assert tuple(variables["IMPORT"]) == (0.0, 1.0, 0.0)
    assert variables["SELF"].joint_ids == (1,)
    assert variables["OS"].joint_ids == (3,)
    assert sorted(variables["SYS"].joint_ids) == [1, 3, 5]
    assert [l.name for l in variables["SELF"].links] == ["CLASS", "NONE"]
    assert variables["PROGRAM"].joints == (1, 3)
    assert variables["MAIN"] == 8
    assert len(variables["CLASS"]) == 12  # a box: 12 triangles


def test_reserved_names_compile_check_and_keep_their_values():
    program, warnings = program_of(NAMES)
    assert warnings == []
    assert program.check() == []
    check_values(program.execute("check").variables)


def _dark(path):
    from PIL import Image

    return (np.asarray(Image.open(path).convert("L")) < 100).sum()


def test_reserved_names_render_a_frame(tmp_path):
    import io

    program, _ = program_of(NAMES)
    out = io.StringIO()
    program.render(str(tmp_path), size=(80, 60), quiet=True, stdout=out)
    frames = sorted(p.name for p in (tmp_path / "scene1").iterdir())
    assert frames == ["00000.png", "00001.png"]
    assert _dark(tmp_path / "scene1" / "00001.png") > 20
    printed = out.getvalue()
    assert "MODEL SELF" in printed and "MOTION PROGRAM" in printed and "RT = 0.5" in printed


def test_compiled_module_imports_and_runs(tmp_path):
    (tmp_path / "names.lig").write_text(NAMES, encoding="utf-8")
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "compile", "names.lig", "-o", "out.py"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    module_path = tmp_path / "out.py"
    # Import it as a module: it defines program, and running it changes nothing in the importer.
    spec = importlib.util.spec_from_file_location("liganimate_names_module", module_path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    check_values(module.program.execute("check").variables)
    # Run it as a script.
    r = subprocess.run(
        [sys.executable, "out.py", "-o", "frames", "--size", "80x60", "--quiet"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    assert "MODEL SELF" in r.stdout
    assert (tmp_path / "frames" / "scene1" / "00001.png").is_file()
    assert _dark(tmp_path / "frames" / "scene1" / "00001.png") > 20


def test_print_as_a_variable_name():
    """PRINT starts a statement, but like WIDTH or LENGTH it should stay usable as a name."""
    program, _ = program_of(
        "      GRAPHICAL print\n"
        "      print :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0\n"
        "      INTEGER n\n"
        "      n = 3\n"
        "      PRINT print, n\n"
    )
    variables = program.execute("check").variables
    assert len(variables["PRINT"]) == 12


def test_underscore_names_are_not_lig_names():
    with pytest.raises(LigDiagnostics) as info:
        compile_text("      REAL X\n      _host = 1\n", "u.lig")
    d = info.value.diagnostics[0]
    assert (d.pos.line, d.pos.column) == (2, 7)
    assert "'_'" in d.message
