"""Fuzzing the front end: mutated example programs must compile or be diagnosed.

Each case takes one of the programs in ``examples/``, applies one to three
random mutations (delete, duplicate or swap lines; delete or insert
characters; insert a LIG token; truncate the file) and runs it the way
``liganimate check`` does, in process: parse, check, lower, execute the
Python module text, then ``program.check()``. A case ends in one of:

* ``ok``: the mutated program compiled and its runtime checks passed;
* ``diagnostics``: a :class:`~liganimate.lang.diagnostics.LigDiagnostics`
  was raised (the user would see ``file:line:col`` and exit status 1);
* ``slow``: the program was still running after the per-case time limit
  (a mutation can turn ``LENGTH 6`` into ``LENGTH 600000``; that is a
  legitimate, long program, not a crash);
* ``crash``: any other exception -- a bug. The first few are printed with
  the mutated text that caused them.

The mutation functions are shared with ``tests/test_fuzz_compile.py``,
which drives them with hypothesis instead of ``random``.

Usage: ``python benchmarks/fuzz_compile.py [--quick] [--cases N] [--seed S]``.
The last line printed is one JSON object: cases, ok, diagnostics, slow,
crashes, seconds, rate (cases per second) and crash_rate (crashes per case).
Crashes are summarised by exception above it, and the first few are shown
in full on stderr with the mutations that produced them.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import sys
import time
import traceback

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(ROOT, "examples")

#: Characters worth inserting: LIG punctuation, digits, a degree sign,
#: comment and quote delimiters, a newline, a $ and a stray non-ASCII letter.
CHARS = "()<>,;:-=*+/[]{}'$0123456789.°\n ACXZé\t"

#: Tokens worth inserting: keywords, operators, names from the examples, numbers.
TOKENS = [
    "JOINT",
    "STARTMODEL",
    "ENDMODEL",
    "STARTMOTION",
    "ENDMOTION",
    "ENDJOINT",
    "FRAME",
    "POSITION",
    "INTERPOLATE",
    "ACCDCC",
    "LINEAR",
    "FIGURE",
    "MAIN",
    "LINK",
    "INITIALIZE",
    "SCENE",
    "STARTSCENE",
    "LENGTH",
    "SAMEFRAME",
    "ENDSCENE",
    "ANIMATE",
    "FROM",
    "TO",
    "USING",
    "REPEAT",
    "BACKGROUND",
    "PRINT",
    "SHOOTSCENES",
    "STOP",
    "END",
    "DO",
    "CONTINUE",
    "IF",
    "THEN",
    "ELSE",
    "BEGIN",
    "STRIP",
    "SYNCHRONIZE",
    "TRANS",
    "JOINTS",
    "BY",
    "SCALE",
    "MODEL",
    "EXTREMES",
    "FRAMES",
    "ROT",
    "X",
    "LIGHTNESS",
    "BOX",
    "WIDTH",
    "HEIGHT",
    "DEPTH",
    "AT",
    "PRIMITIVE",
    "RETURN",
    "DRAW",
    "POLY",
    "WITH",
    "REAL",
    "INTEGER",
    "VECTOR",
    "GRAPHICAL",
    "MOTION",
    "MOD",
    "AND",
    "OR",
    "NOT",
    "VIEW",
    "POINT",
    ":-",
    ":=",
    "=",
    "<",
    ">",
    "(",
    ")",
    ",",
    "+",
    "-",
    "*",
    "/",
    "[",
    "]",
    "$HUMAN",
    "HUMAN",
    "SQUAT",
    "FOOT",
    "TORSO",
    "CLOCK",
    "TIME",
    "HOP",
    "WALK",
    "A",
    "B",
    "ROBOT",
    "0",
    "1",
    "-1",
    "0.0",
    "2.5",
    "135°",
    "1e308",
    "99999",
    "(0.0, 0.0, 0.0)",
    "(0, 0)",
]

MUTATIONS = (
    "delete_line",
    "duplicate_line",
    "swap_lines",
    "delete_chars",
    "insert_char",
    "insert_token",
    "truncate",
    "replace_token",
)


def example_sources() -> list:
    """(name, text) of every example program, sorted by name."""
    out = []
    for name in sorted(os.listdir(EXAMPLES)):
        if name.endswith(".lig"):
            with open(os.path.join(EXAMPLES, name), encoding="utf-8") as fh:
                out.append((name, fh.read()))
    return out


def _index(u: float, n: int) -> int:
    """Map u in [0, 1) to an index in range(n) (n >= 1)."""
    return min(n - 1, max(0, int(u * n)))


def mutate(text: str, kind: str, u: float, v: float, pick: int) -> str:
    """Apply one mutation; ``u`` and ``v`` in [0, 1) choose places, ``pick`` a payload."""
    if kind in ("delete_line", "duplicate_line", "swap_lines"):
        lines = text.split("\n")
        i = _index(u, len(lines))
        if kind == "delete_line":
            del lines[i]
        elif kind == "duplicate_line":
            lines.insert(i, lines[i])
        else:
            j = _index(v, len(lines))
            lines[i], lines[j] = lines[j], lines[i]
        return "\n".join(lines)
    n = len(text)
    i = _index(u, n + 1)
    if kind == "delete_chars":
        return text[:i] + text[i + 1 + pick % 8 :]
    if kind == "insert_char":
        return text[:i] + CHARS[pick % len(CHARS)] + text[i:]
    if kind == "insert_token":
        return text[:i] + " " + TOKENS[pick % len(TOKENS)] + " " + text[i:]
    if kind == "replace_token":
        # Replace the word or number starting at or after i with a token.
        j = i
        while j < n and not (text[j].isalnum() or text[j] == "_"):
            j += 1
        k = j
        while k < n and (text[k].isalnum() or text[k] in "_."):
            k += 1
        return text[:j] + TOKENS[pick % len(TOKENS)] + text[k:]
    if kind == "truncate":
        return text[:i]
    raise ValueError(kind)


# The time limit is the fuzz harness's own (tests/fuzzrun.py), not a second copy.
sys.path.insert(0, os.path.join(ROOT, "tests"))
from fuzzrun import Slow, time_limit  # noqa: E402


def compile_and_check(text: str, filename: str = "fuzz.lig") -> None:
    """What ``liganimate check`` does, in process. Raises LigDiagnostics for user errors."""
    from liganimate.compiler import load_program

    load_program(text=text, name=filename)[0].check()


def classify(text: str, limit: float = 2.0):
    """Run one case; return ("ok" | "diagnostics" | "slow" | "crash", exception or None)."""
    from liganimate.lang.diagnostics import LigDiagnostics

    try:
        with time_limit(limit):
            compile_and_check(text)
    except Slow as exc:
        return "slow", exc
    except LigDiagnostics as exc:
        return "diagnostics", exc
    except BaseException as exc:  # noqa: BLE001 - anything else is the finding
        if isinstance(exc, KeyboardInterrupt):
            raise
        return "crash", exc
    return "ok", None


def random_case(rng: random.Random, sources: list):
    """A (name, mutated text, description) drawn from ``rng``."""
    name, text = sources[rng.randrange(len(sources))]
    steps = []
    for _ in range(rng.randint(1, 3)):
        kind = rng.choice(MUTATIONS)
        u, v, pick = rng.random(), rng.random(), rng.randrange(1 << 16)
        text = mutate(text, kind, u, v, pick)
        steps.append(f"{kind}({u:.4f}, {v:.4f}, {pick})")
    return name, text, " ".join(steps)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="a run of under a minute (1200 cases, at most 50 s)")
    parser.add_argument("--cases", type=int, help="number of cases (default 1200 with --quick, else 5000)")
    parser.add_argument("--seed", type=int, default=1986)
    parser.add_argument("--limit", type=float, default=2.0, help="seconds per case before it counts as slow")
    parser.add_argument("--budget", type=float, help="stop after this many seconds (default 50 with --quick)")
    parser.add_argument("--show", type=int, default=3, help="print this many crashes in full")
    args = parser.parse_args(argv)
    cases = args.cases or (1200 if args.quick else 5000)
    budget = args.budget if args.budget is not None else (50.0 if args.quick else float("inf"))

    sources = example_sources()
    rng = random.Random(args.seed)
    counts = {"ok": 0, "diagnostics": 0, "slow": 0, "crash": 0}
    kinds: dict = {}
    shown = 0
    done = 0
    start = time.perf_counter()
    for _ in range(cases):
        if time.perf_counter() - start > budget:
            break
        name, text, how = random_case(rng, sources)
        outcome, exc = classify(text, args.limit)
        counts[outcome] += 1
        done += 1
        if outcome == "crash":
            key = f"{type(exc).__name__}: {str(exc)[:80]}"
            kinds[key] = kinds.get(key, 0) + 1
            if shown < args.show:
                shown += 1
                print(f"--- crash {shown}: {name} after {how}", file=sys.stderr)
                print("".join(traceback.format_exception(exc)[-6:]), file=sys.stderr)
    seconds = time.perf_counter() - start
    for key, n in sorted(kinds.items(), key=lambda kv: -kv[1]):
        print(f"{n:6d}  {key}")
    print(
        json.dumps(
            {
                "cases": done,
                "ok": counts["ok"],
                "diagnostics": counts["diagnostics"],
                "slow": counts["slow"],
                "crashes": counts["crash"],
                "seconds": round(seconds, 2),
                "rate": round(done / seconds, 1) if seconds > 0 else None,
                "crash_rate": round(counts["crash"] / done, 5) if done else 0.0,
                "seed": args.seed,
                "quick": args.quick,
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
