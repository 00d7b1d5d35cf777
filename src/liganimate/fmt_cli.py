"""``liganimate fmt``: rewrite programs in the canonical layout (lang/formatter.py).

``liganimate fmt FILE_OR_FOLDER...`` rewrites each program that is not in
the layout, atomically; ``--check`` writes nothing and names the files that
would change (exit status 1 if any, for CI); ``--diff`` prints what would
change as a unified diff and writes nothing. A folder stands for every
``.lig`` file under it. A file that does not parse is reported as ``check``
reports it and left alone; the others are still formatted.

Exit status: 0 when every file is (now) in the layout, 1 when ``--check``
found a file to change or a file could not be read or parsed, 2 for a
usage error.
"""

from __future__ import annotations

import os
import sys


def add_commands(subparsers) -> None:
    """Add ``fmt`` to the ``liganimate`` command's subparsers."""
    p = subparsers.add_parser(
        "fmt",
        help="rewrite programs in the canonical layout, keeping every comment",
        description="Lay LIG programs out one way: blocks indented, keywords in capitals, one blank around "
        "operators and after commas, long lines wrapped, every comment kept where it was. The program's "
        "meaning never changes. Folders stand for the .lig files under them.",
    )
    p.add_argument("paths", nargs="+", metavar="FILE", help="a .lig file, or a folder of them")
    p.add_argument(
        "--check", action="store_true", help="write nothing; name the files that would change and exit 1 if any"
    )
    p.add_argument("--diff", action="store_true", help="write nothing; print the changes as a unified diff")
    p.add_argument("--quiet", action="store_true", help="name only the files that fail")
    p.set_defaults(func=cmd_fmt)


def lig_files(paths: list) -> list:
    """The files ``paths`` stand for: each file as given, each folder's ``.lig`` files (recursively, sorted)."""
    out: list = []
    for path in paths:
        if os.path.isdir(path):
            found = []
            for folder, dirs, files in os.walk(path):
                dirs[:] = sorted(d for d in dirs if not d.startswith("."))
                found += [os.path.join(folder, f) for f in files if f.endswith(".lig")]
            out += sorted(found)
        else:
            out.append(path)
    return out


def formatted(path: str) -> tuple:
    """``(text as read, text in the canonical layout)`` of the program at ``path``.

    Raises
    ------
    LigDiagnostics
        The file is not LIG text or does not parse.
    OSError
        The file cannot be read.
    """
    from liganimate.compiler import loaded_primitive_names
    from liganimate.lang.formatter import format_source
    from liganimate.lang.source import load

    source = load(path)
    return source.text, format_source(source, loaded_primitive_names(source, path))


def _write(path: str, text: str) -> None:
    from liganimate.runtime.files import AtomicWriter

    mode = os.stat(path).st_mode & 0o7777
    with AtomicWriter(path) as fh:
        fh.write(text.encode("utf-8"))
    if os.stat(path).st_mode & 0o7777 != mode:
        os.chmod(path, mode)  # a program keeps its permissions


def _one(path: str, args) -> str:
    """Format one file as ``args`` ask: 'same', 'changed' or 'failed' (its diagnostics printed)."""
    from liganimate.cli import guarded

    result = ["failed"]

    def go() -> int:
        before, after = formatted(path)
        if before == after:
            result[0] = "same"
            return 0
        result[0] = "changed"
        if args.diff:
            import difflib  # only for --diff: every command imports this module

            lines = difflib.unified_diff(_lines(before), _lines(after), path, path + " (formatted)")
            sys.stdout.writelines(lines)
        if not args.check and not args.diff:
            _write(path, after)
        return 0

    guarded(go)
    return result[0]


def cmd_fmt(args) -> int:
    """``liganimate fmt``: see the module's docstring for what it does and its exit statuses."""
    counts = {"same": 0, "changed": 0, "failed": 0}
    for path in lig_files(args.paths):
        outcome = _one(path, args)
        counts[outcome] += 1
        if outcome == "changed" and args.check:
            print(f"would reformat {path}", file=sys.stderr)
        elif outcome == "changed" and not args.diff and not args.quiet:
            print(f"reformatted {path}", file=sys.stderr)
    if not args.quiet:
        verb = "would be reformatted" if args.check or args.diff else "reformatted"
        summary = f"{counts['changed']} {_files(counts['changed'])} {verb}, {counts['same']} left unchanged"
        if counts["failed"]:
            summary += f", {counts['failed']} could not be formatted"
        print(summary, file=sys.stderr)
    return 1 if counts["failed"] or (args.check and counts["changed"]) else 0


def _lines(text: str) -> list:
    """The lines of ``text`` ending at each line feed only (a quoted word may hold U+2028, which is no line end)."""
    parts = text.split("\n")
    return [p + "\n" for p in parts[:-1]] + ([parts[-1]] if parts[-1] else [])


def _files(n: int) -> str:
    return "file" if n == 1 else "files"
