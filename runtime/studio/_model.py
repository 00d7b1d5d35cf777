"""Which model the studio poses: a MODEL of a program file, or of the standard library.

``liganimate studio`` with no file poses the library HUMANOID;
``--model NAME`` alone looks the name up in every standard library;
``studio file.lig [--model NAME]`` runs the file once (as ``liganimate
check`` does, nothing drawn) and takes the model variable's final value.
"""

from __future__ import annotations

import io

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure.tree import Figure

__all__ = ["studio_model"]

DEFAULT_MODEL = "HUMANOID"


def _run(program) -> dict:
    return program.execute("check", stdout=io.StringIO()).variables


def _compiled_text(text: str, name: str):
    from liganimate.compiler import load_program

    return load_program(text=text, name=name)[0]


def _stdlib_offering(name: str):
    from liganimate.compiler import library as L
    from liganimate.compiler import types as T

    for lib_name in L.stdlib_names():
        lib = L.load(lib_name, L.resolve(lib_name, "-"))
        if lib.types.get(name) == T.MODEL:
            return lib_name
    return None


def studio_model(path: str | None, name: str | None):
    """The figure to pose, its name and where it comes from.

    Parameters
    ----------
    path : str or None
        A LIG program file, or None for the standard library.
    name : str or None
        The MODEL variable; default HUMANOID for the standard library, and
        the program's only model for a file.

    Returns
    -------
    (Figure, str, str)
        The model, its name in capitals, and a description of its source.

    Raises
    ------
    LigDiagnostics
        When the file does not compile or run.
    LigError
        When there is no such model, or the choice is ambiguous.
    """
    from liganimate.lang.diagnostics import did_you_mean

    wanted = name.upper() if name else None
    if path is None:
        wanted = wanted or DEFAULT_MODEL
        lib = _stdlib_offering(wanted)
        if lib is None:
            from liganimate.compiler import library as L

            raise LigError(
                f"no standard library offers a model called {wanted}",
                "the standard libraries are " + ", ".join(L.stdlib_names()) + "; `liganimate lib` lists their models",
            )
        variables = _run(_compiled_text(f"LOAD {wanted} FROM '{lib}'\n", f"<studio {lib}>"))
        source = f"the standard library '{lib}'"
    else:
        from liganimate.compiler import load_program

        program, _ = load_program(path)
        variables = _run(program)
        source = path
    models = sorted(k for k, v in variables.items() if isinstance(v, Figure))
    if wanted is None:
        if len(models) != 1:
            raise LigError(
                f"{path} has {'no models' if not models else 'several models: ' + ', '.join(models)}, "
                "so say which one to pose",
                "pass --model NAME" if models else "define a MODEL with STARTMODEL or JOINT",
            )
        wanted = models[0]
    fig = variables.get(wanted)
    if not isinstance(fig, Figure):
        hint = did_you_mean(wanted, models) or ("its models are " + ", ".join(models) if models else None)
        raise LigError(f"{source} has no model called {wanted}", hint)
    if fig.n_joints == 0:
        raise LigError(
            f"the model {wanted} has no joints, so there is nothing to pose",
            "pose a model made with JOINT or STARTMODEL",
        )
    return fig, wanted, source
