"""The Python entry point: ``liganimate.load("scene.lig").view()``.

:func:`load` compiles a program (a file or its text) the way ``liganimate
run`` does; the :class:`LoadedProgram` it returns runs the scenes once
without drawing them and shows them in the browser viewer.  In Jupyter,
a loaded program, or the :class:`View` of one of its scenes, displays as
the viewer itself (``_repr_html_``), in a sandboxed frame.
"""

from __future__ import annotations

import os
import warnings
from typing import TYPE_CHECKING, Any, NoReturn

from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics, format_diagnostic

if TYPE_CHECKING:
    from liganimate.runtime.exchange import SceneTake
    from liganimate.runtime.host import Program
    from liganimate.runtime.render.options import RenderOptions

__all__ = ["LigProgramError", "LoadedProgram", "View", "load"]


class LigProgramError(LigDiagnostics):
    """A program that does not compile or run; ``str()`` is the diagnostics as the command line prints them."""

    def __str__(self) -> str:
        return "\n".join(format_diagnostic(d) for d in self.diagnostics)


def _reraise(exc: LigDiagnostics) -> NoReturn:
    raise LigProgramError(exc.diagnostics) from None


class View:
    """The viewer page for some scenes of a program.

    Attributes
    ----------
    html : str
        The complete, self-contained HTML document (what ``liganimate view`` writes).
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

        return iframe(self.html, self.height)


class LoadedProgram:
    """A compiled LIG ANIMATE program.

    Attributes
    ----------
    name : str
        The file name, or ``"<text>"``.
    program : liganimate.runtime.host.Program
        The compiled program (``check``, ``execute``, ``render``).
    warnings : list of Diagnostic
        The compiler's warnings.
    """

    def __init__(self, name: str, program: Program, warnings: list[Diagnostic]) -> None:
        self.name = name
        self.program = program
        self.warnings = warnings
        self._scenes: list[SceneTake] | None = None

    def scenes(self) -> list[SceneTake]:
        """Run the program once without drawing; its shot scenes (``SceneTake``), cached.

        Raises
        ------
        LigProgramError
            When the program fails while it runs.
        """
        if self._scenes is None:
            from liganimate.runtime.exchange import collect

            try:
                scenes = collect(self.program)
            except LigDiagnostics as exc:
                _reraise(exc)
            self._scenes = scenes
        return self._scenes

    def view(self, scene: int | None = None, height: int = 560) -> View:
        """The viewer for every scene, or for the scene whose identifier is ``scene``.

        Raises
        ------
        LigProgramError
            When the program fails while it runs.
        ValueError
            When the program shoots no scene, or none with that identifier.
        """
        from liganimate.runtime.view import viewer_html

        takes = self.scenes()
        if scene is not None:
            takes = [t for t in takes if t.id == scene]
            if not takes:
                shot = ", ".join(str(t.id) for t in self.scenes()) or "none"
                raise ValueError(f"the program shoots no scene {scene!r} (it shoots: {shot})")
        if not takes:
            raise ValueError("the program shoots no scene, so there is nothing to view")
        title = os.path.basename(self.name) + ("" if scene is None else f", scene {scene}")
        return View(viewer_html(takes, title), height)

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
        try:
            return list(self.program.check())
        except LigDiagnostics as exc:
            _reraise(exc)

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
            ``workers=``, ``scheduler=``, ``quiet=``.

        Raises
        ------
        LigProgramError
            When the program fails while it runs.
        ValueError
            When an option cannot be honoured (nothing is written then), or
            nothing would be written.
        TypeError
            When a keyword is not a field of ``RenderOptions``.
        """
        if out is not None:
            fields["out"] = os.fspath(out)
        try:
            self.program.render(options=options, **fields)
        except LigDiagnostics as exc:
            _reraise(exc)

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
            When the program fails while it runs.
        ValueError
            When the extension names no format, an option does not apply to
            it or is out of range, or the program shoots no scene.
        """
        from liganimate.runtime.exchange import export_format, export_options, write_files

        fmt = export_format(path)
        checked = export_options(fmt, options)
        takes = self.scenes()
        if not takes:
            raise ValueError("the program shoots no scene, so there is nothing to export")
        written = fmt.write(takes, os.fspath(path), **checked)
        for note in written.warnings:
            warnings.warn(note, UserWarning, stacklevel=2)
        write_files(written.files)
        return [p for p, _ in written.files]

    def _repr_html_(self) -> str:
        return self.view()._repr_html_()

    def __repr__(self) -> str:
        return f"<liganimate program {self.name!r}>"


def load(path_or_text: str | os.PathLike[str]) -> LoadedProgram:
    """Compile a LIG ANIMATE program from a file or from its text.

    Parameters
    ----------
    path_or_text : str or os.PathLike
        A path (a path object, a string naming an existing file, or a
        one-line string ending in ``.lig``), or otherwise the program text
        itself; a text's relative LOADs start from the current folder.

    Returns
    -------
    LoadedProgram

    Raises
    ------
    LigProgramError
        When the program does not compile (its ``str()`` is the diagnostics).
    OSError
        When the file cannot be read.
    """
    from liganimate.compiler import load_program

    path: str | None
    text: str | None
    if isinstance(path_or_text, os.PathLike):
        path, text = os.fspath(path_or_text), None
    elif not isinstance(path_or_text, str):
        raise TypeError(f"load() takes a path or the program's text, not {type(path_or_text).__name__}")
    elif "\n" not in path_or_text and (path_or_text.lower().endswith(".lig") or os.path.isfile(path_or_text)):
        path, text = path_or_text, None
    else:
        path, text = None, path_or_text
    try:
        program, warnings = load_program(path, text=text)
    except LigDiagnostics as exc:
        _reraise(exc)
    return LoadedProgram(path if path is not None else "<text>", program, warnings)
