"""Image files: PNG, greyscale or colour, encoded fast and deterministically.

Writing is atomic (:class:`liganimate.runtime.files.AtomicWriter`): a
temporary file in the destination's folder, renamed over the destination
only when complete, so a reader never sees a half-written file and a
failed write leaves any earlier file intact.  The GIF and MP4 writers are
in :mod:`.video`.
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

from liganimate.runtime.errors import RenderError
from liganimate.runtime.files import AtomicWriter

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# Chosen by measurement on flat-shaded 640x480 frames of five figures
# (filters None/Sub/Up x zlib levels 1-6 x default/RLE strategy): the Up
# filter turns the many rows equal to the row above into zeros, and RLE at
# level 1 then gives the smallest files of all (4.5 kB, as small as level 6
# unfiltered) in 0.8 ms, where level 6 takes 2.1 ms.  zlib's memory level
# 4 (rather than 9) then takes 0.46 ms instead of 0.73 on the 1,000 frames
# of benchmarks/scene.py, and gives slightly smaller files (3.0 kB, not
# 3.1): with RLE, the larger buffers only cost time to set up.  Splicing
# in cached blocks for runs of rows equal to the row above (_zlib_rows)
# then brings it to 0.29 ms, at 3.2 kB.
_PNG_LEVEL = 1
_PNG_STRATEGY = zlib.Z_RLE
_PNG_MEMLEVEL = 4
_PNG_FILTER_UP = 2


def check_image(img) -> np.ndarray:
    """``img`` as an array of shape (H, W) (grey levels) or (H, W, 3) (RGB), uint8; else a RenderError."""
    a = np.asarray(img)
    if a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] != 3) or a.shape[0] < 1 or a.shape[1] < 1:
        raise RenderError(
            f"An image must be an array of grey levels (H, W) or of colours (H, W, 3), not shape {a.shape}."
        )
    if a.dtype != np.uint8:
        raise RenderError(f"An image must hold 8-bit levels (uint8), not {a.dtype}.")
    return a


def encode_png(img) -> bytes:
    """Encode a greyscale or colour image as PNG bytes.

    The output depends only on the pixels: no timestamp, gamma or other
    ancillary chunk is written.

    Parameters
    ----------
    img : array_like, shape (H, W) or (H, W, 3), uint8
        Grey levels, or red, green and blue levels; row 0 at the top.

    Returns
    -------
    bytes
        A complete PNG file (8-bit greyscale, colour type 0, or 8-bit RGB,
        colour type 2; not interlaced).
    """
    a = check_image(img)
    H, W = a.shape[:2]
    colour = a.ndim == 3
    if colour:
        a = a.reshape(H, W * 3)  # Up filters each byte against the byte above: channels need no care
    rows = np.empty((H, a.shape[1] + 1), dtype=np.uint8)
    rows[:, 0] = _PNG_FILTER_UP
    rows[0, 1:] = a[0]  # Up on the first row sees a row of zeros
    np.subtract(a[1:], a[:-1], out=rows[1:, 1:])  # uint8 arithmetic wraps mod 256, as PNG wants
    header = struct.pack(">IIBBBBB", W, H, 8, 2 if colour else 0, 0, 0, 0)
    data = _zlib_rows(rows)
    return b"".join([_PNG_SIGNATURE, _chunk(b"IHDR", header), _chunk(b"IDAT", data), _chunk(b"IEND", b"")])


# A run of at least this many rows equal to the row above is not compressed
# again but spliced in from a cache (see _zlib_rows).
_BLANK_RUN = 8


def _zlib_rows(rows: np.ndarray) -> bytes:
    """The zlib stream of filtered PNG rows (H, W + 1), spliced for speed.

    With the Up filter, a row equal to the row above filters to zeros (a
    "blank" row), and in flat-shaded frames most rows are: background above
    and below the figures.  Runs of blank rows are not deflated every time:
    their deflate blocks, ended by a full flush (which aligns to a byte and
    forgets the history), are computed once per width and length and
    spliced between the blocks of the other rows, each stretch of which is
    likewise ended by a full flush.  The Adler-32 checksum runs over the
    other rows and is advanced over blank runs by formula.  The stream is a
    valid zlib stream for any pixels, and depends on the pixels alone.
    """
    H, W1 = rows.shape
    blank = rows[:, 1:].max(axis=1, initial=0) == 0
    if H > 1 and rows.shape[1] > 1:
        # Runs of blank rows: [start, end) pairs at least _BLANK_RUN long.
        edges = np.flatnonzero(np.diff(np.concatenate([[False], blank, [False]]).astype(np.int8)))
        runs = [(int(b), int(e)) for b, e in zip(edges[0::2], edges[1::2]) if e - b >= _BLANK_RUN]
    else:
        runs = []
    comp = zlib.compressobj(_PNG_LEVEL, zlib.DEFLATED, -15, _PNG_MEMLEVEL, _PNG_STRATEGY)
    out = [b"\x78\x01"]  # zlib header: deflate, 32 kB window, fastest
    adler = 1
    at = 0
    for start, end in runs:
        if start > at:
            out.append(comp.compress(rows[at:start].data))
            out.append(comp.flush(zlib.Z_FULL_FLUSH))
            adler = zlib.adler32(rows[at:start].data, adler)
        out.append(_blank_blocks(W1, end - start))
        adler = _adler32_blank(adler, W1, end - start)
        at = end
    if at < H:
        out.append(comp.compress(rows[at:].data))
        adler = zlib.adler32(rows[at:].data, adler)
    out.append(comp.flush(zlib.Z_FINISH))
    out.append(struct.pack(">I", adler))
    return b"".join(out)


def _adler32_blank(adler: int, width: int, count: int) -> int:
    """Adler-32 continued over ``count`` blank rows: the Up filter byte, then ``width - 1`` zeros.

    Each row adds 2 to A, then A (now A + 2) to B once per byte of the row:
    over k rows, A grows by 2k and B by ``width (k A + k (k + 1))``.
    """
    a, b = adler & 0xFFFF, adler >> 16
    b = (b + width * (count * a + count * (count + 1))) % 65521
    a = (a + 2 * count) % 65521
    return (b << 16) | a


_BLANK_CACHE: dict = {}


def _blank_blocks(width: int, count: int) -> bytes:
    """Deflate blocks (byte-aligned, history-free, not final) of ``count`` blank rows of ``width`` bytes."""
    parts = []
    bit = 1
    while count:
        if count & bit:
            key = (width, bit)
            block = _BLANK_CACHE.get(key)
            if block is None:
                row = bytes([_PNG_FILTER_UP]) + bytes(width - 1)
                comp = zlib.compressobj(_PNG_LEVEL, zlib.DEFLATED, -15, _PNG_MEMLEVEL, _PNG_STRATEGY)
                block = comp.compress(row * bit) + comp.flush(zlib.Z_FULL_FLUSH)
                if len(_BLANK_CACHE) > 256:
                    _BLANK_CACHE.clear()
                _BLANK_CACHE[key] = block
            parts.append(block)
            count -= bit
        bit <<= 1
    return b"".join(parts)


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(data, zlib.crc32(kind)))


def write_png(path, img, *, fsync: bool = True) -> None:
    """Write a greyscale or colour image as a PNG file, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced if it exists.
    img : array_like, shape (H, W) or (H, W, 3), uint8
        Grey levels or RGB, row 0 at the top.
    fsync : bool, optional
        Flush the data to disk before the rename (default), so that after a
        power loss the file is either the old one or the complete new one;
        without it, the file is still whole after a crash of the process.
    """
    write_png_bytes(path, encode_png(img), fsync=fsync)


def write_png_bytes(path, data, *, fsync: bool = True) -> None:
    """Write already encoded PNG bytes ``data`` to ``path`` atomically (see :func:`write_png`)."""
    with AtomicWriter(path, fsync, buffer=0) as f:
        f.write(data)


def read_png(path, colour: bool = False) -> np.ndarray:
    """Read a PNG file as a greyscale (or colour) image.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    colour : bool, optional
        Return RGB rather than grey levels.

    Returns
    -------
    ndarray, shape (H, W) or, with ``colour``, (H, W, 3), uint8
        Grey levels (colour images are converted to luminance), or RGB.
    """
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im.convert("RGB" if colour else "L")).copy()
