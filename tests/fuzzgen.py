"""Program generators for fuzzing: grammar expansion, extreme numbers, cross-file splices.

Shared by the fuzz tests (tests/test_fuzz_grammar.py, test_fuzz_numbers.py,
test_fuzz_splice.py) and ``benchmarks/fuzz.py``. Every generator takes an
``rng`` with the interface of :class:`random.Random` (``random``,
``randrange``, ``choice``) -- a seeded ``Random`` in the benchmark,
hypothesis' ``st.randoms()`` in the tests -- and returns program text.

* :func:`grammar_program` expands lang/lig.lark (tests/fuzzgrammar.py);
* :func:`number_program` fills the numeric slots of small complete
  programs with extreme values: 1e308, 1e309, -0.0, 5e-324, 2**63,
  401- and 5,000-digit integers, infinities and NaNs made by arithmetic;
* :func:`splice_program` splices lines and blocks of examples/*.lig and
  stdlib/*.lig into each other at random places;
* :func:`wild_program` is a grammar-expanded program with extreme numbers.

Cases must stay fast: the generators keep scenes a few ticks long and DO
loops a few trips long. The one exception is on purpose: an extreme value
may land in a scene length or a loop bound; the loop templates stop the
program after a few trips, so that only an eager implementation (one that
builds every loop value first) runs out of time or memory.
"""

from __future__ import annotations

import functools
import os
import re

from fuzzgrammar import grammar_program

__all__ = ["EXTREMES", "GENERATORS", "TEMPLATES", "grammar_program", "number_program", "splice_program", "wild_program"]

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# ================================================================ extreme numbers

_BIG = "1" + "0" * 400  # 401 digits
#: Values for a numeric slot: literals, and expressions that make inf, NaN, huge integers.
EXTREMES = [
    "1e308",
    "1e309",
    "1E400",
    "-0.0",
    "0.0",
    "0",
    "5e-324",
    "4.9e-324",
    "1e-320",
    "2.2250738585072014e-308",
    "9223372036854775808",
    "9223372036854775807",
    "-9223372036854775809",
    "18446744073709551616",
    "2147483648",
    "4294967296",
    "1e18",
    "1000000000000",
    "1e300",
    "-1e308",
    "1e309°",
    "1e308°",
    "1e-300",
    _BIG,
    "9" * 401,
    "-" + _BIG,
    "1" * 4301,
    "1" * 5000,
    "1e308*10",
    "-(1e308*10)",
    "1e308*10-1e308*10",
    "0*(1e308*10)",
    "1e308+1e308",
    "1e308*1e308",
    "1/(1e308*10)",
    "-5e-324",
    f"{_BIG} / 3",
    f"{_BIG} MOD 7",
    f"{_BIG} * {_BIG}",
    f"({_BIG}) * 1.5",
    "INT(1e308)",
    "NINT(1e300)",
    "INT(1e308*10)",
    "NINT(1e308*10-1e308*10)",
    "(1e308*10) MOD 7",
    "7 MOD (1e308*10)",
    "COS(1e308*10)",
    "SIN(1e308)",
    "TAN(90)",
    "SQRT(1e308*10)",
    "EXP(1000)",
    "EXP(709.7)",
    "LOG(5e-324)",
    "ABS(1e308*10-1e308*10)",
    "MAX(1e308*10, 0)",
    "MIN(1e308*10-1e308*10, 1)",
    "NORM((1e200, 1e200, 1e200))",
    "NORM((1e308*10, 0, 0))",
    f"REAL({_BIG})",
    "REAL(1e309)",
    "DOT((1e200, 1e200, 1e200), (1e200, 1e200, 1e200))",
    "X(CROSS((1e308, 0, 0), (0, 1e308, 0)))",
    "-1e309",
    "1e-400",
    "1e308*-10",
    "-(1e308*10)+(1e308*10)",
    "1e-100",
    "1e-101",
    "0.5e-100",
    # Either side of the language's limits (lang/numbers.py): geometry, angles, keyframes, scene length.
    "1e12",
    "1000000000000.5",
    "999999999999.9999",
    "1e9",
    "1000000001",
    "1000000",
    "1000001",
    "10000000",
    "10000001",
]

# Slots: «N:default» a number, «V:(x, y, z)» a vector, «P:(lo, hi)» a pair of extremes.
_SLOT = re.compile(r"«([NVP]):([^»]*)»")

_FIGURE = """\
      GRAPHICAL G1, G2, G3
      MODEL M
      MOTION W
      G1 :- BOX AT «V:(0.0, 0.0, 0.0)», WIDTH «N:1.0», HEIGHT «N:0.5», DEPTH «N:0.5», LIGHTNESS «N:50.0»
      G2 :- BOX WIDTH «N:0.2», HEIGHT «N:1.0», DEPTH «N:0.2»
      G3 :- BOX WIDTH «N:0.3», HEIGHT «N:0.3», DEPTH «N:0.3»
      M :- JOINT «N:1», G1, «V:(0.0, 0.25, 0.0)», G2, «V:(0.0, 0.0, 0.0)», «P:(0°, 0°)», «P:(0°, 0°)», «P:(-90°, 90°)»
      M :- JOINT «N:2», M, «V:(0.0, 1.0, 0.0)», G3, «V:(0.0, 0.0, 0.0)», «P:(-45°, 45°)», «P:(0°, 0°)», «P:(0°, 0°)»
      W[«N:1», «N:1»] = FRAME «N:0» POSITION «V:(0.0, 0.0, 0.0)»
      W[«N:1», «N:2»] = FRAME «N:2» POSITION «V:(0.0, 0.0, 45.0)» INTERPOLATE ACCDCC
"""
_SCENE = """\
      INITIALIZE SCENE «N:1»
          VIEW POINT = «V:(0.0, 0.5, -6.0)»
          VIEW WIDTH = «N:4.0»
          BACKGROUND G3
      STARTSCENE LENGTH «N:2»
          ANIMATE M FROM «N:0» TO «N:1» USING W
      ENDSCENE
"""

#: Complete programs with numeric slots (each runs as it stands, slots at their defaults).
TEMPLATES = {
    "arithmetic": """\
      REAL S, T
      INTEGER N
      VECTOR P
      S = «N:1.5»
      N = «N:3»
      T = S * «N:2» + «N:0.5»
      P = «V:(1.0, 2.0, 3.0)»
      PRINT S, T, N, P
      PRINT REAL(«N:2»), INT(«N:2.5»), NINT(«N:2.5»), MOD(«N:7», «N:3»), «N:7» MOD «N:3», «N:1» / «N:3»
      PRINT COS(«N:30»), SIN(«N:30»), TAN(«N:30»), SQRT(«N:4»), EXP(«N:1»), LOG(«N:2»), ABS(«N:-2»)
      PRINT ATAN2(«N:1», «N:1»), ASIN(«N:0.5»), ACOS(«N:0.5»), ATAN(«N:1»), MIN(«N:1», «N:2»), MAX(«N:1», «N:2»)
      PRINT NORM(«V:(1.0, 2.0, 2.0)»), DOT(«V:(1.0, 0.0, 0.0)», P), CROSS(P, «V:(0.0, 1.0, 0.0)»), X(P) + «N:1»
      N = INT(«N:2.5») + NINT(«N:0.5») + «N:1»
      IF «N:1» < «N:2» AND S >= «N:0» THEN PRINT 'less'
      IF NOT (T = «N:3.5») OR N <> «N:3» THEN BEGIN
          S = S - «N:1»
      END
      P = P * «N:2» + P / «N:4»
      PRINT S, N, P
""",
    "figure": _FIGURE
    + """\
      G1 :- G1 <TRANS «V:(0.0, -0.5, 0.0)», ROT X «N:10», ROT Y «N:0», SCALE «N:1.0», LIGHTNESS «N:60»>
      G3 :- G1 + G2 <ROT Z «N:15»>
      M :- M <TRANS «V:(0.0, 0.0, 0.0)», ROT Z «N:0», SCALE MODEL «N:1.0», SCALE EXTREMES «N:1.0»>
      M :- M <TRANS JOINTS BY «N:0», SCALE «N:1.0»>
      FIGURE M MAIN JOINT «N:1»
"""
    + _SCENE
    + """\
      INITIALIZE SCENE 2
          VIEW POINT = (0.0, 0.5, -6.0)
          VIEW WIDTH = 4.0
      STARTSCENE LENGTH «N:2» SAMEFRAME «N:2»
          ANIMATE M FROM «N:0» TO «N:2» USING W
      ENDSCENE
      SHOOTSCENES
""",
    "motion": _FIGURE
    + """\
      MOTION W2, W3, W4
      STARTMOTION W2
        JOINT «N:2» POSITION «N:0.0», «N:0.0», «N:10.0»
          FRAME «N:2» POSITION «N:0.0», «N:0.0», «N:30.0» INTERPOLATE LINEAR
          FRAME «N:4» POSITION «V:(0.0, 0.0, 0.0)»
        ENDJOINT
      ENDMOTION
      W3 = «N:2» * W + W2 <SCALE FRAMES «N:0.5»>
      W3 = STRIP W3, «N:1», «N:2»
      W4 := SYNCHRONIZE W, W2 <SCALE EXTREMES «N:1.0»>
      W4 = W4 <SCALE FRAMES «N:-1»>
      PRINT LEN(W3), LEN(W4)
      INITIALIZE SCENE 1
          VIEW POINT = (0.0, 0.5, -6.0)
          VIEW WIDTH = 4.0
      STARTSCENE LENGTH «N:3»
          ANIMATE M FROM «N:0» TO «N:2» USING W3 REPEAT
      ENDSCENE
      INITIALIZE SCENE 2
          VIEW POINT = (0.0, 0.5, -6.0)
          VIEW WIDTH = 4.0
      STARTSCENE LENGTH 2
          ANIMATE M FROM «N:1» TO «N:2» USING W4
      ENDSCENE
      SHOOTSCENES
""",
    "loops": """\
      INTEGER N, I
      REAL R
      MOTION W
      N = 0
      DO 10 I = «N:1», «N:3»
         N = N + 1
         W[1, I] = FRAME I POSITION (0.0, 0.0, 10.0)
         IF N > 3 THEN STOP
10    CONTINUE
      DO 20 R = «N:0.5», «N:2.5», «N:0.5»
         N = N + 1
         IF N > 8 THEN STOP
20    CONTINUE
      DO 30 I = «N:3», «N:1», «N:-1»
         N = N + 1
         IF N > 12 THEN STOP
30    CONTINUE
      PRINT N, R, LEN(W)
""",
    "reach": """\
      GRAPHICAL UPPER, LOWER, BASE
      MODEL ARM
      MOTION R, R2
      VECTOR SHIFT
      UPPER :- BOX AT (0, -0.5, 0), WIDTH 0.1, HEIGHT 1, DEPTH 0.1
      LOWER :- BOX AT (0, -0.5, 0), WIDTH 0.1, HEIGHT 1, DEPTH 0.1
      BASE :- BOX WIDTH 0.2, HEIGHT 0.2, DEPTH 0.2
      STARTMODEL ARM
        JOINT 1, BASE, (0, 0, 0), UPPER, (0, 0, 0), (0, 0), (0, 0), «P:(-170, 170)»
        JOINT 2, UPPER, «V:(0, -1, 0)», LOWER, (0, 0, 0), (0, 0), (0, 0), «P:(0, 160)»
      ENDMODEL
      STARTREACH R MODEL ARM FRAME «N:4» INTERPOLATE ACCDCC
        GOAL LOWER AT «V:(0, -1, 0)» TO «V:(1.2, -0.9, 0)» WEIGHT «N:10»
        TOLERANCE «N:0.0001»
        ITERATIONS «N:50»
      ENDREACH
      STARTREACH R2 MODEL ARM FRAME «N:3» FROM R
        GOAL LOWER ON PLANE «V:(0, -1.5, 0)» NORMAL «V:(0, 1, 0)»
        GOAL UPPER AXIS «V:(0, 1, 0)» ALONG «V:(1, 1, 0)» WEIGHT «N:0.5»
        MOVE JOINTS «N:1», «N:2»
        TRANSLATE INTO SHIFT
      ENDREACH
      STARTREACH R3 MODEL ARM FRAME «N:2» FROM R2
        GOAL JOINT 2 TO «V:(0.5, -1.0, 0)»
        MOVE CHAIN «N:2»
        SOLVER CCD
        ITERATIONS «N:20»
      ENDREACH
      INITIALIZE SCENE 1
          VIEW POINT = (0.0, -0.5, -6.0)
          VIEW WIDTH = 4.0
      STARTSCENE LENGTH 2
          ANIMATE ARM FROM 0 TO «N:1» USING R + R2 + R3
      ENDSCENE
      SHOOTSCENES
""",
    "primitive": """\
      PRIMITIVE PEG
      REAL SIZE, LIGHT
      VECTOR CENTRE
      PEG ::= 'PEG' [ 'AT' CENTRE ',' ] <CENTRE = «V:(0.0, 0.0, 0.0)»>
              'SIZE' SIZE [ ',' 'LIGHTNESS' LIGHT ]<LIGHT = «N:40.0»> ;
      DRAW WITH <LIGHTNESS LIGHT * «N:1.0»>
      DRAW POLY FROM CENTRE TO CENTRE + (SIZE, 0.0, 0.0) TO «V:(0.0, 1.0, 0.0)» TO CENTRE
      RETURN
      END
      LOAD CYLINDER, SPHERE FROM 'shapes'
      GRAPHICAL G, H, C
      MODEL M
      MOTION W
      G :- PEG AT «V:(0.0, 0.0, 0.0)», SIZE «N:1.0», LIGHTNESS «N:70.0»
      H :- CYLINDER RADIUS «N:0.2», HEIGHT «N:1.0», SIDES «N:6»
      C :- SPHERE RADIUS «N:0.3», SIDES «N:6», LIGHTNESS «N:20»
      M :- JOINT 1, G, (0.0, 0.0, 0.0), H, «V:(0.0, 0.5, 0.0)», (0°, 0°), (0°, 0°), (-90°, 90°)
      W[1, 1] = FRAME 0 POSITION (0.0, 0.0, 0.0)
      W[1, 2] = FRAME 2 POSITION (0.0, 0.0, «N:45.0»)
      INITIALIZE SCENE 1
          VIEW POINT = (0.0, 0.5, -6.0)
          VIEW WIDTH = 4.0
          BACKGROUND C <TRANS «V:(1.0, 0.0, 0.0)»>
      STARTSCENE LENGTH 2
          ANIMATE M FROM 0 TO 1 USING W
      ENDSCENE
      SHOOTSCENES
""",
}
TEMPLATES["scene"] = _FIGURE + _SCENE + "      SHOOTSCENES\n"
TEMPLATES["library"] = """\
      LOAD HUMANOID, WALK, WAVE FROM 'humanoid'
      LOAD ROBOT, ROBOT_WALK FROM 'robot'
      MODEL H, R
      MOTION M1, M2
      H :- HUMANOID <SCALE MODEL «N:1.0», TRANS «V:(0.0, 0.0, 0.0)»>
      R :- ROBOT <SCALE EXTREMES «N:1.0», ROT Y «N:90»>
      M1 = STRIP «N:2» * WALK, «N:1», «N:31», «N:32»
      M2 := SYNCHRONIZE M1, WAVE <SCALE FRAMES «N:1»>
      FIGURE H MAIN LINK R_FOOT
      INITIALIZE SCENE 1
          VIEW POINT = «V:(0.0, 1.0, 8.0)»
          VIEW WIDTH = «N:5.0»
      STARTSCENE LENGTH «N:2» SAMEFRAME «N:1»
          ANIMATE H FROM «N:0» TO «N:1» USING M2
          ANIMATE R FROM «N:0» TO «N:1» USING ROBOT_WALK REPEAT
          H :- H <TRANS «V:(0.05, 0.0, 0.0)»>
      ENDSCENE
      SHOOTSCENES
"""


def slots(template: str) -> list:
    """The slots of a template, in order: ``[(kind, default), ...]``."""
    return _SLOT.findall(template)


def fill(template: str, values: dict) -> str:
    """The template with slot ``i`` replaced by ``values[i]`` and every other slot by its default."""
    counter = iter(range(1 << 30))

    def one(m):
        i = next(counter)
        return values.get(i, m.group(2))

    return _SLOT.sub(one, template)


def extreme(rng, kind: str) -> str:
    """An extreme value for a slot of ``kind`` (N, V or P): an extreme number, or a tuple holding some."""

    def number():
        v = rng.choice(EXTREMES)
        return v if re.fullmatch(r"[0-9.eE+°]+", v) else f"({v})"

    if kind == "N":
        return number()
    n = 3 if kind == "V" else 2
    parts = ["0.0"] * n
    for _ in range(1 + rng.randrange(n)):
        parts[rng.randrange(n)] = number()
    return "(" + ", ".join(parts) + ")"


def number_program(rng) -> str:
    """A template (see :data:`TEMPLATES`) with one to three slots given extreme values."""
    name = rng.choice(sorted(TEMPLATES))
    template = TEMPLATES[name]
    found = slots(template)
    values = {}
    for _ in range(1 + rng.randrange(3)):
        i = rng.randrange(len(found))
        values[i] = extreme(rng, found[i][0])
    return fill(template, values)


# ================================================================ splices

_OPENERS = re.compile(r"(?i)^[ \t*]*(STARTMODEL|STARTMOTION|STARTREACH|INITIALIZE|PRIMITIVE|BEGIN)\b")
_CLOSERS = {
    "STARTMODEL": "ENDMODEL",
    "STARTMOTION": "ENDMOTION",
    "STARTREACH": "ENDREACH",
    "INITIALIZE": "ENDSCENE",
    "PRIMITIVE": "END",
    "BEGIN": "END",
}
_DO = re.compile(r"(?i)^[ \t]*DO[ \t]+(\d+)")
_LENGTH = re.compile(r"(?i)(\bLENGTH[ \t]+)(\d+)")
#: Longest scene a splice keeps: the examples' long scenes would make cases slow.
MAX_LENGTH = 3


@functools.lru_cache(maxsize=1)
def corpus() -> tuple:
    """``((name, lines), ...)`` of every example and standard library, sorted by name."""
    out = []
    for folder in ("examples", "stdlib"):
        path = os.path.join(ROOT, folder)
        for name in sorted(os.listdir(path)):
            if name.endswith(".lig"):
                with open(os.path.join(path, name), encoding="utf-8") as fh:
                    out.append((f"{folder}/{name}", tuple(fh.read().split("\n"))))
    return tuple(out)


def _is_code(line: str) -> bool:
    return bool(line.strip()) and line[:1] not in ("C", "c")


def _continues(prev: str, line: str) -> bool:
    """Does ``line`` continue the statement of code line ``prev`` (an open parenthesis, a trailing comma...)?"""
    code = re.sub(r"\{[^}]*\}|'[^'\n]*'", "", prev).rstrip()
    return (
        code.count("(") > code.count(")")
        or code[-1:] in (",", "(", "+", "-", "*", "/", "=", "<")
        or re.match(r"(?i)\s*(TO|INTERPOLAT\w*)\b", line) is not None
    )


@functools.cache
def units(lines: tuple) -> tuple:
    """Spans ``(start, end)`` worth moving: whole statements, blocks, DO loops with their CONTINUE."""
    spans = []
    i = 0
    while i < len(lines):
        if not _is_code(lines[i]):
            i += 1
            continue
        j, last = i + 1, i
        while j < len(lines) and (not _is_code(lines[j]) or _continues(lines[last], lines[j])):
            if _is_code(lines[j]):
                last = j
            elif not lines[j].strip() and j + 1 < len(lines) and not _is_code(lines[j + 1]):
                break
            j += 1
        spans.append((i, last + 1))
        i = last + 1
    for i, line in enumerate(lines):
        m = _OPENERS.match(line)
        closer = _CLOSERS.get(m.group(1).upper()) if m else None
        d = _DO.match(line)
        if closer:
            end = re.compile(rf"(?i)^[ \t*]*{closer}\b")
        elif d:
            end = re.compile(rf"^[ \t]*{d.group(1)}[ \t]+CONTINUE\b", re.IGNORECASE)
        else:
            continue
        j = next((j for j in range(i + 1, len(lines)) if end.match(lines[j])), None)
        if j is not None:
            spans.append((i, j + 1))
    return tuple(spans)


def splice_program(rng) -> str:
    """One to three splices of example and library code into one of them.

    A splice takes a span of lines from one file -- usually a whole
    statement, block or loop, now and then a few lines in a row -- and puts
    it into another between two statements (now and then at any line), or
    in place of one of its statements or blocks. Scene lengths above
    :data:`MAX_LENGTH` are cut down.
    """
    files = corpus()
    _, lines = files[rng.randrange(len(files))]
    lines = list(lines)
    for _ in range(1 + rng.randrange(3)):
        _, donor = files[rng.randrange(len(files))]
        spans = units(donor)
        if rng.random() < 0.85 and spans:
            a, b = spans[rng.randrange(len(spans))]
        else:
            a = rng.randrange(len(donor))
            b = min(len(donor), a + 1 + rng.randrange(6))
        piece = list(donor[a:b])
        own = units(tuple(lines))
        r = rng.random()
        if own and r < 0.35:
            c, d = own[rng.randrange(len(own))]
            lines[c:d] = piece
        else:
            at = own[rng.randrange(len(own))][rng.randrange(2)] if own and r < 0.85 else rng.randrange(len(lines) + 1)
            lines[at:at] = piece
    text = "\n".join(lines)
    return _LENGTH.sub(lambda m: m.group(1) + str(min(int(m.group(2)), MAX_LENGTH)), text)


def wild_program(rng) -> str:
    """A grammar-expanded program in which a quarter of the numbers are extreme (:data:`EXTREMES`)."""
    wild = [v if re.fullmatch(r"[0-9.eE+°]+", v) else f"({v})" for v in EXTREMES]
    return grammar_program(rng, wild, 0.25)


#: Sizes of deep and long constructs: around the nesting limit (100) and far past it.
SIZES = (1, 2, 50, 99, 100, 101, 102, 200, 500, 1000, 3000)

_BOX = "      GRAPHICAL G\n      G :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0\n"


def _deep_parens(n: int) -> str:
    return "      REAL X\n      X = " + "(" * n + "1.5" + ")" * n + "\n      PRINT X\n"


def _deep_negations(n: int) -> str:
    return "      REAL X\n      X = " + "-" * n + "1.5\n      PRINT X\n"


def _long_sum(n: int) -> str:
    return "      INTEGER N\n      N = " + " + ".join(["1"] * n) + "\n      PRINT N\n"


def _deep_ifs(n: int) -> str:
    opened = "".join(f"{'  ' * i}      IF {i} < {n} THEN BEGIN\n" for i in range(n))
    closed = "".join(f"{'  ' * i}      END\n" for i in reversed(range(n)))
    return "      INTEGER N\n      N = 0\n" + opened + "      N = N + 1\n" + closed + "      PRINT N\n"


def _deep_loops(n: int) -> str:
    names = [f"I{i}" for i in range(n)]
    head = "      INTEGER " + ", ".join(names) + "\n"
    opened = "".join(f"      DO {10 + i} {v} = 1, 1\n" for i, v in enumerate(names))
    closed = "".join(f" {10 + i}   CONTINUE\n" for i in reversed(range(n)))
    return head + opened + closed


def _modifier_chain(n: int) -> str:
    return _BOX + "      G :- G" + " <SCALE 1.0>" * n + "\n"


def _joint_chain(n: int) -> str:
    return (
        _BOX
        + "      MODEL M\n      INTEGER I\n"
        + "      M :- JOINT 0, G, (0.0, 1.0, 0.0), G, (0.0, 0.0, 0.0), (-10, 10)\n"
        + f"      DO 10 I = 1, {n}\n"
        + "        M :- JOINT I, M, (0.0, 1.0, 0.0), G, (0.0, 0.0, 0.0), (-10, 10)\n"
        + " 10   CONTINUE\n"
    )


def _motion_sum(n: int) -> str:
    return (
        "      MOTION W, S\n      W[1, 1] = FRAME 0 POSITION (0.0, 0.0, 0.0)\n"
        "      W[1, 2] = FRAME 2 POSITION (0.0, 0.0, 45.0)\n      S = " + " + ".join(["W"] * n) + "\n"
    )


def _many_statements(n: int) -> str:
    return "      INTEGER N\n      N = 0\n" + "      N = N + 1\n" * n + "      PRINT N\n"


def _long_line(n: int) -> str:
    return "      INTEGER " + ", ".join(f"V{i}" for i in range(n)) + "\n"


#: Deep and long constructs, each built for a size.
DEEP = (
    _deep_parens,
    _deep_negations,
    _long_sum,
    _deep_ifs,
    _deep_loops,
    _modifier_chain,
    _joint_chain,
    _motion_sum,
    _many_statements,
    _long_line,
)


def deep_program(rng) -> str:
    """One or two deep or long constructs (nesting, chains, sums, loops) of a size around or past the limits.

    Now and then the construct is spliced into a real program, so that it
    meets scenes and models.
    """
    parts = [DEEP[rng.randrange(len(DEEP))](SIZES[rng.randrange(len(SIZES))]) for _ in range(1 + rng.randrange(2))]
    text = "".join(parts)
    if rng.random() < 0.3:
        files = corpus()
        _, lines = files[rng.randrange(len(files))]
        text = text + "\n".join(lines) + "\n"
    return text


#: Characters that are not plain ASCII letters: letters of other scripts, marks, spaces, controls, emoji.
UNICODE = (
    "é",
    "ß",
    "Ж",
    "ж",
    "Ω",
    "ǅ",
    "ﬁ",
    "Ａ",
    "１",
    "٣",
    "\u0301",  # a combining acute accent
    "\u00a0",  # no-break space
    "\u2003",  # em space
    "\u200b",  # zero-width space
    "\u202e",  # right-to-left override
    "\u2028",  # line separator
    "\ufeff",  # byte order mark
    "\x85",  # next line (C1)
    "\x1b[31m",  # a terminal escape
    "\x00",
    "\t",
    "\r",
    "\x0c",
    "😀",
    "🏳️‍🌈",
    "\ud800",  # a lone surrogate (written with surrogatepass)
    "°",
    "′",
    "−",  # the minus sign, not a hyphen
    "İ",
    "ı",
)


def unicode_program(rng) -> str:
    """A real or spliced program with one to four non-ASCII characters or sequences put in.

    Each goes into a name (after or inside a word), a quoted string, a
    comment, between tokens or at the start of the file.
    """
    text = splice_program(rng) if rng.random() < 0.5 else "\n".join(corpus()[rng.randrange(len(corpus()))][1])
    for _ in range(1 + rng.randrange(4)):
        piece = UNICODE[rng.randrange(len(UNICODE))]
        where = rng.random()
        if where < 0.1:
            at = 0
        else:
            words = [m.end() for m in re.finditer(r"[A-Za-z_][A-Za-z0-9_]*|'|\{|\s", text)]
            at = words[rng.randrange(len(words))] if words else 0
            if where < 0.4 and words:
                at = max(0, at - 1 - rng.randrange(3))
        text = text[:at] + piece + text[at:]
    return text


#: The generators by name, as the benchmark and the tests call them.
GENERATORS = {
    "grammar": grammar_program,
    "numbers": number_program,
    "splice": splice_program,
    "wild": wild_program,
    "deep": deep_program,
    "unicode": unicode_program,
}
