"""Numbers (lang/numbers.py): literals out of range, arithmetic that leaves the range, host limits.

Every program goes through the command line (``python -m liganimate check``)
and must end in a positioned diagnostic: never a traceback, never an
internal error. The memory tests run in a child process with a capped
address space, so they fail on a regression without hurting the machine.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from liganimate.lang import numbers as N

BIG = "1" + "0" * 400  # a 401-digit integer
HUGE = "7" * 5000  # beyond Python's 4300-digit int() limit
BOX = "(BOX WIDTH 1, HEIGHT 1, DEPTH 1)"
HUMANOID = "LOAD HUMANOID, WALK FROM 'humanoid'; "


def cli(*args, cwd, env=None, preexec_fn=None, timeout=120):
    return subprocess.run(
        [sys.executable, "-m", "liganimate", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        check=False,
        env=env,
        preexec_fn=preexec_fn,
        timeout=timeout,
    )


def check(tmp_path, program: str, **kw):
    (tmp_path / "f.lig").write_text(program + "\n", encoding="utf-8")
    return cli("check", "f.lig", cwd=tmp_path, **kw)


def assert_diagnostic(r, where: str, words: str):
    assert r.returncode == 1, r.stdout + r.stderr
    assert "Traceback" not in r.stderr and "internal error" not in r.stderr, r.stderr
    assert "Warning" not in r.stderr, r.stderr
    first = r.stderr.splitlines()[0]
    assert first.startswith(f"f.lig:{where}: error: "), first
    assert words in first, first


# ----------------------------------------------------------------- literals


def col(program: str, needle: str) -> str:
    """'1:<column of needle>' for a one-line program."""
    return f"1:{program.index(needle) + 1}"


LITERALS = {
    "real beyond a double": "X = 1e309",
    "5000-digit integer": f"X = {HUGE}",
    "in a vector": f"V = ({BIG}, 0, 0)",
    "REAL()": f"X = REAL({BIG})",
    "BOX size": f"G = BOX WIDTH {BIG}, HEIGHT 1, DEPTH 1",
    "LIGHTNESS": f"G = {BOX} <LIGHTNESS {BIG}>",
    "TRANS": f"G = {BOX} <TRANS ({BIG}, 0, 0)>",
    "VIEW WIDTH": f"VIEW WIDTH = {BIG}",
    "SCALE FRAMES": f"{HUMANOID}W = WALK <SCALE FRAMES {BIG}>",
    "SCALE EXTREMES": f"{HUMANOID}W = WALK <SCALE EXTREMES {BIG}>",
    "SCALE MODEL": f"{HUMANOID}M = HUMANOID <SCALE MODEL {BIG}>",
    "extremes": f"M = JOINT 1, {BOX}, (0, 0, 0), {BOX}, (0, 0, 0), (0, {BIG})",
    "FRAME": f"W[1, 1] = FRAME {BIG} POSITION 0, 0, 0",
    "ANIMATE FROM": f"{HUMANOID}INITIALIZE SCENE 1 STARTSCENE LENGTH 2 ANIMATE HUMANOID FROM {BIG} TO 1 "
    "USING WALK ENDSCENE",
    "divided": f"X = {BIG} / 3",
    "MOD": f"X = {BIG} MOD 7",
    "just past INT_MAX": "I = 9223372036854775808",
}


@pytest.mark.parametrize("program", LITERALS.values(), ids=LITERALS.keys())
def test_a_literal_out_of_range_is_an_error_at_the_literal(tmp_path, program):
    needle = next(t for t in ("1e309", HUGE[:30], BIG, "9223372036854775808") if t in program)
    r = check(tmp_path, program)
    assert_diagnostic(r, col(program, needle), "too large")


def test_compile_writes_nothing_for_a_bad_literal(tmp_path):
    (tmp_path / "f.lig").write_text("X = 1e309\nPRINT X\n")
    r = cli("compile", "f.lig", "-o", "f.py", cwd=tmp_path)
    assert_diagnostic(r, "1:5", "too large for a REAL")
    assert not (tmp_path / "f.py").exists()
    assert "inf" not in r.stderr.replace("infinite", "")


def test_a_do_label_out_of_range_is_an_error(tmp_path):
    r = check(tmp_path, "DO 1e999 I = 1, 2\n1e999 CONTINUE")
    assert_diagnostic(r, "1:1", "label")


def test_literals_at_the_edges():
    assert N.literal("9223372036854775807") == N.INT_MAX
    assert isinstance(N.literal("9223372036854775808"), N.BadInteger)
    assert N.literal("000000000000000000000000000042") == 42
    assert isinstance(N.literal(HUGE), N.BadInteger)
    assert N.literal("1.7976931348623157e308") == N.REAL_MAX
    assert isinstance(N.literal("1.8e308"), N.BadReal)
    assert N.literal("1e-400") == 0.0  # underflow is allowed: it is still a finite REAL
    assert N.literal_problem(N.literal("12")) is None


# ---------------------------------------------------------------- run time

RUNTIME = [
    # (program, needle the diagnostic points at, words)
    ("X = 1e308 * 10", "1e308 * 10", "REAL overflow"),
    ("I = 9223372036854775807 + 1", "9223372036854775807 + 1", "INTEGER overflow"),
    ("I = 3037000500 * 3037000500", "3037000500 * 3037000500", "INTEGER overflow"),
    ("X = COS(1e308 * 10)", "1e308 * 10", "REAL overflow"),
    ("X = INT(1e308 * 10)", "1e308 * 10", "REAL overflow"),
    ("X = INT(1e300)", "INT(", "INTEGER overflow"),
    ("X = NINT(-1e300)", "NINT(", "INTEGER overflow"),
    ("X = (1e308 * 10) MOD 7", "1e308 * 10", "REAL overflow"),
    ("X = INT((1e308 * 10) - (1e308 * 10))", "1e308 * 10) - ", "REAL overflow"),
    ("X = 1e300 / 1e-10", "/", "REAL overflow"),
    ("X = EXP(1000)", "EXP(", "too large"),
    ("X = DOT((1e200, 1e200, 1e200), (1e200, 0, 0))", "DOT(", "REAL overflow"),
    ("V = (1e308, 0, 0) * 10", "1e308, 0, 0) * 10", "REAL overflow"),
    ("V = CROSS((1e200, 0, 0), (0, 1e200, 0))", "CROSS(", "REAL overflow"),
]


@pytest.mark.parametrize("program, needle, words", RUNTIME, ids=[p for p, _, _ in RUNTIME])
def test_arithmetic_leaving_the_range_is_an_error_at_the_operation(tmp_path, program, needle, words):
    r = check(tmp_path, program)
    assert_diagnostic(r, col(program, needle), words)


def test_integer_arithmetic_inside_one_expression_is_exact(tmp_path):
    # Only the value an expression hands on must be in range (docs/language.md, Numbers).
    (tmp_path / "f.lig").write_text("I = 9223372036854775807 + 1 - 1\nPRINT I\n")
    r = cli("run", "f.lig", "-o", "out", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "I = 9223372036854775807" in r.stdout


def test_norm_of_large_components_is_finite(tmp_path):
    (tmp_path / "f.lig").write_text("X = NORM((1e200, 1e200, 1e200))\nPRINT X\n")
    r = cli("run", "f.lig", "-o", "out", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "X = 1.73205e+200" in r.stdout


def test_functions_keep_their_values(tmp_path):
    (tmp_path / "f.lig").write_text(
        textwrap.dedent("""\
        A = -1 MOD 360
        B = 7.5 MOD -2
        PRINT NINT(-2.5), NINT(2.5), INT(-2.7), A, B, 7 MOD 3, MIN(1, 2.5), 7 / 2
        """)
    )
    r = cli("run", "f.lig", "-o", "out", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split("\n")[:8] == [
        "NINT(-2.5) = -3",
        "NINT(2.5) = 3",
        "INT(-2.7) = -2",
        "A = 359",
        "B = -0.5",
        "7 MOD 3 = 1",
        "MIN(1, 2.5) = 1",
        "7 / 2 = 3.5",
    ]


def test_a_real_do_loop_counts_as_before(tmp_path):
    (tmp_path / "f.lig").write_text(
        textwrap.dedent("""\
        REAL X, S
        INTEGER N
        DO 10 X = 0.0, 1.0, 0.1
            S = S + X
            N = N + 1
        10 CONTINUE
        PRINT N, X
        """)
    )
    r = cli("run", "f.lig", "-o", "out", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[:2] == ["N = 11", "X = 1"]


# ----------------------------------------------------------- host limits

LIMITS = [
    ("G = BOX WIDTH 1e300, HEIGHT 1, DEPTH 1", "BOX WIDTH", "limit"),
    (f"G = {BOX} <TRANS (1e300, 0, 0)>", BOX[1:], "limit"),
    (f"{HUMANOID}M = HUMANOID <SCALE MODEL 1e300>", "HUMANOID <SCALE", "limit"),
    (f"{HUMANOID}W = WALK <SCALE FRAMES 1e-300>", "WALK <SCALE", "apart"),
    (f"{HUMANOID}W = WALK <SCALE FRAMES 1e300>", "WALK <SCALE", "beyond the last frame"),
    (f"{HUMANOID}W = WALK <SCALE EXTREMES 1e300>", "WALK <SCALE", "degrees"),
    ("W[1, 1] = FRAME 1e300 POSITION 0, 0, 0", "W[1", "beyond the last frame"),
    ("W[1, 1] = FRAME 1 POSITION 1e300, 0, 0", "W[1", "degrees"),
    (f"M = JOINT 1, {BOX}, (0, 0, 0), {BOX}, (0, 0, 0), (-1e308, 1e308)", "JOINT", "extremes"),
    ("VIEW WIDTH = 1e-300", "VIEW", "smallest width"),
    ("VIEW POINT = (1e200, 0, 0)", "VIEW", "limit"),
    ("VIEW POINT = (1e-200, 0, 0)", "VIEW", "closer to the origin"),
    (f"{HUMANOID}M = HUMANOID <TRANS JOINTS 9223372036854775807>", "HUMANOID <TRANS", "INTEGER range"),
]


@pytest.mark.parametrize("program, needle, words", LIMITS, ids=[p[-40:] for p, _, _ in LIMITS])
def test_a_host_limit_is_an_error_at_the_statement(tmp_path, program, needle, words):
    r = check(tmp_path, program)
    assert_diagnostic(r, col(program, needle), words)


def test_primitive_without_a_pattern_is_a_diagnostic(tmp_path):
    r = check(tmp_path, "PRIMITIVE FOO\nEND")
    assert_diagnostic(r, "1:11", "has no invocation pattern")


def test_a_scene_too_long_is_refused_at_its_length(tmp_path):
    program = "INITIALIZE SCENE 1\nSTARTSCENE LENGTH 1000000000000\nENDSCENE\nSHOOTSCENES"
    r = check(tmp_path, program, timeout=60)
    assert_diagnostic(r, "2:19", "longer than the longest allowed")
    assert "hint:" in r.stderr


def test_the_longest_scene_allowed_is_the_documented_one():
    assert N.MAX_SCENE_LENGTH == 10_000_000 and N.MAX_KEYFRAME == 1_000_000


# ------------------------------------------------------------------ memory


def _capped():
    import resource

    limit = 1536 * 1024 * 1024
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def capped_check(tmp_path, program: str, **more_env):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1", **more_env)
    return check(tmp_path, program, env=env, preexec_fn=_capped, timeout=120)


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS is Linux's")
def test_a_real_do_loop_to_1e18_runs_in_bounded_memory(tmp_path):
    # The loop used to build its list of 1e18 values before the first pass.
    # Its 1e18 passes are over the loop budget (docs/security.md), which is
    # refused up front; raised past them, the loop runs lazily until STOP.
    program = "REAL R\nINTEGER N\nDO 10 R = 0.0, 1e18\nN = N + 1\nIF N > 100000 THEN STOP\n10 CONTINUE"
    refused = capped_check(tmp_path, program)
    assert_diagnostic(refused, "3:1", "would make 1E18 passes, over the budget of 100000000 passes for one loop")
    assert "e+" not in refused.stderr  # spelled as LIG writes numbers
    r = capped_check(tmp_path, program, LIGANIMATE_MAX_LOOP_PASSES=str(2 * 10**18))
    assert r.returncode == 0, r.stderr


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS is Linux's")
def test_an_absurd_keyframe_number_is_refused_in_bounded_memory(tmp_path):
    r = capped_check(tmp_path, "W[1, 1000000000000000000] = FRAME 2 POSITION 0, 0, 0\nX = LEN(W)")
    assert_diagnostic(r, "1:1", "beyond the last keyframe number allowed")


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS is Linux's")
def test_a_missing_keyframe_is_found_without_walking_every_number(tmp_path):
    r = capped_check(tmp_path, "W[1, 1000000] = FRAME 2 POSITION 0, 0, 0\nX = LEN(W)")
    assert_diagnostic(r, "1:1", "keyframe 1000000 of joint 1 is set, but keyframe 1 never is")


def test_limits_are_spelled_as_lig_writes_numbers(tmp_path):
    # A message quotes the limit the user must stay within; Python's '1e+12'
    # is not a number the user could type back into a program as shown.
    r = check(tmp_path, "G :- BOX WIDTH 3E12, HEIGHT 1, DEPTH 1\n")
    assert r.returncode == 1 and "1E12" in r.stderr
    assert "e+" not in r.stderr and "inf" not in r.stderr
    assert N.magnitude(2.5e-7) == "2.5E-7" and N.magnitude(float("inf")) == "more than 1.8E308"
