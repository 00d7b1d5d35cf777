"""The Python API: ``liganimate.load("scene.lig")``, then ``.render()``, ``.export()``, ``.view()``.

:func:`load` compiles a program file and :func:`loads` a program's text, the
way ``liganimate run`` does; the :class:`LoadedProgram` they return checks
the program (:meth:`~LoadedProgram.check`), draws its scenes to files with
the command line's options (:meth:`~LoadedProgram.render`, through one
:class:`RenderOptions`), writes them in an exchange format
(:meth:`~LoadedProgram.export`, through the same table as ``liganimate
export``), and shows them in the browser viewer (:meth:`~LoadedProgram.view`).
In Jupyter, a loaded program, or the :class:`View` of one of its scenes,
displays as the viewer itself (``_repr_html_``), in a sandboxed frame.

Everything wrong with a program or an option raises one exception type,
:class:`LigProgramError`.  Loading leaves the calling process as it was:
the garbage collector is paused while a program compiles and restored
after (only the command line also freezes what survives).
"""

from __future__ import annotations

import contextlib
import os
import warnings as _warnings
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics, format_diagnostic
from liganimate.runtime.errors import LigError

if TYPE_CHECKING:
    from liganimate.runtime.exchange import ModelTake, SceneTake
    from liganimate.runtime.host import Program
    from liganimate.runtime.render.options import RenderOptions

__all__ = ["LigProgramError", "LoadedProgram", "ModelTake", "RenderOptions", "SceneTake", "View", "load", "loads"]


class LigProgramError(LigDiagnostics, ValueError):
    """What the API raises for a program that does not compile or run, or an option it cannot honour.

    ``str()`` is what the command line prints: the diagnostics
    (``file:line:col``, the line, a caret, a sentence, a hint), or the one
    sentence and its hint when the problem has no place in the program (a
    frame rate out of range, an output file in a missing folder).

    Attributes
    ----------
    diagnostics : list of Diagnostic
        The program's errors, each at its place; empty for an option's.
    message : str
        The first (or only) sentence.
    hint : str or None
        How to fix it, when there is one sentence and no diagnostics.
    """

    def __init__(self, diagnostics: list[Diagnostic], message: str | None = None, hint: str | None = None) -> None:
        super().__init__(diagnostics)
        self.message = message if message is not None else "; ".join(d.message for d in diagnostics)
        self.hint = hint

    def __str__(self) -> str:
        if self.diagnostics:
            return "\n".join(format_diagnostic(d) for d in self.diagnostics)
        return self.message + (f"\n  hint: {self.hint}" if self.hint else "")


@contextlib.contextmanager
def _program_errors() -> Iterator[None]:
    """Turn the compiler's and the runtime's exceptions into :class:`LigProgramError`."""
    try:
        yield
    except LigProgramError:
        raise
    except LigDiagnostics as exc:
        raise LigProgramError(exc.diagnostics) from None
    except LigError as exc:
        raise LigProgramError([], exc.message, exc.hint) from None


class View:
    """The viewer page for some scenes of a program.

    Attributes
    ----------
    html : str
        The complete, self-contained HTML document (what ``liganimate view`` writes).
    height : int
        The height in pixels of the notebook's frame.
    """

    def __init__(self, html: str, height: int = 560) -> None:
        self.html = html
        self.height = height

    def save(self, path: str | os.PathLike[str]) -> str:
        """Write the page to ``path`` atomically; return the path."""
        from liganimate.runtime.exchange import write_files

        write_files([(os.fspath(path), self.html.encode("utf-8"))])
        return os.fspath(path)

    def _repr_html_(self) -> str:
        from liganimate.runtime.view import iframe

        frame: str = iframe(self.html, self.height)
        return frame


class LoadedProgram:
    """A compiled LIG ANIMATE program.

    Attributes
    ----------
    name : str
        The file name, or the name given to :func:`loads` (``"<text>"``).
    program : liganimate.runtime.host.Program
        The compiled program, as the command line runs it.
    warnings : list of Diagnostic
        The compiler's warnings.
    """

    def __init__(self, name: str, program: Program, warnings: list[Diagnostic]) -> None:
        self.name = name
        self.program = program
        self.warnings = warnings
        self._scenes: list[SceneTake] | None = None

    def scenes(self) -> list[SceneTake]:
        """Run the program once without drawing; its shot scenes, cached.

        Returns
        -------
        list of SceneTake
            One per shot scene: its identifier, camera and the models it
            draws (:class:`ModelTake`: the joint angles and placements at
            each tick, as ``--poses`` records them).

        Raises
        ------
        LigProgramError
            When the program fails while it runs.
        """
        if self._scenes is None:
            from liganimate.runtime.exchange import collect

            with _program_errors():
                self._scenes = collect(self.program)
        return self._scenes

    def _shot(self, doing: str) -> list[SceneTake]:
        takes = self.scenes()
        if not takes:
            raise LigProgramError(
                [],
                f"the program shoots no scene, so there is nothing to {doing}",
                "define a scene with INITIALIZE SCENE ... ENDSCENE and SHOOTSCENES",
            )
        return takes

    def check(self) -> list[Diagnostic]:
        """Run every statement and every scene tick without drawing, as ``liganimate check`` does.

        Returns
        -------
        list of Diagnostic
            The warnings of the run (the compiler's are in :attr:`warnings`).

        Raises
        ------
        LigProgramError
            When the program fails while it runs.
        """
        with _program_errors():
            return list(self.program.check())

    def render(
        self, out: str | os.PathLike[str] | None = None, *, options: RenderOptions | None = None, **fields: Any
    ) -> None:
        """Check the program, then draw its scenes to files, as ``liganimate run`` does.

        Parameters
        ----------
        out : str or os.PathLike, optional
            The folder for the PNG frames (``out/scene<ID>/<NNNNN>.png``);
            None writes only the movies asked for.
        options : RenderOptions, optional
            What to write and how, as one value; ``out`` and ``fields`` replace its values.
        **fields
            Fields of :class:`liganimate.RenderOptions`, as the command
            line's options: ``size=(640, 480)``, ``gif=``, ``mp4=``,
            ``poses=``, ``fps=``, ``aa=``, ``look=`` (``"modern"``, the
            default, or ``"thesis"``), ``crf=``, ``preset=``,
            ``workers=``, ``scheduler=``, ``quiet=``, ``progress=``.

        Raises
        ------
        LigProgramError
            When the program fails while it runs, or an option cannot be
            honoured (nothing is written then), or nothing would be written.
        TypeError
            When a keyword is not a field of :class:`RenderOptions`.
        """
        if out is not None:
            fields["out"] = os.fspath(out)
        with _program_errors():
            self.program.render(options=options, **fields)

    def export(self, path: str | os.PathLike[str], **options: Any) -> list[str]:
        """Write the scenes' models and motion in the format ``path``'s extension chooses.

        The formats and their options are those of ``liganimate export``
        (``liganimate.runtime.exchange.EXPORT_FORMATS``): ``.glb`` and
        ``.gltf`` (glTF 2.0; options ``fps``, ``size``) and ``.bvh`` (one
        file per drawn model; option ``fps``).  Files are written all or
        none; a format's warnings are issued as :class:`UserWarning`.

        Parameters
        ----------
        path : str or os.PathLike
            The file to write (BVH writes several beside it when the scenes
            draw several models).
        **options
            The format's options, for example ``fps=30``, ``size=(1280, 720)``.

        Returns
        -------
        list of str
            The paths written.

        Raises
        ------
        LigProgramError
            When the program fails while it runs or shoots no scene, the
            extension names no format, or an option does not apply to it or
            is out of range.
        """
        from liganimate.runtime.exchange import export_format, export_options, write_files

        with _program_errors():
            fmt = export_format(path)
            checked = export_options(fmt, options)
            written = fmt.write(self._shot("export"), os.fspath(path), **checked)
        for note in written.warnings:
            _warnings.warn(note, UserWarning, stacklevel=2)
        write_files(written.files, written.folders)
        return [p for p, _ in written.files]

    def view(self, scene: int | None = None, height: int = 560) -> View:
        """The viewer for every scene, or for the scene whose identifier is ``scene``.

        Raises
        ------
        LigProgramError
            When the program fails while it runs, shoots no scene, or none
            with that identifier.
        """
        from liganimate.runtime.view import viewer_html

        takes = self._shot("view")
        if scene is not None:
            takes = [t for t in takes if t.id == scene]
            if not takes:
                shot = ", ".join(str(t.id) for t in self.scenes())
                raise LigProgramError([], f"the program shoots no scene {scene!r} (it shoots: {shot})")
        title = os.path.basename(self.name) + ("" if scene is None else f", scene {scene}")
        return View(viewer_html(takes, title), height)

    def _repr_html_(self) -> str:
        return self.view()._repr_html_()

    def __repr__(self) -> str:
        return f"<liganimate program {self.name!r}>"


def load(path: str | os.PathLike[str]) -> LoadedProgram:
    """Compile the LIG ANIMATE program in a file.

    Parameters
    ----------
    path : str or os.PathLike
        The program's file; its relative LOADs start from its folder.

    Returns
    -------
    LoadedProgram

    Raises
    ------
    LigProgramError
        When the program does not compile (its ``str()`` is the diagnostics).
    OSError
        When the file cannot be read.
    TypeError
        When ``path`` is not a path (program text goes to :func:`loads`).
    """
    from liganimate.compiler import load_program

    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"load() takes a path, not {type(path).__name__}")
    name = os.fspath(path)
    if not isinstance(name, str) or "\n" in name:
        raise TypeError("load() takes a file's path; give a program's text to liganimate.loads()")
    with _program_errors():
        program, warnings = load_program(name)
    return LoadedProgram(name, program, warnings)


def loads(text: str, name: str = "<text>") -> LoadedProgram:
    """Compile a LIG ANIMATE program from its text.

    Parameters
    ----------
    text : str
        The program; its relative LOADs start from the current folder.
    name : str, optional
        What diagnostics call it (default ``"<text>"``).

    Returns
    -------
    LoadedProgram

    Raises
    ------
    LigProgramError
        When the program does not compile (its ``str()`` is the diagnostics).
    TypeError
        When ``text`` is not a string.
    """
    from liganimate.compiler import load_program

    if not isinstance(text, str):
        raise TypeError(f"loads() takes the program's text as a str, not {type(text).__name__}")
    with _program_errors():
        program, warnings = load_program(None, text=text, name=name)
    return LoadedProgram(name, program, warnings)


def __getattr__(name: str) -> Any:
    # The public value types, from the packages that own them, imported on first use.
    if name == "RenderOptions":
        from liganimate.runtime.render.options import RenderOptions

        return RenderOptions
    if name in ("SceneTake", "ModelTake"):
        from liganimate.runtime import exchange

        return getattr(exchange, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
