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

_EXPORT_KINDS = {".glb": "glb", ".gltf": "gltf", ".bvh": "bvh"}


def _fps(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of frames per second") from None
    if not (value > 0 and value < 1e6):
        raise argparse.ArgumentTypeError(f"the frame rate must be a positive number, not {text}")
    return value


def _degrees(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of degrees") from None
    if not (0 <= value < 180):
        raise argparse.ArgumentTypeError(f"the tolerance must be at least 0 and below 180 degrees, not {text}")
    return value


def add_commands(subparsers) -> None:
    """Add ``export`` and ``import`` to the ``liganimate`` command's subparsers."""
    from liganimate.cli import _lig_name, _size

    p = subparsers.add_parser(
        "export",
        help="write a program's scenes as glTF 2.0 (.glb, .gltf) or BVH (.bvh)",
        description="Write every model the program's scenes draw, with their motion, "
        "to glTF 2.0 or BVH (see docs/exchange.md).",
    )
    p.add_argument("file")
    p.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUT.glb|OUT.gltf|OUT.bvh",
        help="the file to write; its extension chooses the format",
    )
    p.add_argument("--fps", type=_fps, default=24.0, help="ticks per second of the time axis (default 24)")
    p.add_argument(
        "--size",
        type=_size,
        default=(640, 480),
        metavar="WxH",
        help="image size whose aspect ratio the glTF cameras take (default 640x480)",
    )
    p.add_argument(
        "--rig",
        choices=("skin", "nodes"),
        default="skin",
        help="glTF: a skeleton and one skinned mesh per model (skin, the default) or a tree of rigid "
        "segment nodes (nodes)",
    )
    p.add_argument("--quiet", action="store_true", help="do not list the files written")
    p.set_defaults(func=cmd_export)
    p = subparsers.add_parser(
        "import",
        help="turn a BVH capture into a LIG library (a MODEL and a MOTION)",
        description="Write a library file that LOAD takes, with the capture's skeleton as "
        "a MODEL and its frames as a MOTION (see docs/exchange.md).",
    )
    p.add_argument("file", metavar="FILE.bvh")
    p.add_argument("-o", "--output", metavar="OUT.lig", help="default: <stem>.lig beside the current folder")
    p.add_argument("--model", type=_lig_name, help="the MODEL's name (default: <STEM>_FIGURE)")
    p.add_argument("--motion", type=_lig_name, help="the MOTION's name (default: <STEM>)")
    p.add_argument(
        "--tolerance",
        type=_degrees,
        default=0.0,
        metavar="DEG",
        help="drop keyframes while every angle stays within DEG degrees (default 0: every frame)",
    )
    p.add_argument("--quiet", action="store_true", help="do not say what was written")
    p.set_defaults(func=cmd_import)


def cmd_export(args) -> int:
    """``liganimate export FILE -o OUT``."""
    from liganimate.cli import _guarded, _shot_scenes

    def go():
        from liganimate.runtime import exchange as X
        from liganimate.runtime.errors import LigError

        kind = _EXPORT_KINDS.get(os.path.splitext(args.output)[1].lower())
        if kind is None:
            raise LigError(
                f"cannot tell the format of {args.output} from its extension.",
                "write to a file ending in .glb, .gltf or .bvh",
            )
        scenes = _shot_scenes(args.file, "export")
        if kind == "bvh":
            files = X.bvh_files(scenes, args.output, args.fps)
        else:
            data, notes = X.gltf_bytes(scenes, kind == "glb", fps=args.fps, size=args.size, rig=args.rig)
            for note in notes:
                sys.stderr.write(f"liganimate: warning: {note}\n")
            files = [(args.output, data)]
        X.write_files(files)
        if not args.quiet:
            for path, _ in files:
                sys.stderr.write(f"wrote {path}\n")
        return 0

    return _guarded(go)


def cmd_import(args) -> int:
    """``liganimate import FILE.bvh -o OUT.lig``."""
    from liganimate.cli import _guarded

    def go():
        from liganimate.runtime import exchange as X

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
        text = X.lig_library(
            clip, model=model, motion=motion, source_name=os.path.basename(args.file), tolerance=args.tolerance
        )
        X.write_files([(out, text)])
        if not args.quiet:
            sys.stderr.write(
                f"wrote {out}: MODEL {model} and MOTION {motion} "
                f"({len(clip.names)} joints, {clip.data.shape[0]} frames)\n"
            )
        return 0

    return _guarded(go)
