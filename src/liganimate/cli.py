"""The ``liganimate`` command: run, check, compile and plot LIG ANIMATE programs.

Every user error is printed as a diagnostic (``file:line:col``, the line, a
caret, a sentence, a hint) and the command exits with status 1; no Python
traceback reaches the user, and nothing is written when a program is wrong.
Output options (``-o``, ``--gif``, ``--mp4``, ``--poses``, ``--fps``,
``--aa``, ``--look``, ``--crf``, ``--preset``, ``--scheduler``) are checked before the
program is compiled.  SIGINT and SIGTERM stop a command
cleanly (exit status 130 and 143), leaving only whole files.
"""

from __future__ import annotations

import argparse
import io
import os
import signal
import sys
import time

from liganimate import __version__
from liganimate.runtime import interrupts

EXIT_USER_ERROR = 1
EXIT_INTERNAL = 3


def _print_diagnostics(diags, stream=None) -> None:
    from liganimate.lang.diagnostics import format_diagnostic

    stream = stream or sys.stderr
    for d in diags:
        stream.write(format_diagnostic(d) + "\n")


def _size(text: str):
    from liganimate.runtime.render.options import MAX_SIDE  # only when --size is given

    try:
        width, height = text.lower().split("x")
        w, h = int(width), int(height)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a size like 640x480") from None
    if not (0 < w <= MAX_SIDE and 0 < h <= MAX_SIDE):
        raise argparse.ArgumentTypeError(f"{text!r} is out of range: width and height are 1 to {MAX_SIDE} pixels each")
    return w, h


def lig_name(text: str) -> str:
    """An option that names a MODEL or MOTION a tool writes: a name a program may define (compiler/names.py)."""
    from liganimate.compiler.names import definable

    if not definable(text):
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a LIG name a library can define (a letter, then letters, digits and _; not a keyword)"
        )
    return text.upper()


def shot_scenes(path: str, doing: str) -> list:
    """The scenes the program at ``path`` shoots, its warnings printed; an error when it shoots none.

    ``doing`` finishes the sentence "there is nothing to ..." (export, view).
    """
    from liganimate.compiler import load_program
    from liganimate.runtime import exchange as X
    from liganimate.runtime.errors import LigError

    program, warnings = load_program(path)
    _print_diagnostics(warnings)
    run_warnings: list = []
    scenes = X.collect(program, run_warnings)
    _print_diagnostics(run_warnings)
    if not scenes:
        raise LigError(NO_SCENE.format(doing=doing), NO_SCENE_HINT)
    return scenes


def _add_render_options(p: argparse.ArgumentParser) -> None:
    # Every command builds the whole parser: the movie table is read from its
    # own light module, not the renderer's options (which import the renderer).
    from liganimate.runtime.render.movies import MOVIES

    p.add_argument(
        "-o",
        "--out",
        metavar="DIR",
        help="folder for the PNG frames (default: <stem>_frames, or none when a movie is asked for)",
    )
    p.add_argument("--size", type=_size, default=(640, 480), metavar="WxH", help="image size (default 640x480)")
    for movie in MOVIES:
        p.add_argument("--" + movie.name, metavar="FILE", help=movie.help)
    p.add_argument(
        "--crf",
        default=None,
        metavar="N",
        help="MP4 quality, 0 (lossless) to 51 (default 20); lower is better and larger",
    )
    p.add_argument(
        "--preset",
        default=None,
        metavar="NAME",
        help="MP4 encoding speed, ultrafast to veryslow (default superfast); slower makes smaller files",
    )
    p.add_argument("--poses", metavar="FILE", help="write the pose record (JSON Lines, see docs/poses.md)")
    p.add_argument("--fps", default="24", help="frame rate of the GIF and MP4, 0.01 to 1000 (default 24)")
    p.add_argument(
        "--aa", default="1", metavar="N", help="anti-aliasing: draw N times finer and average, 1 to 8 (default 1, off)"
    )
    p.add_argument(
        "--look",
        default=None,
        metavar="NAME",
        help="modern (default: lit, outlined, shadowed, smooth edges) or thesis (flat shades on white, as in the thesis)",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        default=None,
        help="draw the frames on this Dask cluster (default: $LIGANIMATE_SCHEDULER, else this machine)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    _add_progress_option(p)


def _add_progress_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--progress",
        action="store_true",
        help="show progress on stderr even when it is not a terminal (a line a second)",
    )


def _usage_checked(args, parser: argparse.ArgumentParser) -> None:
    """Refuse option values that are wrong whatever the files say: exit status 2 and the usage line, as argparse does.

    ``--aa 9`` is as much a usage error as ``--size 640``; so is a movie
    file whose suffix is not its format's (``--gif out.png`` would be a GIF
    named .png). What depends on the files (a missing folder, an output
    another run is writing, no ffmpeg) stays an error of exit status 1.
    """
    from liganimate.lang.messages import sentence
    from liganimate.runtime.errors import RenderError
    from liganimate.runtime.render.options import MOVIES, check_aa
    from liganimate.runtime.render.outputs import check_fps
    from liganimate.runtime.render.video import check_crf, check_preset

    try:
        for movie in MOVIES:
            path = getattr(args, movie.name, None)
            if path is not None and not path.lower().endswith("." + movie.name):
                raise RenderError(
                    f"the file of --{movie.name} must end in .{movie.name} (it is a {movie.label}), not {path!r}"
                )
        check_fps(args.fps, "--fps")
        check_aa(args.aa, "--aa")
        if args.crf is not None:
            check_crf(args.crf, "--crf")
        if args.preset is not None:
            check_preset(args.preset, "--preset")
    except RenderError as exc:
        parser.error(sentence(exc.message))


def _render_options(args, stem: str):
    """The command line's RenderOptions, checked before compiling (nothing is written here).

    The folder and lock files are made when rendering starts; an output
    another run is writing is refused now too.
    """
    import dataclasses

    from liganimate.runtime.render.options import CLI_NAMES, MOVIES, RenderOptions, checked
    from liganimate.runtime.render.outputs import refuse_if_locked

    given = {f.name: getattr(args, f.name) for f in dataclasses.fields(RenderOptions) if hasattr(args, f.name)}
    given = {k: v for k, v in given.items() if v is not None}
    # A movie alone writes no PNG frames; -o adds them.
    if args.out is None and not any(getattr(args, m.name) for m in MOVIES):
        given["out"] = f"{stem}_frames"
    if args.scheduler is None:
        given["scheduler"] = os.environ.get("LIGANIMATE_SCHEDULER") or None
    options = checked(RenderOptions(**given), CLI_NAMES)
    refuse_if_locked(options.out, options.files())
    return options


class _CheckProgress:
    """``checking scene 1: 40,960/10,000,000 ticks`` once a check has run for a second.

    A check runs every tick of every scene; a scene of millions of ticks
    would otherwise keep the terminal silent for minutes. On a terminal the
    line is redrawn in place; asked for elsewhere (``--progress`` into a log),
    a line is written at most once a second.
    """

    def __init__(self, in_place: bool = True):
        self.start = time.monotonic()
        self.width = 0
        self.in_place = in_place
        self.last = 0.0

    def __call__(self, scene_id, tick, length) -> None:
        now = time.monotonic()
        if not self.width and now - self.start < 1.0:
            return
        line = f"checking scene {scene_id}: {tick:,}/{length:,} ticks"
        if not self.in_place:
            if now - self.last >= 1.0 or tick == length:
                self.last = now
                self.width = max(self.width, 1)
                sys.stderr.write(line + "\n")
                sys.stderr.flush()
            return
        self.width = max(self.width, len(line))
        sys.stderr.write("\r" + line.ljust(self.width))
        sys.stderr.flush()

    def done(self) -> None:
        """Clear the line, if one was shown in place."""
        if self.width and self.in_place:
            sys.stderr.write("\r" + " " * self.width + "\r")
            sys.stderr.flush()


def _progress_for(quiet: bool, asked: bool = False):
    """The check's progress line: on a terminal unless ``quiet``, or wherever stderr goes when ``asked``."""
    tty = sys.stderr.isatty()
    if asked or (tty and not quiet):
        return _CheckProgress(in_place=tty)
    return None


def _checked(program, quiet: bool, stdout=None, asked: bool = False, drawing: bool = False):
    """Run every check (``Program.check``) with a progress line on a terminal (or when ``asked``); returns the runtime.

    Its ``warnings`` are the run's warnings, its ``shot`` the number of
    scenes the program shot.
    """
    progress = _progress_for(quiet, asked)
    try:
        if stdout is None:
            # PRINT output is dropped: a run prints it once, when it renders.
            return program.execute("check", stdout=io.StringIO(), progress=progress, drawing=drawing)
        return program.execute("check", stdout=stdout, echo_print=True, progress=progress, drawing=drawing)
    finally:
        if progress is not None:
            progress.done()


#: A program that shoots no scene (a library, an empty file, SHOOTSCENES left out): ``run`` runs it
#: for its PRINTs, writes nothing (no empty folder, no movie), says so in a warning and exits 0.
NO_SCENE = "the program shoots no scene, so there is nothing to {doing}"
NO_SCENE_HINT = "define a scene with INITIALIZE SCENE ... ENDSCENE and SHOOTSCENES"


def _render(program, warnings, options) -> int:
    from liganimate.runtime.render.options import MOVIES

    _print_diagnostics(warnings)
    asked = options.progress  # --progress: a line a second wherever stderr goes
    checked = _checked(program, options.quiet, asked=asked, drawing=True)
    _print_diagnostics(checked.warnings)
    if not checked.shot:
        # Nothing to draw: no empty folder, no "frames written".
        program.execute("check", stdout=sys.stdout, echo_print=True)  # its PRINTs, once
        sys.stderr.write(f"liganimate: warning: {NO_SCENE.format(doing='render')}; nothing was written\n")
        sys.stderr.write(f"  hint: {NO_SCENE_HINT}\n")
        return 0
    program.render(checked=True, options=options)
    if not options.quiet:
        written = [f"frames written to {options.out}"] if options.out is not None else []
        written += [f"{m.label} written to {path}" for m in MOVIES if (path := getattr(options, m.name))]
        sys.stderr.write("; ".join(written) + "\n")
    return 0


def guarded(fn):
    """Run a command, turning diagnostics into exit status 1 and bugs into a short report.

    KeyboardInterrupt (and :class:`~liganimate.runtime.interrupts.Interrupted`)
    goes through, to :func:`_stopping`.
    """
    from liganimate.lang import collector

    # Importing makes classes and functions, no garbage: the collector would only walk them (lang/collector.py).
    with collector.paused():
        from liganimate.lang.diagnostics import LigDiagnostics
        from liganimate.lang.display import escape_text
        from liganimate.lang.messages import sentence
        from liganimate.runtime.errors import LigError
        from liganimate.runtime.files import os_error_words

    try:
        return fn()
    except LigDiagnostics as exc:
        _print_diagnostics(exc.diagnostics)
        return EXIT_USER_ERROR
    except LigError as exc:
        # Messages can quote program-derived text (names, paths): escaped like
        # every diagnostic, so no control sequence reaches the terminal.
        sys.stderr.write(f"liganimate: error: {escape_text(sentence(exc.message))}\n")
        if exc.hint:
            sys.stderr.write(f"  hint: {escape_text(sentence(exc.hint))}\n")
        return EXIT_USER_ERROR
    except BrokenPipeError:
        # The reader went away (liganimate lib | head): not an error of ours.
        # Point stdout at nothing so the interpreter's final flush stays quiet.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except OSError as exc:
        where = f": {escape_text(str(exc.filename))}" if exc.filename else ""
        sys.stderr.write(f"liganimate: error: {escape_text(os_error_words(exc))}{where}\n")
        return EXIT_USER_ERROR
    except RecursionError:
        sys.stderr.write("liganimate: error: the program is nested too deeply to compile\n")
        return EXIT_USER_ERROR
    except Exception as exc:  # noqa: BLE001 - the user must never see a traceback
        sys.stderr.write(
            f"liganimate: internal error: {type(exc).__name__}: {exc}\n"
            "  please report this with the program that caused it\n"
        )
        if os.environ.get("LIGANIMATE_DEBUG"):
            raise
        return EXIT_INTERNAL


def _stopping(exc: KeyboardInterrupt) -> int:
    """Report a stop by SIGINT (Ctrl-C) or SIGTERM; the exit status a shell gives a command it stopped."""
    interrupts.ignore_signals()  # a second signal must not interrupt this message
    if interrupts.stopped_by() == signal.SIGTERM:
        sys.stderr.write("\nliganimate: terminated (SIGTERM); every file already written is complete\n")
        return 143
    sys.stderr.write("\nliganimate: interrupted; every file already written is complete\n")
    return 130


def _stoppable(fn, whole_process: bool) -> int:
    """Run ``fn`` with SIGINT and SIGTERM turned into one clean stop (see runtime/interrupts.py).

    When the command is the whole process (``argv`` from the command line),
    a signal after it has finished is ignored: the process is only exiting,
    and a KeyboardInterrupt there would print a traceback.  Called with an
    explicit ``argv`` from other Python code, the usual handlers come back.
    """
    try:
        interrupts.stop_on_signals()
        status = fn()
    except KeyboardInterrupt as exc:
        return _stopping(exc)
    if whole_process:
        interrupts.ignore_signals()
    else:
        interrupts.restore_signals()
    return status


def _load_program(path: str) -> tuple:
    """``compiler.load_program(path)``, the compiler itself imported with the cyclic collector paused.

    Importing the compiler makes a few hundred classes, functions and
    tables and no garbage, yet the collector walks them a dozen times on the
    way (a few ms of a cold ``check``); compiling and running the module
    pause it already (lang/collector.py).
    """
    from liganimate.lang import collector

    with collector.paused():
        from liganimate.compiler import load_program

        return load_program(path)


def cmd_run(args) -> int:
    def go():
        stem = os.path.splitext(os.path.basename(args.file))[0]
        _usage_checked(args, args.parser)
        options = _render_options(args, stem)
        program, warnings = _load_program(args.file)
        return _render(program, warnings, options)

    return guarded(go)


def cmd_check(args) -> int:
    def go():
        program, warnings = _load_program(args.file)
        _print_diagnostics(warnings)
        _print_diagnostics(_checked(program, False, stdout=sys.stdout, asked=args.progress).warnings)
        return 0

    return guarded(go)


def cmd_compile(args) -> int:
    def go():
        from liganimate.compiler import compile_file
        from liganimate.runtime.files import AtomicWriter

        compiled = compile_file(args.file)
        _print_diagnostics(compiled.warnings)
        out = args.output or os.path.splitext(os.path.basename(args.file))[0] + ".py"
        with AtomicWriter(out) as fh:
            fh.write(compiled.python.encode("utf-8"))
        return 0

    return guarded(go)


def cmd_archive(args) -> int:
    def go():
        from liganimate.compiler import compile_source
        from liganimate.compiler.archive import archive_text
        from liganimate.lang.source import prepare
        from liganimate.runtime.files import AtomicWriter

        out = args.output or os.path.splitext(os.path.basename(args.file))[0] + "_lib.lig"
        text = archive_text(args.file, out)
        # The archive must itself load cleanly before it replaces anything.
        compile_source(prepare(text, out), path=os.path.abspath(out))
        with AtomicWriter(out) as fh:
            fh.write(text.encode("utf-8"))
        print(f"wrote {out}", file=sys.stderr)
        return 0

    return guarded(go)


def cmd_lib(args) -> int:
    def go():
        from liganimate.compiler import library as L
        from liganimate.runtime.errors import LigError

        names = [args.library] if args.library else L.stdlib_names()
        for i, name in enumerate(names):
            try:
                path = L.resolve(name, os.path.join(os.getcwd(), "-"))
            except L.LibraryNotFound as exc:
                raise LigError(*L.failure(exc, name)[:2]) from None
            lib = L.load(name, path)
            if i:
                print()
            print(f"{name}  ({lib.display})")
            order = {"PRIMITIVE": 0, "MODEL": 1, "MOTION": 2, "GRAPHICAL": 3}
            offered = sorted(lib.default_names(), key=lambda n: (order.get(lib.kind_of(n), 4), n))
            width = max((len(n) for n in offered), default=0)
            for n in offered:
                kind = lib.kind_of(n)
                print(f"  {n:<{width}}  {kind:<9}  {lib.descriptions.get(n, '(no description)')}")
        return 0

    return guarded(go)


def cmd_plot(args) -> int:
    def go():
        from liganimate.compiler import load_program
        from liganimate.runtime.render.plot import plot_motion

        program, warnings = load_program(args.file)
        _print_diagnostics(warnings)
        rt = program.execute("check")
        name = args.motion.upper()
        out = args.output or f"{name.lower()}.png"
        plot_motion(rt, name, out)
        return 0

    return guarded(go)


def cmd_lsp(args) -> int:
    """``liganimate lsp``: the language server, over stdin and stdout, until the editor says exit."""
    from liganimate.lsp import main as serve

    return serve(whole_parse=args.whole_parse)


def suffixed(suffix: str, what: str):
    """An argparse ``type`` for an output file that must end in ``suffix`` (``what`` names its format)."""

    def check(text: str) -> str:
        if not text.lower().endswith(suffix):
            raise argparse.ArgumentTypeError(f"{text!r} must end in {suffix}, as the file is {what}")
        return text

    return check


#: What a program file argument is, for every command's --help.
PROGRAM_HELP = "the LIG program (a .lig file)"


def _add_run(sub) -> None:
    p = sub.add_parser("run", help="compile a program and render its scenes")
    p.add_argument("file", help=PROGRAM_HELP)
    _add_render_options(p)
    p.set_defaults(func=cmd_run, parser=p)


def _add_check(sub) -> None:
    p = sub.add_parser("check", help="run every check without rendering")
    p.add_argument("file", help=PROGRAM_HELP)
    _add_progress_option(p)
    p.set_defaults(func=cmd_check)


def _add_compile(sub) -> None:
    p = sub.add_parser("compile", help="write the program as a standalone Python module")
    p.add_argument("file", help=PROGRAM_HELP)
    p.add_argument(
        "-o",
        "--output",
        metavar="FILE.py",
        type=suffixed(".py", "a Python module"),
        help="the module to write (default: <stem>.py in the current folder); run it with python FILE.py -o DIR",
    )
    p.set_defaults(func=cmd_compile)


def _add_lib(sub) -> None:
    p = sub.add_parser("lib", help="list the standard library's models, motions and primitives")
    p.add_argument("library", nargs="?", help="one library (a standard name or a path)")
    p.set_defaults(func=cmd_lib)


def _add_archive(sub) -> None:
    p = sub.add_parser("archive", help="write a program's models and motions out as a library file")
    p.add_argument("file", help=PROGRAM_HELP)
    p.add_argument(
        "-o", "--output", metavar="LIB.lig", type=suffixed(".lig", "a LIG library"), help="default: <stem>_lib.lig"
    )
    p.set_defaults(func=cmd_archive)


def _add_plot(sub) -> None:
    p = sub.add_parser("plot", help="draw a motion's joint angle curves with matplotlib")
    p.add_argument("file", help=PROGRAM_HELP)
    p.add_argument("motion", help="the MOTION variable to draw, as the program names it")
    p.add_argument(
        "-o",
        "--output",
        metavar="FILE.png",
        type=suffixed(".png", "a PNG image"),
        help="the image to write (default: <motion>.png in the current folder)",
    )
    p.set_defaults(func=cmd_plot)


def _add_tools(sub) -> None:
    # Export/import and the browser tools register their own subcommands.
    from liganimate import exchange_cli, fmt_cli, view_cli

    exchange_cli.add_commands(sub)
    view_cli.add_commands(sub)
    fmt_cli.add_commands(sub)


def _add_lsp(sub) -> None:
    p = sub.add_parser("lsp", help="serve the LIG language to an editor (the Language Server Protocol, over stdio)")
    p.add_argument(
        "--whole-parse",
        action="store_true",
        help="parse the whole text after every change instead of only the part around it (slower; for comparison)",
    )
    p.set_defaults(func=cmd_lsp)


def _add_completion(sub) -> None:
    p = sub.add_parser(
        "completion",
        help="print a shell completion script (bash, zsh or tcsh)",
        description="Print the script that completes liganimate's commands, options and files in a shell. "
        'In bash: eval "$(liganimate completion bash)"; in zsh: liganimate completion zsh > ~/.zfunc/_liganimate.',
    )
    p.add_argument("shell", choices=("bash", "zsh", "tcsh"), help="the shell to complete in")
    p.set_defaults(func=cmd_completion)


#: The subcommands, in the order ``liganimate --help`` lists them: (name, or None for the tools'
#: several, and the function that adds it to the subparsers).
_COMMANDS = (
    ("run", _add_run),
    ("check", _add_check),
    ("compile", _add_compile),
    ("lib", _add_lib),
    ("archive", _add_archive),
    ("plot", _add_plot),
    (None, _add_tools),
    ("lsp", _add_lsp),
    ("completion", _add_completion),
)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of the ``liganimate`` command.

    Parameters
    ----------
    command : str, optional
        Build only this subcommand's parser, when it is one of the commands
        defined here (``main`` passes the first argument, so that ``liganimate
        check`` does not build, or import the modules of, every other
        command's options: a fifth of what a cold check cost beyond its own
        work). Otherwise, every subcommand (``--help``, a mistyped command).
    """
    parser = argparse.ArgumentParser(
        prog="liganimate", description="LIG ANIMATE: model and animate articulated figures."
    )
    parser.add_argument("--version", action="version", version=f"liganimate {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    only = command if any(command == name for name, _ in _COMMANDS) else None
    for name, add in _COMMANDS:
        if only is None or name == only:
            add(sub)
    return parser


def cmd_completion(args) -> int:
    """``liganimate completion SHELL``: the completion script, made by shtab from the argument parser itself."""
    import shtab

    sys.stdout.write(shtab.complete(build_parser(), shell=args.shell))
    return 0


def main(argv=None) -> int:
    """Entry point of the ``liganimate`` command."""
    if argv is None:
        # This process is the command's own: freeze each compile's survivors
        # (lang/collector.py). Never done for a library user's process.
        from liganimate.lang import collector

        collector.freeze_survivors()

    def go():
        given = sys.argv[1:] if argv is None else argv
        args = build_parser(given[0] if given else None).parse_args(argv)
        return args.func(args)

    return _stoppable(go, argv is None)


def run_program_cli(program, argv=None) -> int:
    """``python compiled.py [-o DIR] ...``: render a compiled module."""
    parser = argparse.ArgumentParser(prog=os.path.basename(sys.argv[0]), description=f"Render {program.name}.")
    _add_render_options(parser)

    def go():
        args = parser.parse_args(argv)
        _usage_checked(args, parser)
        stem = os.path.splitext(os.path.basename(program.name))[0]
        return guarded(lambda: _render(program, [], _render_options(args, stem)))

    return _stoppable(go, argv is None)
