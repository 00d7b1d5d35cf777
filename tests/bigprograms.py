"""Big generated programs, for the parser's scale tests and benchmarks/compile.py."""


def short_lines(n: int) -> str:
    """``n`` short assignment lines (``X17 = 17``) over a hundred variables: issue 14's stress shape."""
    return "".join(f"X{i % 100} = {i}\n" for i in range(n))


def mixed_lines(n: int) -> str:
    """``n`` lines, every one a statement: arithmetic, vectors, keyframes, IF, DO, JOINT (about 15 tokens a line)."""
    out = ["REAL X, Y", "VECTOR V", "MOTION M", "GRAPHICAL G", "MODEL A", "G :- BOX WIDTH 1, HEIGHT 2, DEPTH 0.5"]
    i = 0
    while len(out) + 8 <= n:  # whole blocks only: a cut one would leave a DO open
        i += 1
        out += [
            f"X = X + {i}.5 * (Y - 2) / 3",
            f"V = (X, Y, {i}) + V * 0.5",
            f"M[{i % 20 + 1}, 1] := FRAME {i % 50 + 1} POSITION X, 0, {i % 90}",
            f"IF X > {i} THEN Y = Y + 1 ELSE Y = Y - 1",
            f"DO {i + 10} J = 1, 3",
            "  Y = Y + J MOD 2",
            f"{i + 10} CONTINUE",
            f"A :- JOINT {i % 30 + 1}, G, (0, 1, 0), G, (0, -1, 0), (-45, 45), (0, 0), (-90, {i % 90})",
        ]
    out += ["Y = Y + 1"] * (n - len(out))
    return "\n".join(out[:n]) + "\n"
