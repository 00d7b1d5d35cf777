"""``liganimate view`` and ``liganimate studio``: scenes in the browser, and posing by eye.

:func:`add_commands` registers both subcommands on the main command's
subparsers.  Errors are diagnostics as everywhere in liganimate (exit 1, no
traceback), and ``view`` writes its page only when the program has run
cleanly, atomically.
"""

from __future__ import annotations

import argparse
import os
import sys


def _whole(text: str, low: int, high: int, message: str) -> int:
    # One rule for every whole-number option: digits only, within its range,
    # and the option's own sentence when not.
    try:
        value = int(text)
    except ValueError:
        value = low - 1
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(message.format(text=repr(text)))
    return value


def _seed(text: str) -> int:
    return _whole(text, 0, 2**32 - 1, "the seed must be a whole number from 0 to 4294967295, not {text}")


def _port(text: str) -> int:
    return _whole(text, 0, 65535, "{text} is not a port number (0 picks a free one)")


def _frames(text: str) -> int:
    return _whole(text, 1, 1_000_000, "the frames between kept poses must be 1 to 1000000, not {text}")


def add_commands(subparsers) -> None:
    """Add ``view`` and ``studio`` to the ``liganimate`` command's subparsers."""
    from liganimate.cli import lig_name

    p = subparsers.add_parser(
        "view",
        help="write a program's scenes as one HTML page with a 3D viewer",
        description="Run the program once without drawing and write a self-contained "
        "HTML page that shows its scenes in 3D (see docs/viewer.md).",
    )
    p.add_argument("file", help="the LIG program whose scenes to show")
    p.add_argument("-o", "--output", metavar="OUT.html", help="default: <stem>.html in the current folder")
    p.add_argument("--quiet", action="store_true", help="do not say what was written")
    p.add_argument(
        "--watch",
        action="store_true",
        help="serve the page on 127.0.0.1 instead, and reload it within a second of each save, keeping the view",
    )
    p.add_argument("--port", type=_port, default=0, help="with --watch, the port (default: a free one, printed)")
    p.add_argument("--no-browser", action="store_true", help="with --watch, do not open a browser")
    p.set_defaults(func=cmd_view)
    p = subparsers.add_parser(
        "studio",
        help="pose a model by eye with the posing thesis' Generator, in the browser",
        description="Start a local server (127.0.0.1 only) with the Generator of the thesis on "
        "posing figures with interactive genetic algorithms (see docs/viewer.md).",
    )
    p.add_argument("file", nargs="?", help="a program whose model to pose (default: the standard library)")
    p.add_argument("--model", type=lig_name, help="the MODEL to pose (default HUMANOID, or the file's only model)")
    p.add_argument("--save", metavar="LIB.lig", help="the library Save writes (default: <model>_poses.lig)")
    p.add_argument("--motion", type=lig_name, default="POSES", help="the saved MOTION's name (default POSES)")
    p.add_argument(
        "--frames",
        type=_frames,
        default=24,
        metavar="N",
        help="frames between kept poses in the saved motion (default 24)",
    )
    p.add_argument("--seed", type=_seed, help="the Generator's seed (default: a random one, shown)")
    p.add_argument("--port", type=_port, default=0, help="the port (default: a free one, printed)")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser; just print the address")
    p.add_argument("--verbose", action="store_true", help="log every request")
    p.set_defaults(func=cmd_studio)


def _page(path: str) -> str:
    """The viewer page of the program at ``path`` (an exception when it is wrong or shoots no scene)."""
    from liganimate.cli import shot_scenes
    from liganimate.runtime.view import viewer_html

    return viewer_html(shot_scenes(path, "view"), os.path.basename(path))


def cmd_view(args) -> int:
    """``liganimate view FILE [-o OUT.html]``, or ``--watch``: served and reloaded on each save."""
    from liganimate.cli import guarded, shot_scenes

    if args.watch:
        return guarded(lambda: _watch(args))

    def go():
        from liganimate.runtime import exchange as X
        from liganimate.runtime.view import viewer_html

        out = args.output or os.path.splitext(os.path.basename(args.file))[0] + ".html"
        scenes = shot_scenes(args.file, "view")
        page = viewer_html(scenes, os.path.basename(args.file)).encode("utf-8")
        X.write_files([(out, page)])
        if not args.quiet:
            size = f"{len(page) / 1e6:.1f} MB" if len(page) >= 1e5 else f"{len(page) / 1e3:.0f} kB"
            sys.stderr.write(f"wrote {out} ({size}, {len(scenes)} scene(s))\n")
        return 0

    return guarded(go)


def _watch(args) -> int:
    """Serve the program's page until Ctrl-C (see liganimate.watch)."""
    import webbrowser

    from liganimate import watch

    if not os.path.isfile(args.file):
        raise FileNotFoundError(2, "no such file", args.file)

    def ready(url, program) -> None:
        print(f"liganimate view: watching {args.file}", flush=True)
        print(f"  open {url}  (127.0.0.1 only; Ctrl-C stops the server)", flush=True)
        if program.error:
            print(program.error, file=sys.stderr, flush=True)
        if not args.no_browser:
            webbrowser.open(url)

    try:
        watch.serve(args.file, _page, port=args.port, ready=ready)
    except KeyboardInterrupt:
        print("\nliganimate view: stopped", flush=True)
    return 0


def cmd_studio(args) -> int:
    """``liganimate studio [FILE] [--model NAME] ...``: serve until Ctrl-C."""
    from liganimate.cli import guarded

    def go():
        import secrets
        import webbrowser

        from liganimate.runtime.errors import LigError
        from liganimate.runtime.studio import (
            Session,
            StudioLimits,
            StudioServer,
            serve,
            studio_model,
            studio_page,
        )

        fig, model, source = studio_model(args.file, args.model)
        if args.motion == model:
            raise LigError(
                f"the model and the motion cannot both be called {model}.", "give the motion another name with --motion"
            )
        save = os.path.abspath(args.save or f"{model.lower()}_poses.lig")
        if not save.lower().endswith(".lig"):
            raise LigError(
                f"{args.save} does not end in .lig, so LOAD would not take it.", "name the library file something.lig"
            )
        if not os.path.isdir(os.path.dirname(save)):
            raise LigError(f"there is no folder {os.path.dirname(save)} to save {os.path.basename(save)} in.")
        limits = StudioLimits.from_environment()  # before anything starts: a bad variable is one line
        seed = args.seed if args.seed is not None else secrets.randbelow(2**32)
        session = Session(fig, model, args.motion, save, seed=seed, spacing=args.frames)
        server = StudioServer(
            session, studio_page(session.generator, model), port=args.port, quiet=not args.verbose, limits=limits
        )
        print(f"liganimate studio: posing {model} from {source}, seed {seed}", flush=True)
        print(f"  open {server.url}  (127.0.0.1 only; Ctrl-C stops the server)", flush=True)
        print(f"  Save writes {save}", flush=True)
        if not args.no_browser:
            webbrowser.open(server.url)
        try:
            serve(server)
        except KeyboardInterrupt:
            print("\nliganimate studio: stopped", flush=True)
        return 0

    return guarded(go)
