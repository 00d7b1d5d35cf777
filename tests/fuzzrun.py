"""Running one fuzz case the way ``liganimate`` does, and judging the outcome.

Shared by the fuzz tests (tests/test_fuzz_*.py) and ``benchmarks/fuzz.py``.
A case is a program text. :func:`run_case` writes it to a file, loads it
with :func:`liganimate.compiler.load_program` (what ``check`` and ``run`` call),
runs ``program.check()`` and then renders every shot tick at 16x12 into a
scratch folder, and sorts what happened into one outcome:

========== ======== ==========================================================
outcome    failure  meaning
========== ======== ==========================================================
ok         no       compiled, checked and rendered
diagnosed  no       LigDiagnostics, every one with file:line:col and one sentence
error      no       an exception ``cli.guarded`` prints as a clean error line
                    (LigError, OSError, RecursionError); counted apart because
                    it carries no position
slow       no       still running after the time limit (a legitimately long program)
crash      yes      anything else: the CLI would print "internal error"
baddiag    yes      a diagnostic without a position, or with Python text in it
disagree   yes      ``check`` passed but the render failed (the issue's
                    "check and run must agree")
leak       yes      a Python RuntimeWarning (numpy overflow...) reached stderr
========== ======== ==========================================================

Each failure has a *site*: the exception type and the innermost frame of
liganimate's own code (or of the generated module) it passed through, so
that a thousand cases of one bug count as one finding.
"""

from __future__ import annotations

import io
import os
import re
import resource
import shutil
import signal
import tempfile
import time
import traceback
import unicodedata
import warnings
from contextlib import contextmanager
from dataclasses import dataclass

import liganimate

#: Outcomes that are bugs.
FAILURES = ("crash", "baddiag", "disagree", "leak")
#: Every outcome, in the order reports list them.
OUTCOMES = ("ok", "diagnosed", "error", "slow") + FAILURES

#: Image size of the tiny render.
SIZE = (16, 12)
#: Address space a case may add to the process before it gets a MemoryError.
MEMORY = 1 << 30

_PACKAGE_ROOTS = tuple(
    os.path.realpath(p) + os.sep
    for p in {
        os.path.dirname(os.path.dirname(liganimate.__file__)),  # repo root (editable install)
        os.path.dirname(liganimate.__file__),
    }
)
# Text that must never appear in a diagnostic's sentence or hint.
_PYTHON_TEXT = re.compile(
    r"Traceback|array\(|site-packages|\w/[\w/.-]*\.py\b|object at 0x|<liganimate|\bnan\b|\binf\b|Errno"
)


class Slow(BaseException):
    """The case ran past its time limit (a BaseException, so that no ``except Exception`` swallows it)."""


@dataclass
class Outcome:
    """What one case did.

    ``kind`` is one of :data:`OUTCOMES`; ``stage`` is compile, check or
    render; ``site`` groups failures (empty for non-failures); ``detail`` is
    a one-line description; ``exc`` the exception, if any.
    """

    kind: str
    stage: str = ""
    site: str = ""
    detail: str = ""
    exc: BaseException | None = None
    seconds: float = 0.0

    @property
    def failed(self) -> bool:
        """Is this outcome a bug?"""
        return self.kind in FAILURES


@contextmanager
def time_limit(seconds: float):
    """Raise :class:`Slow` in the main thread after ``seconds`` (no-op without SIGALRM or when <= 0)."""
    if seconds <= 0 or not hasattr(signal, "setitimer"):
        yield
        return

    def on_alarm(signum, frame):
        raise Slow()

    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _address_space() -> int | None:
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


@contextmanager
def memory_limit(extra: int):
    """Let the process grow by at most ``extra`` bytes of address space (Linux; no-op elsewhere).

    A program that builds a list of 10**18 loop values then gets a
    MemoryError -- an internal error, reported -- instead of taking the
    machine down with it.
    """
    now = _address_space()
    if not extra or now is None:
        yield
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = now + extra
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def site_of(exc: BaseException) -> str:
    """``Type at file:function`` of the innermost frame of liganimate (or generated code) in the traceback."""
    frames = traceback.extract_tb(exc.__traceback__)
    where = "outside liganimate"
    for fr in frames:
        if fr.filename.startswith("<liganimate"):
            where = "generated module"
            continue
        path = os.path.realpath(fr.filename)
        for root in _PACKAGE_ROOTS:
            if path.startswith(root) and "site-packages" not in path[len(root) :]:
                where = f"{os.path.relpath(path, root)}:{fr.name}"
                break
    return f"{type(exc).__name__} at {where}"


def _bad_diagnostic(diags) -> str | None:
    """Why a LigDiagnostics is not what a user should see, or None if it is fine."""
    from liganimate.lang.diagnostics import format_diagnostic

    if not diags:
        return "LigDiagnostics with no diagnostic in it"
    for d in diags:
        if not d.filename or d.pos.line < 1 or d.pos.column < 1:
            return f"diagnostic without a position: {d.filename}:{d.pos.line}:{d.pos.column}: {d.message}"
        if d.source is not None and d.pos.line > d.source.count("\n") + 1:
            return f"diagnostic past the end of its file (line {d.pos.line}): {d.message}"
        for text in (d.message, d.hint or ""):
            if not isinstance(text, str) or "\n" in text or _PYTHON_TEXT.search(text):
                return f"diagnostic with Python text in it: {text!r}"
        if not d.message.strip():
            return "diagnostic with an empty sentence"
        if d.source is not None and d.pos.line <= d.source.count("\n"):
            line = d.source.split("\n")[d.pos.line - 1]
            if d.pos.column > len(line) + 1:
                return f"diagnostic at column {d.pos.column} of a line of {len(line)} characters: {d.message}"
        shown = format_diagnostic(d)  # what the CLI prints; must not raise
        raw = [c for c in shown if c != "\n" and unicodedata.category(c) in ("Cc", "Zl", "Zp")]
        if raw:
            return f"diagnostic prints control characters raw ({raw[0]!r}): {d.message}"
    return None


def _runtime_warnings(caught) -> list:
    return [w for w in caught if issubclass(w.category, RuntimeWarning)]


def run_case(
    text: str, limit: float = 2.0, render: bool = True, memory: int = MEMORY, workdir: str | None = None
) -> Outcome:
    """Compile, check and (if ``render``) render ``text``; return its :class:`Outcome`.

    ``limit`` is in seconds (0: none); ``memory`` is the address space the
    case may add (0: no limit); ``workdir`` is a folder for the scratch
    files (default: a fresh temporary folder, removed afterwards).
    """
    from liganimate.compiler import load_program
    from liganimate.lang.diagnostics import LigDiagnostics
    from liganimate.runtime.errors import LigError

    own = workdir is None
    tmp = tempfile.mkdtemp(prefix="ligfuzz-") if own else workdir
    path = os.path.join(tmp, "fuzz.lig")
    with open(path, "w", encoding="utf-8", errors="surrogatepass") as fh:
        fh.write(text)
    stage = "compile"
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with time_limit(limit), memory_limit(memory):
                program, _ = load_program(path)
                stage = "check"
                program.check()
                if render:
                    stage = "render"
                    program.render(
                        os.path.join(tmp, "out"), checked=True, size=SIZE, quiet=True, workers=1, stdout=io.StringIO()
                    )
        leaked = _runtime_warnings(caught)
        if leaked:
            w = leaked[0]
            return Outcome("leak", stage, f"{w.category.__name__} from {os.path.basename(w.filename)}", str(w.message))
        return Outcome("ok", stage)
    except Slow:
        return Outcome("slow", stage, detail=f"over {limit:g} s")
    except KeyboardInterrupt:
        raise
    except LigDiagnostics as exc:
        if stage == "render":
            return Outcome("disagree", stage, f"check passed, render raised {site_of(exc)}", _first_line(str(exc)), exc)
        bad = _bad_diagnostic(exc.diagnostics)
        if bad:
            return Outcome("baddiag", stage, f"bad diagnostic from {site_of(exc)}", bad, exc)
        return Outcome("diagnosed", stage, detail=_first_line(str(exc)), exc=exc)
    except (LigError, OSError, RecursionError) as exc:
        if stage == "render":
            return Outcome("disagree", stage, f"check passed, render raised {site_of(exc)}", _first_line(str(exc)), exc)
        return Outcome("error", stage, detail=f"{type(exc).__name__}: {_first_line(str(exc))}", exc=exc)
    except Exception as exc:  # noqa: BLE001 - what the CLI would call an internal error is the finding
        return Outcome("crash", stage, site_of(exc), f"{type(exc).__name__}: {_first_line(str(exc))}", exc)
    finally:
        if own:
            shutil.rmtree(tmp, ignore_errors=True)
        elif os.path.isdir(os.path.join(tmp, "out")):
            shutil.rmtree(os.path.join(tmp, "out"), ignore_errors=True)


def _first_line(text: str, width: int = 200) -> str:
    line = text.strip().split("\n", 1)[0]
    return line if len(line) <= width else line[:width] + "..."


def timed(text: str, **options) -> Outcome:
    """:func:`run_case` with the wall time filled in."""
    start = time.perf_counter()
    out = run_case(text, **options)
    out.seconds = time.perf_counter() - start
    return out


# ------------------------------------------------------------------ minimising

# A token and the blanks after it: removing a token never glues its neighbours together.
_TOKEN = re.compile(
    r"(?:\{[^}]*\}|'[^'\n]*'|[A-Za-z_][A-Za-z0-9_]*|[0-9.]+(?:[eE][-+]?\d+)?°?|::=|:-|:=|\S)\s*"
    r"|\s+"
)


def _ddmin(parts: list, keeps, deadline: float, join) -> list:
    """Zeller's delta debugging: a smaller list of parts for which ``keeps(join(parts))`` still holds."""
    n = 2
    while len(parts) >= 2 and time.monotonic() < deadline:
        chunk = max(1, len(parts) // n)
        removed = False
        for i in range(0, len(parts), chunk):
            if time.monotonic() >= deadline:
                break
            trial = parts[:i] + parts[i + chunk :]
            if trial and keeps(join(trial)):
                parts = trial
                n = max(n - 1, 2)
                removed = True
                break
        if not removed:
            if chunk == 1:
                break
            n = min(len(parts), n * 2)
    return parts


def _drop_runs(lines: list, keeps, deadline: float, longest: int = 8) -> list:
    """Remove runs of 2..``longest`` lines that only go together (a block's opener and closer)."""
    for width in range(min(longest, len(lines) - 1), 1, -1):
        i = 0
        while i + width <= len(lines) and time.monotonic() < deadline:
            trial = lines[:i] + lines[i + width :]
            if keeps("\n".join(trial)):
                lines = trial
            else:
                i += 1
    return lines


def minimise(text: str, outcome: Outcome, budget: float = 20.0, limit: float = 2.0) -> str:
    """The smallest text found within ``budget`` seconds that fails with the same kind and site.

    Lines are removed first, then tokens (whitespace kept where it
    separates words), then runs of spaces are squeezed.
    """
    deadline = time.monotonic() + budget
    memo: dict = {}

    def keeps(candidate: str) -> bool:
        if candidate not in memo:
            got = run_case(candidate, limit=limit)
            memo[candidate] = got.kind == outcome.kind and got.site == outcome.site
        return memo[candidate]

    lines = _ddmin(text.split("\n"), keeps, deadline, "\n".join)
    lines = _drop_runs(lines, keeps, deadline)
    text = "\n".join(lines)
    tokens = _ddmin(_TOKEN.findall(text), keeps, deadline, "".join)
    text = "".join(tokens)
    # Blank lines go, runs of blanks inside a line become one; indentation
    # stays (a line starting with C in column 1 is a comment).
    squeezed = re.sub(r"(?<=\S)[ \t]+", " ", re.sub(r"\n\s*\n", "\n", text)).rstrip() + "\n"
    if squeezed != text and keeps(squeezed):
        text = squeezed
    return text


# ------------------------------------------------------------------ for the tests

_MINIMISED: dict = {}


def assert_runs_or_is_diagnosed(text: str, limit: float = 2.0, budget: float = 15.0) -> Outcome:
    """Run one case; raise AssertionError with the minimised program if it fails.

    Hypothesis runs a failing example once more to report it; the
    minimisation is remembered so that it is done once.
    """
    out = run_case(text, limit=limit)
    if not out.failed:
        return out
    if text not in _MINIMISED:
        _MINIMISED[text] = minimise(text, out, budget=budget, limit=limit)
    raise AssertionError(
        f"{out.kind} in {out.stage}: {out.site}\n  {out.detail}\n"
        f"--- minimised program ---\n{_MINIMISED[text]}"
        f"--- generated program ---\n{text}"
    ) from out.exc


def seeded_programs(cases: int):
    """Decorate a test ``f(rng)`` to run on ``cases`` seeded random generators, the same ones every run.

    Hypothesis only supplies the seeds (derandomized, no example database,
    no shrinking phase: :func:`minimise` shrinks a failing program instead),
    so the fuzz tests are reproducible in CI and on a laptop alike.
    """
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import strategies as st

    def wrap(test):
        return settings(
            max_examples=cases,
            derandomize=True,
            deadline=None,
            database=None,
            phases=(Phase.explicit, Phase.generate),
            suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.large_base_example],
        )(given(rng=st.randoms(use_true_random=False))(test))

    return wrap
