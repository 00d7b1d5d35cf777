"""``liganimate export`` and ``liganimate import``: glTF 2.0 and BVH out, BVH in.

:func:`add_commands` registers both subcommands on the main command's
subparsers.  Errors are diagnostics as everywhere in liganimate (exit 1, no
traceback), and nothing is written unless every output file is complete.
"""

from __future__ import annotations

import argparse
import os
import re
import sys


def _option_type(option):
    """An argparse ``type`` for an export option: its ``convert``, errors as usage errors."""

    def convert(text: str):
        try:
            return option.convert(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    convert.__name__ = option.name  # argparse names the option's type in some messages
    return convert


def _degrees(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of degrees") from None
    if not (0 <= value < 180):
        raise argparse.ArgumentTypeError(f"the tolerance must be at least 0 and below 180 degrees, not {text}")
    return value


def _rate(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of frames per second") from None
    if not (0 < value < 1e6):
        raise argparse.ArgumentTypeError(f"the frame rate must be a positive number, not {text}")
    return value


def _frame_range(text: str) -> tuple:
    first, sep, last = text.partition(":")
    try:
        a = int(first) if first.strip() else 0
        b = int(last) if last.strip() else None
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a range of frames such as 100:399") from None
    if not sep or a < 0 or (b is not None and b < a):
        raise argparse.ArgumentTypeError(f"{text!r} is not a range of frames A:B with 0 <= A <= B")
    return a, b


def add_commands(subparsers) -> None:
    """Add ``export`` and ``import`` to the ``liganimate`` command's subparsers."""
    from liganimate.cli import lig_name
    from liganimate.runtime import exchange as X

    formats = X.EXPORT_FORMATS
    suffixes = "|".join("OUT" + s for f in formats for s in f.suffixes)
    p = subparsers.add_parser(
        "export",
        help="write a program's scenes as " + ", ".join(f"{f.name} ({'/'.join(f.suffixes)})" for f in formats),
        description="Write every model the program's scenes draw, with their motion, in the format "
        "the output's extension chooses (see docs/exchange.md): "
        + "; ".join(f"{'/'.join(f.suffixes)}: {f.summary}" for f in formats)
        + ".",
    )
    p.add_argument("file", help="the LIG program whose scenes to export")
    p.add_argument(
        "-o",
        "--output",
        required=True,
        metavar=suffixes,
        help="the file to write; its extension chooses the format",
    )
    for option in X.EXPORT_OPTIONS.values():
        users = ", ".join(f.name for f in formats if option.name in f.options)
        p.add_argument(
            option.flag,
            dest="export_" + option.name,
            type=_option_type(option),
            default=None,
            metavar=option.metavar,
            help=f"{option.help}; for {users}",
        )
    p.add_argument("--quiet", action="store_true", help="do not list the files written")
    p.set_defaults(func=cmd_export)
    p = subparsers.add_parser(
        "import",
        help="turn a BVH capture (a MODEL and a MOTION) or a URDF robot (a MODEL) into a LIG library",
        description="Write a library file that LOAD takes: from a BVH file, the capture's skeleton as "
        "a MODEL and its frames as a MOTION; from a URDF file, the robot as a MODEL (see docs/exchange.md).",
    )
    p.add_argument("file", metavar="FILE.bvh|FILE.urdf", help="the BVH capture or URDF robot to read")
    p.add_argument("-o", "--output", metavar="OUT.lig", help="default: <stem>.lig beside the current folder")
    p.add_argument("--model", type=lig_name, help="the MODEL's name (default: <STEM>_FIGURE)")
    p.add_argument("--motion", type=lig_name, help="the MOTION's name (default: <STEM>)")
    p.add_argument(
        "--tolerance",
        type=_degrees,
        default=0.0,
        metavar="DEG",
        help="drop keyframes while every angle stays within DEG degrees (default 0: every frame)",
    )
    p.add_argument(
        "--joint-translation",
        choices=("error", "drop"),
        default="error",
        help="joints other than the ROOT that slide: refuse the file (error, the default) or keep each "
        "at its first frame's offset (drop); position channels that hold still are always dropped, with a note",
    )
    p.add_argument("--frames", type=_frame_range, metavar="A:B", help="import frames A to B only (inclusive)")
    p.add_argument("--fps", type=_rate, metavar="N", help="resample the capture to N frames per second")
    p.add_argument(
        "--onto",
        metavar="LIBRARY",
        help="retarget the capture onto a figure of this library (a standard library's name, or FILE.lig); "
        "the output then holds only the MOTION",
    )
    p.add_argument("--onto-model", type=lig_name, metavar="NAME", help="the model of --onto's library")
    p.add_argument("--map", metavar="FILE", help="joint map for --onto: 'capture joint = figure link' lines")
    p.add_argument("--scale", type=_rate, metavar="R", help="with --onto: scale the capture's lengths by R")
    p.add_argument(
        "--mesh-triangles",
        type=_count,
        default=None,
        metavar="N",
        help="URDF: thin each mesh to at most N triangles (default 1500)",
    )
    p.add_argument("--quiet", action="store_true", help="do not say what was written")
    p.set_defaults(func=cmd_import)


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 4 <= value <= 100000:
        raise argparse.ArgumentTypeError("give 4 to 100000 triangles")
    return value


def _import_urdf(args) -> int:
    """``liganimate import FILE.urdf -o OUT.lig [--model NAME]``: the robot as a MODEL."""
    from liganimate.runtime import exchange as X
    from liganimate.runtime.errors import LigError

    for flag, value in (
        ("--motion", args.motion),
        ("--frames", args.frames),
        ("--fps", args.fps),
        ("--tolerance", args.tolerance or None),
        ("--joint-translation", None if args.joint_translation == "error" else args.joint_translation),
        ("--onto", args.onto),
        ("--map", args.map),
    ):
        if value is not None:
            raise LigError(f"{flag} applies to BVH captures; a URDF file holds a robot, not a motion.")
    stem = os.path.splitext(os.path.basename(args.file))[0]
    out = args.output or f"{stem}.lig"
    robot = X.read_urdf(args.file)
    model = args.model or X.robot_model_name(robot)
    options = X.UrdfImportOptions(
        model=model,
        source_name=os.path.basename(args.file),
        mesh_triangles=args.mesh_triangles or X.MESH_TRIANGLES,
    )
    text, notes = X.import_urdf(robot, options)
    X.write_files([(out, text)])
    for note in notes:
        sys.stderr.write(f"liganimate: note: {note}\n")
    if not args.quiet:
        sys.stderr.write(f"wrote {out}: MODEL {model} ({len(robot.links)} links, {len(robot.joints)} joints)\n")
    return 0


def cmd_export(args) -> int:
    """``liganimate export FILE -o OUT``."""
    from liganimate.cli import guarded, shot_scenes

    def go():
        from liganimate.runtime import exchange as X

        # The format and its options are checked before the program runs.
        fmt = X.export_format(args.output)
        options = X.export_options(fmt, {o: getattr(args, "export_" + o) for o in X.EXPORT_OPTIONS})
        scenes = shot_scenes(args.file, "export")
        export = fmt.write(scenes, args.output, **options)
        for note in export.warnings:
            sys.stderr.write(f"liganimate: warning: {note}\n")
        files = export.files
        X.write_files(files, export.folders)
        if not args.quiet:
            for path, _ in files:
                sys.stderr.write(f"wrote {path}\n")
        return 0

    return guarded(go)


def cmd_import(args) -> int:
    """``liganimate import FILE.bvh -o OUT.lig``."""
    from liganimate.cli import guarded

    def go():
        from liganimate.runtime import exchange as X

        if args.file.lower().endswith(".urdf"):
            return _import_urdf(args)
        if args.mesh_triangles is not None:
            from liganimate.runtime.errors import LigError

            raise LigError("--mesh-triangles applies to URDF robots, not BVH captures.")
        stem = os.path.splitext(os.path.basename(args.file))[0]
        base = re.sub(r"[^A-Za-z0-9_]", "_", stem).upper().strip("_") or "CAPTURE"
        if not base[0].isalpha():
            base = "C_" + base
        motion = args.motion or base
        model = args.model or f"{base}_FIGURE"
        if model == motion:
            from liganimate.runtime.errors import LigError

            raise LigError(
                f"the model and the motion cannot both be called {model}.",
                "give them different names with --model and --motion",
            )
        out = args.output or f"{stem}.lig"
        clip = X.read_bvh(args.file)
        if args.frames is not None:
            clip = X.cut_frames(clip, *args.frames)
        if args.fps is not None:
            clip = X.resample(clip, args.fps)
        if args.onto is not None:
            return _retarget(args, X, clip, out, base)
        if args.onto_model or args.map or args.scale:
            from liganimate.runtime.errors import LigError

            raise LigError("--onto-model, --map and --scale go with --onto.", "add --onto LIBRARY")
        options = X.ImportOptions(
            model=model,
            motion=motion,
            source_name=os.path.basename(args.file),
            tolerance=args.tolerance,
            joint_translation=args.joint_translation,
        )
        text, notes = X.import_library(clip, options)
        X.write_files([(out, text)])
        for note in notes:
            sys.stderr.write(f"liganimate: note: {note}\n")
        if not args.quiet:
            sys.stderr.write(
                f"wrote {out}: MODEL {model} and MOTION {motion} "
                f"({len(clip.names)} joints, {clip.data.shape[0]} frames)\n"
            )
        return 0

    return guarded(go)


def _retarget(args, X, clip, out: str, base: str) -> int:
    """``import --onto``: write the retargeted MOTION and print the report."""
    options = X.OntoOptions(
        library=args.onto,
        model=args.onto_model,
        map_file=args.map,
        motion=args.motion or base,
        source_name=os.path.basename(args.file),
        retarget=X.RetargetOptions(scale=args.scale, joint_translation=args.joint_translation),
        tolerance=args.tolerance,
    )
    text, report, _ = X.retarget_library(clip, options)
    X.write_files([(out, text)])
    if not args.quiet:
        for line in report:
            sys.stderr.write(line + "\n")
        sys.stderr.write(f"wrote {out}: MOTION {options.motion} ({clip.data.shape[0]} frames)\n")
    return 0
