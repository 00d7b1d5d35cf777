"""What a cold ``liganimate check`` imports: the language, the compiler and the host, never the renderer, the
solvers or the exchange formats (issue 22's start-up goal; benchmarks/compile.py measures its cost).

Structural, not timed: a new process runs the command's own entry point on Appendix A and lists the
modules it holds at exit. A module that appears here was imported by something ``check`` runs; make
that import lazy (at its call site) rather than widen the allowed list.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

from paths import ROOT_DIR

APPENDIX_A = os.path.join(ROOT_DIR, "examples", "appendix_a.lig")

#: Run ``liganimate check`` as the console script does, then print the modules loaded.
_PROBE = """
import json, sys
from liganimate.cli import main
sys.argv[1:] = ["check", sys.argv[1]]
status = main()
sys.stdout.write("\\n" + json.dumps({"status": status, "modules": sorted(sys.modules)}) + "\\n")
"""

#: Packages check needs none of: drawing, solving, reading or writing other formats, the plugin lookup.
FORBIDDEN = (
    "liganimate.runtime.render.",
    "liganimate.runtime.ik.",
    "liganimate.runtime.exchange.",
    "liganimate.runtime.view",
    "liganimate.runtime.studio",
    "importlib.metadata",
    "matplotlib",
    "scipy",
    # The other commands' options: ``liganimate check`` builds only its own (cli.build_parser).
    "liganimate.exchange_cli",
    "liganimate.view_cli",
    "liganimate.fmt_cli",
    "liganimate.runtime.render.movies",
    "liganimate.runtime.exchange",
    # The language server's incremental parser; the libraries (Appendix A LOADs none) and their cache;
    # the did-you-mean hints of a wrong name.
    "liganimate.lang.incremental",
    "liganimate.compiler.library",
    "difflib",
    # Reading and packing a TABLE's numbers (Appendix A has no TABLE).
    "liganimate.lang.keyframe_table",
    "base64",
    # Posing and morphing segments: Appendix A poses nothing during a check (a graphical sum of
    # graphicals, no figure drawn as one), so the kinematics' walks are never needed.
    "liganimate.runtime.figure.pose",
    "liganimate.runtime.figure.morphing",
    "liganimate.runtime.figure.short",
    "liganimate.runtime.figure.folded",
    "liganimate.runtime.figure.walk",
)
#: Light modules under those packages that check does use: the host's framing of a scene and its camera,
#: REACH's options and solver names.
ALLOWED = {
    "liganimate.runtime.render.framing",
    "liganimate.runtime.render.camera",
    "liganimate.runtime.ik.options",
    "liganimate.runtime.ik.names",
}


def _modules_after_check() -> list[str]:
    r = subprocess.run(
        [sys.executable, "-c", _PROBE, APPENDIX_A], cwd=ROOT_DIR, capture_output=True, text=True, check=False
    )
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout.strip().splitlines()[-1])
    assert report["status"] == 0, r.stderr
    return report["modules"]


def test_check_makes_its_records_without_dataclass_inspection():
    # Every record a check makes (the syntax tree's nodes, the checker's and the host's records, the
    # figures', keyframes' and REACH options' classes) is assembled from lang/_node_methods.py: none
    # pays for @dataclass's inspection of its fields or for compiling its methods (lang/node_methods.py).
    probe = _PROBE.replace(
        '"modules": sorted(sys.modules)',
        '"modules": sorted(sys.modules), "made": [f"{c.__module__}.{c.__qualname__}" for c in N.MADE], '
        '"written": [f"{c.__module__}.{c.__qualname__}" for c in N.WRITTEN]',
    ).replace(
        "from liganimate.cli import main",
        "from liganimate.cli import main\nfrom liganimate.lang import node_methods as N",
    )
    r = subprocess.run(
        [sys.executable, "-c", probe, APPENDIX_A], cwd=ROOT_DIR, capture_output=True, text=True, check=False
    )
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout.strip().splitlines()[-1])
    made = report["made"]
    assert len(made) > 80 and "liganimate.runtime.figure.tree.Figure" in made and "liganimate.lang.ast.Program" in made
    assert sorted(set(made) - set(report["written"])) == []


def test_check_imports_no_renderer_solver_or_exchange_module():
    modules = _modules_after_check()
    # The probe is real: check did load the compiler and ran the program in the host.
    assert {"liganimate.compiler.check", "liganimate.runtime.host", "liganimate.lang.parser"} <= set(modules)
    stray = [m for m in modules if m.startswith(FORBIDDEN) and m not in ALLOWED]
    assert stray == [], f"check imported {stray}: import them where they are used"
