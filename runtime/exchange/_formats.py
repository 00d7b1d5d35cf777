"""The export formats: one table that ``liganimate export`` and ``LoadedProgram.export`` both read.

A format is an :class:`ExportFormat`: its name, the file suffixes that
choose it, one line for the documentation, the names of the options it
takes, and a writer.  Every writer has the same shape::

    write(scenes, path, *, <its options>) -> Export

and returns the files to write (``(path, bytes)`` pairs: one format may
write several) and the warnings to show; nothing is written by the writer
itself, so that :func:`write_files` can write all of them or none.

An option is an :class:`ExportOption`, shared by name among the formats
that take it (``fps`` by glTF and BVH alike): its default, one ``convert``
that accepts the command line's text or a Python value and returns the
checked value (or raises ``ValueError`` with one plain sentence), and its
help.  The command line turns each into ``--<name>`` once; a format that
does not take an option refuses it.

Adding a format: its writer (a module of this package) and one
``ExportFormat`` in :data:`EXPORT_FORMATS`; a new option: one
``ExportOption`` in :data:`EXPORT_OPTIONS` (docs/architecture.md).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from liganimate.runtime.errors import LigError

if TYPE_CHECKING:
    from ._collect import SceneTake

__all__ = [
    "EXPORT_FORMATS",
    "EXPORT_OPTIONS",
    "Export",
    "ExportFormat",
    "ExportOption",
    "export_format",
    "export_scenes",
    "export_options",
]


@dataclass(frozen=True)
class Export:
    """What a writer returns: the files to write, all or none, and warnings for the user.

    Attributes
    ----------
    files : tuple of (str, bytes)
        Destination paths and their contents.
    warnings : tuple of str
        Plain sentences (what the format cannot express, for example).
    folders : tuple of str
        Folders the files go into that are made if missing (URDF's meshes).
    """

    files: tuple[tuple[str, bytes], ...]
    warnings: tuple[str, ...] = ()
    folders: tuple[str, ...] = ()  # made (if missing) before the files are written


@dataclass(frozen=True)
class ExportOption:
    """An option of one or more export formats.

    Attributes
    ----------
    name : str
        The Python keyword; the command line's flag is ``--<name>`` with ``_`` as ``-``.
    default : object
        The value when the option is not given.
    convert : callable
        Text (from the command line) or a Python value -> the checked value;
        raises ``ValueError`` with one plain sentence when it is not acceptable.
    help : str
        One line for ``--help`` and the API reference.
    metavar : str, optional
        The placeholder ``--help`` shows.
    """

    name: str
    default: Any
    convert: Callable[[Any], Any]
    help: str
    metavar: str | None = None

    @property
    def flag(self) -> str:
        """The command line's spelling, ``--<name>``."""
        return "--" + self.name.replace("_", "-")


@dataclass(frozen=True)
class ExportFormat:
    """One export format.

    Attributes
    ----------
    name : str
        Its short name (``glb``).
    suffixes : tuple of str
        The lower-case file suffixes that choose it (``(".glb",)``).
    summary : str
        One line for the documentation and ``--help``.
    options : tuple of str
        The names of the :data:`EXPORT_OPTIONS` its writer takes, as keywords.
    write : callable
        ``write(scenes, path, **options) -> Export``.
    """

    name: str
    suffixes: tuple[str, ...]
    summary: str
    options: tuple[str, ...]
    write: Callable[..., Export] = field(repr=False)


def _fps(value: Any) -> float:
    try:
        fps = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{value!r} is not a number of frames per second") from None
    if not (0 < fps < 1e6):
        raise ValueError(f"the frame rate must be a positive number, not {value}")
    return fps


def _size(value: Any) -> tuple[int, int]:
    try:
        if isinstance(value, str):
            width, height = value.lower().split("x")
            w, h = int(width), int(height)
        else:
            w, h = (int(v) for v in value)
            if (w, h) != tuple(value):
                raise ValueError
    except (TypeError, ValueError):
        raise ValueError(f"{value!r} is not a size like 640x480") from None
    if not (0 < w <= 16384 and 0 < h <= 16384):
        raise ValueError(f"{value!r} is out of range: width and height are 1 to 16384 pixels each")
    return w, h


def _rig(value: Any) -> str:
    # The names are repeated from _gltf.RIGS, which this light module cannot import.
    rig = str(value).lower() if isinstance(value, str) else value
    if rig not in ("skin", "nodes"):
        raise ValueError(f"{value!r} is not a glTF rig; the rigs are skin and nodes")
    return rig


#: The options of the export formats, by name.
EXPORT_OPTIONS: dict[str, ExportOption] = {
    o.name: o
    for o in (
        ExportOption("fps", 24.0, _fps, "ticks per second of the time axis (default 24)", "N"),
        ExportOption(
            "size", (640, 480), _size, "image size whose aspect ratio the glTF cameras take (default 640x480)", "WxH"
        ),
        ExportOption(
            "rig",
            "skin",
            _rig,
            "skin: per model a skeleton and one skinned mesh (default); nodes: a tree of rigid segment nodes",
            "skin|nodes",
        ),
    )
}


# The writers import their modules when called: this table is read to build
# the command line, which must not load numpy or pygltflib for --help.


def _write_glb(scenes: Sequence[SceneTake], path: str, *, fps: float, size: tuple[int, int], rig: str) -> Export:
    from ._gltf import gltf_bytes

    data, warnings = gltf_bytes(scenes, True, fps=fps, size=size, rig=rig)
    return Export(((path, data),), tuple(warnings))


def _write_gltf(scenes: Sequence[SceneTake], path: str, *, fps: float, size: tuple[int, int], rig: str) -> Export:
    from ._gltf import gltf_bytes

    data, warnings = gltf_bytes(scenes, False, fps=fps, size=size, rig=rig)
    return Export(((path, data),), tuple(warnings))


def _write_bvh(scenes: Sequence[SceneTake], path: str, *, fps: float) -> Export:
    from ._bvh_write import bvh_files, bvh_notes

    return Export(tuple(bvh_files(scenes, path, fps)), bvh_notes(scenes))


def _write_urdf(scenes: Sequence[SceneTake], path: str) -> Export:
    from ._urdf_write import urdf_files

    files, warnings = urdf_files(scenes, path)
    folders = tuple(sorted({os.path.dirname(p) for p, _ in files if p.endswith(".stl")}))
    return Export(tuple(files), tuple(warnings), folders)


def _write_csv(scenes: Sequence[SceneTake], path: str, *, fps: float) -> Export:
    from ._trajectory import trajectory_csv_files

    return Export(tuple(trajectory_csv_files(scenes, path, fps)))


def _write_json(scenes: Sequence[SceneTake], path: str, *, fps: float) -> Export:
    from ._trajectory import trajectory_json

    return Export(((path, trajectory_json(scenes, fps)),))


#: Every export format, in the order the documentation lists them.
EXPORT_FORMATS: tuple[ExportFormat, ...] = (
    ExportFormat(
        "glb",
        (".glb",),
        "glTF 2.0, binary: every drawn model, one animation per scene",
        ("fps", "size", "rig"),
        _write_glb,
    ),
    ExportFormat(
        "gltf",
        (".gltf",),
        "glTF 2.0, JSON with the buffer embedded: the same as .glb",
        ("fps", "size", "rig"),
        _write_gltf,
    ),
    ExportFormat("bvh", (".bvh",), "BVH (Biovision hierarchy): one file per drawn model", ("fps",), _write_bvh),
    ExportFormat(
        "urdf", (".urdf",), "URDF robot description: one file per drawn model, STL meshes beside it", (), _write_urdf
    ),
    ExportFormat(
        "csv",
        (".csv",),
        "joint-space trajectory (radians, metres, per second): one file per drawn model",
        ("fps",),
        _write_csv,
    ),
    ExportFormat(
        "json", (".json",), "joint-space trajectories of every drawn model in one file", ("fps",), _write_json
    ),
)


def _suffix_list() -> str:
    suffixes = [s for f in EXPORT_FORMATS for s in f.suffixes]
    return ", ".join(suffixes[:-1]) + " or " + suffixes[-1] if len(suffixes) > 1 else suffixes[0]


def export_format(path: str | os.PathLike[str]) -> ExportFormat:
    """The format a file's suffix chooses.

    Raises
    ------
    LigError
        When no format has that suffix.
    """
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    for f in EXPORT_FORMATS:
        if suffix in f.suffixes:
            return f
    raise LigError(
        f"cannot tell the format of {os.fspath(path)} from its extension.",
        f"write to a file ending in {_suffix_list()}",
    )


def export_options(fmt: ExportFormat, given: Mapping[str, Any]) -> dict[str, Any]:
    """The checked keyword arguments of ``fmt``'s writer: ``given`` converted, the rest defaults.

    Parameters
    ----------
    fmt : ExportFormat
    given : mapping
        Option name -> value (text or a Python value); ``None`` means not given.

    Raises
    ------
    LigError
        When an option is unknown, does not apply to the format, or has a bad value.
    """
    given = {k: v for k, v in given.items() if v is not None}
    for name in given:
        if name not in EXPORT_OPTIONS:
            known = ", ".join(sorted(EXPORT_OPTIONS))
            raise LigError(f"there is no export option {name!r}.", f"the options are {known}")
        if name not in fmt.options:
            takes = ", ".join(EXPORT_OPTIONS[n].flag for n in fmt.options) or "no options"
            raise LigError(
                f"{EXPORT_OPTIONS[name].flag} does not apply to {fmt.name} files.",
                f"{fmt.name} takes {takes}",
            )
    out = {}
    for name in fmt.options:
        option = EXPORT_OPTIONS[name]
        if name not in given:
            out[name] = option.default
            continue
        try:
            out[name] = option.convert(given[name])
        except ValueError as exc:
            raise LigError(f"{option.flag}: {exc}.") from None
    return out


def export_scenes(scenes: Sequence[SceneTake], path: str | os.PathLike[str], **options: Any) -> Export:
    """The files of ``scenes`` in the format ``path``'s suffix chooses (nothing written yet).

    Parameters
    ----------
    scenes : list of SceneTake
        What :func:`collect` returned.
    path : str or os.PathLike
        Where the (first) file goes.
    **options
        The format's options (:data:`EXPORT_OPTIONS`), as text or values.

    Raises
    ------
    LigError
        When the suffix names no format, an option does not apply or is bad,
        or the scenes cannot be written in the format.
    """
    fmt = export_format(path)
    return fmt.write(scenes, os.fspath(path), **export_options(fmt, options))
