"""Tables of numbers as text, fast: fixed-point columns built with numpy, not one format call per number.

BVH motion data and keyframe listings are millions of numbers; Python's
``%`` formatting costs about as much as everything else an export does.
Here each column's digits are cut out of scaled integers for all rows at
once and laid into a byte buffer.
"""

from __future__ import annotations

import numpy as np

__all__ = ["format_rows"]

# Above this a number's scaled integer would lose digits in float64.
_EXACT = 2.0**52


def format_rows(values, decimals, sep: str = " ", prefix: str = "", suffix: str = "\n", columns_prefix=None) -> bytes:
    """Format a table of finite numbers in fixed-point notation, one line per row.

    Parameters
    ----------
    values : array_like, shape (N, C)
    decimals : int or sequence of C ints
        Digits after the point per column (0: an integer, no point).  Each
        number is rounded to that many decimals; ``-0`` is written ``0``.
    sep : str
        Between columns (unless ``columns_prefix`` is given).
    prefix, suffix : str
        Before the first and after the last column of every row.
    columns_prefix : sequence of C str, optional
        Text before each column instead of ``prefix`` / ``sep``.

    Returns
    -------
    bytes
        ASCII.  Columns are right-aligned to a common width, padded with
        spaces, so whitespace-separated readers see exactly the numbers.

    Raises
    ------
    ValueError
        If a value is not finite.
    """
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 2:
        raise ValueError(f"values must be a 2-D table, not shape {v.shape}")
    N, C = v.shape
    if not np.isfinite(v).all():
        raise ValueError("cannot write a number that is not finite")
    dec = np.broadcast_to(np.asarray(decimals, dtype=np.int64), (C,))
    if columns_prefix is None:
        columns_prefix = [prefix] + [sep] * (C - 1)
    pieces: list = []
    for c in range(C):
        pieces.append(_literal(columns_prefix[c], N))
        pieces.append(_column(v[:, c], int(dec[c])))
    pieces.append(_literal(suffix, N))
    if N == 0:
        return b""
    return np.concatenate(pieces, axis=1).tobytes()


def _literal(text: str, n: int) -> np.ndarray:
    raw = np.frombuffer(text.encode("ascii"), dtype=np.uint8)
    return np.broadcast_to(raw, (n, len(raw)))


def _column(x: np.ndarray, dec: int) -> np.ndarray:
    """One column's characters, shape (N, width)."""
    mag = np.rint(np.abs(x) * 10.0**dec)
    if len(x) and mag.max() >= _EXACT:
        return _column_slow(x, dec)
    ints = mag.astype(np.int64)
    neg = (x < 0) & (ints != 0)
    whole = ints // 10**dec
    top = int(whole.max()) if len(x) else 0
    n_int = len(str(top))
    n_dig = n_int + dec
    width = 1 + n_int + (dec + 1 if dec else 0)
    powers = 10 ** np.arange(n_dig - 1, -1, -1, dtype=np.int64)  # most significant first
    digits = (ints[:, None] // powers) % 10  # (N, n_dig)
    # The integer part's own length per row (at least one digit).
    own = np.ones(len(x), dtype=np.int64)
    for k in range(1, n_int):
        own += whole >= 10**k
    chars = np.full((len(x), width), ord(" "), dtype=np.uint8)
    # Integer digits occupy columns 1 .. n_int, decimals after the point.
    lead = n_int - own  # leading places to blank
    idx = np.arange(n_int)
    int_chars = (digits[:, :n_int] + ord("0")).astype(np.uint8)
    int_chars[idx[None, :] < lead[:, None]] = ord(" ")
    chars[:, 1 : 1 + n_int] = int_chars
    if dec:
        chars[:, 1 + n_int] = ord(".")
        chars[:, 2 + n_int :] = (digits[:, n_int:] + ord("0")).astype(np.uint8)
    rows = np.flatnonzero(neg)
    chars[rows, lead[rows]] = ord("-")
    return chars


def _column_slow(x: np.ndarray, dec: int) -> np.ndarray:
    """Huge numbers: Python's own formatting, padded to one width."""
    text = [f"{v:.{dec}f}" for v in x.tolist()]
    text = ["0" + t[2:] if t.startswith("-0") and not t.strip("-0.") else t for t in text]
    width = max(len(t) for t in text) + 1
    return np.frombuffer("".join(t.rjust(width) for t in text).encode("ascii"), dtype=np.uint8).reshape(len(x), width)
