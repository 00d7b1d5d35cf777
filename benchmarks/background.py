"""Static-background benchmark: would a per-camera cache of the background pay, in CPU time?

The scene is ``benchmarks/five_humans.lig`` (five Appendix A humans on a
ground BOX, one still camera), at 640x480, in the thesis look and the
modern look.  The renderer keeps each BACKGROUND object's triangles once a
render (the static-background table) but projects them, spans them and
fills their pixels with every image, merged with the figures' triangles.
This measures, CPU time an image (the draw step alone, one process, the
round of least CPU of several, interleaved; the frame's wall time and the
load are printed beside it):

* **frame**: drawing the image as the renderer does;
* **ground**: what the background adds (the frame less the same frame
  drawn without it): the most any background cache could save;
* **cacheable**: the part of it a per-camera cache of the background's
  projected triangles and spans could skip: the image's camera-space
  triangles, trapezoids and spans (in the modern look also its normals and
  lit shades) with the ground merged in, less the same without it.  Its
  pixels must still be filled each image (the figures' depths decide which
  of them show), and merging cached spans with the figures' would cost
  something of its own, so this is an upper bound of the saving;
* **buffers**: copying a drawn background's full buffers into a new image
  (the depth buffer and the image, or the modern look's supersampled
  samples), what a per-camera cache of the drawn background would cost
  instead of drawing it.

The last line printed is one JSON object with the figures.

Usage: ``python benchmarks/background.py [--quick]`` (``--quick``: 24
images and 9 rounds, well under a minute; default 64 and 15).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile

from _clock import Cost, best_of, load_text, measure
from film import captured_draws, scene_program

from liganimate.runtime.render import frames as R
from liganimate.runtime.render import look as L
from liganimate.runtime.render import raster

SIZE = (640, 480)


def best(fns: dict, count: int, rounds: int) -> dict:
    """The cost (CPU and wall) of one of ``count`` calls made by each function, the round of least CPU of ``rounds`` interleaved."""
    costs: dict[str, list[Cost]] = {name: [] for name in fns}
    for _ in range(rounds):
        for name, fn in fns.items():
            costs[name].append(measure(fn).per(count))
    return {name: best_of(c) for name, c in costs.items()}


def projection(draws: list, look: str, ground: bool):
    """A function doing, for every image, the per-camera work on its merged triangles (with or without the ground).

    The work a cache of the background's projected triangles and spans
    would spare: camera-space triangles, trapezoids and spans (in the
    modern look also normals and lit shades), for the triangles the image's
    first camera sees, the ground first as the renderer merges them.
    """
    params = L.look_params(look)
    work = []
    for image in draws:
        camera = image[0][0]
        parts = [p for c, ps in image if c == camera for p in ps] if ground else image[1][1]
        tris, shade, cull = R._joined(parts)
        work.append((R._camera(camera, SIZE), tris, shade, cull))

    def run():
        for cam, tris, shade, cull in work:
            if params is not None:
                L._lit(shade, L._visible_normals(tris, cam.point), cam, params)
            raster._spans(tris, cull, cam, 0, None)

    return run


def buffers(look: str):
    """A function copying a drawn background's buffers into a new image, once."""
    params = L.look_params(look)
    fb = raster.Framebuffer(SIZE, 255 if params is None else params.background, aa=1)
    kept = (fb.zbuf.copy(), fb.samples.copy())

    def run():
        fb.zbuf[...] = kept[0]
        fb.samples[...] = kept[1]

    return run, sum(a.nbytes for a in kept)


def measure_look(program, look: str, count: int, rounds: int) -> dict:
    draws = captured_draws(program, count, look)
    bare = [[(image[0][0], [])] + image[1:] for image in draws]
    assert all(len(image) == 2 and image[0][0] == image[1][0] for image in draws)  # one still camera
    copy, nbytes = buffers(look)
    ms = best(
        {
            "full": lambda: [R.draw(SIZE, d, 1, look) for d in draws],
            "without": lambda: [R.draw(SIZE, d, 1, look) for d in bare],
            "spans": projection(draws, look, True),
            "spans_without": projection(draws, look, False),
            "copy": lambda: [copy() for _ in draws],
        },
        len(draws),
        rounds,
    )
    cpu = {name: 1e3 * c.cpu for name, c in ms.items()}
    full, without, copied = cpu["full"], cpu["without"], cpu["copy"]
    cached = cpu["spans"] - cpu["spans_without"]
    return {
        "frame_ms": round(full, 4),
        "frame_wall_ms": round(1e3 * ms["full"].wall, 4),
        "load": ms["full"].load,
        "ground_ms": round(full - without, 4),
        "cacheable_ms": round(cached, 4),
        "buffers_ms": round(copied, 4),
        "buffer_bytes": nbytes,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="24 images, 9 rounds")
    args = ap.parse_args(argv)
    count, rounds = (24, 9) if args.quick else (64, 15)
    print(load_text())
    print(
        f"scene: five humans on a ground BOX, {count} images, {SIZE[0]}x{SIZE[1]}, CPU ms an image (best of {rounds})"
    )
    out: dict = {"images": count, "size": f"{SIZE[0]}x{SIZE[1]}"}
    with tempfile.TemporaryDirectory() as folder:
        program = scene_program(folder, count)
        for look in ("thesis", "modern"):
            m = measure_look(program, look, count, rounds)
            out[look] = m
            print(
                f"{look:>6}: frame {m['frame_ms']:.3f} ms CPU ({m['frame_wall_ms']:.3f} ms wall); the ground adds {m['ground_ms']:.3f} ms, of which a "
                f"per-camera cache of its projection and spans could skip {m['cacheable_ms']:.3f} ms "
                f"({100 * m['cacheable_ms'] / m['frame_ms']:.1f}% of the frame); copying a drawn background's "
                f"buffers ({m['buffer_bytes'] / 1e6:.2f} MB) costs {m['buffers_ms']:.3f} ms"
            )
    print(load_text())
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
