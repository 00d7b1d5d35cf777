"""The worker message (issue 22): tasks carry link matrices, workers form the triangles, the frames stay the same bytes.

A render task names each figure's mesh table and each background drawing
by a key and carries only cameras, link matrices and morphed rows
(:mod:`liganimate.runtime.render.message`); a worker keeps the shapes it is
shipped.  The frames must be those drawn in the main process, whatever
worker draws an image and whether its shapes came with the task, earlier,
or after a :class:`Missing` answer.
"""

from __future__ import annotations

import pathlib
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest
from paths import ROOT_DIR

from liganimate.compiler import load_program
from liganimate.runtime.figure.pose import MeshTable, world_triangles
from liganimate.runtime.render import frames as R
from liganimate.runtime.render import message as M

EXAMPLES = pathlib.Path(ROOT_DIR) / "examples"
SIZE = (120, 90)


def moving_eye(folder: pathlib.Path) -> pathlib.Path:
    """reversed_squat (re-rooted at a foot, a BACKGROUND) with its camera moving every tick, three ticks an image."""
    text = (EXAMPLES / "reversed_squat.lig").read_text()
    assert text.count("STARTSCENE LENGTH 11 SAMEFRAME 11") == 2
    text = text.replace("STARTSCENE LENGTH 11 SAMEFRAME 11", "STARTSCENE LENGTH 24 SAMEFRAME 3")
    text = text.replace("ANIMATE HUMAN FROM 0 TO 10", "ANIMATE HUMAN FROM 0 TO 23")
    text = text.replace(
        "        LOCATN = LOCATN + (DISTAN / 10.0)\n",
        "        LOCATN = LOCATN + (DISTAN / 10.0)\n        VIEW POINT = (LOCATN + (0.0, 2.0, 12.0))\n",
    )
    assert text.count("VIEW POINT = (LOCATN") == 2
    path = folder / "moving_eye.lig"
    path.write_text(text)
    return path


def scenes(folder: pathlib.Path) -> list:
    return [
        EXAMPLES / "mailbox.lig",  # SHAPE and SCALE morphs
        EXAMPLES / "rerooting.lig",  # re-rooted figures on a BACKGROUND
        EXAMPLES / "thesis_fragments.lig",  # two scenes, two cameras, backgrounds, a scaled robot
        moving_eye(folder),  # a camera per tick, several in an image
    ]


def frames_of(folder: pathlib.Path) -> list:
    return [(str(p.relative_to(folder)), p.read_bytes()) for p in sorted(folder.rglob("*.png"))]


def render(path: pathlib.Path, out: pathlib.Path, look: str, workers: int) -> list:
    program, _ = load_program(str(path))
    program.render(str(out), size=SIZE, quiet=True, workers=workers, look=look)
    return frames_of(out)


@pytest.mark.parametrize("look", ["thesis", "modern"])
def test_frames_from_link_matrices_are_the_bytes_drawn_in_one_process(tmp_path, monkeypatch, look):
    resent = []
    close = R.Renderer.close
    monkeypatch.setattr(R.Renderer, "close", lambda self: resent.append(self.resent) or close(self))
    for path in scenes(tmp_path):
        here = render(path, tmp_path / f"{path.stem}-1", look, workers=1)
        assert len(here) >= 16, path
        assert render(path, tmp_path / f"{path.stem}-2", look, workers=2) == here, path
    # No shape shipped ahead: every worker answers Missing first, and the task goes again.
    monkeypatch.setattr(M.Shipping, "pick", lambda self, shapes, spread: {})
    M._kept.clear()
    resent.clear()
    path = EXAMPLES / "mailbox.lig"
    again = render(path, tmp_path / "resent", look, workers=2)
    assert again == frames_of(tmp_path / "mailbox-1")
    assert resent and resent[-1] >= 1  # the first task a fresh worker took came back Missing


def _table(triangles: np.ndarray, link: np.ndarray) -> MeshTable:
    table = MeshTable.__new__(MeshTable)
    table.triangles, table.link = triangles, link
    table.shade = np.full(len(link), 100, dtype=np.uint8)
    table.closed = np.ones(len(link), dtype=bool)
    table.lightness, table.colour = np.full(len(link), 0.5), None
    return table


def test_the_worker_forms_the_triangles_the_main_process_formed_from_a_batch():
    rng = np.random.default_rng(5)
    table = _table(rng.normal(size=(40, 3, 3)), rng.integers(0, 6, 40))
    X = rng.normal(size=(13, 6, 4, 4))  # thirteen frames of a six-link figure
    local = np.broadcast_to(table.triangles, (13, 40, 3, 3)).copy()
    local[:, 5:9] += rng.normal(size=(13, 4, 3, 3))  # a SHAPE morph moves rows 5-8
    table.triangles[2, 0, 0] = local[:, 2, 0, 0] = 0.0
    local[4, 2, 0, 0] = -0.0  # and row 2 by a sign only, in one frame
    batch = world_triangles(table, X, None)
    morphed = world_triangles(table, X, local)
    rows, moved = R._moved_rows(table, local)
    assert rows.tolist() == [2, 5, 6, 7, 8]
    images = []
    for n in range(13):
        plain = M.Posed(table, X[n], n == 3)
        shaped = M.Posed(table, X[n], False, rows, moved[n])
        images.append([(((0.0, 0.0, 10.0), 10.0), [plain, shaped])])
    for start in range(0, 13, 8):  # two tasks, of eight and five images
        task, shapes = M.pack(images[start : start + 8], M.Keys(), (SIZE, 1, False, False, "thesis"))
        got = M.resolve(task.shipping(shapes))
        for n, draws in enumerate(got, start):
            ((_camera, ((tris, _, cull), (shaped_tris, _, _))),) = draws
            assert np.array_equal(tris.view(np.uint64), batch[n].view(np.uint64))
            assert np.array_equal(shaped_tris.view(np.uint64), morphed[n].view(np.uint64))
            assert cull.all() != (n == 3)  # a mirrored figure culls nothing


def five_humans(folder: pathlib.Path, ticks: int) -> pathlib.Path:
    text = (pathlib.Path(ROOT_DIR) / "benchmarks" / "five_humans.lig").read_text()
    assert "LENGTH 1000" in text and text.count("TO 999") == 5
    path = folder / "five.lig"
    path.write_text(text.replace("LENGTH 1000", f"LENGTH {ticks}").replace("TO 999", f"TO {ticks - 1}"))
    return path


def test_an_image_carries_link_matrices_and_each_shape_travels_with_the_first_tasks_only(tmp_path, monkeypatch):
    tasks, shipped = [], []
    pack, pick = M.pack, M.Shipping.pick
    monkeypatch.setattr(R, "pack", lambda *a: tasks.append(pack(*a)) or tasks[-1])
    monkeypatch.setattr(M.Shipping, "pick", lambda self, *a: shipped.append(pick(self, *a)) or shipped[-1])
    program, _ = load_program(str(five_humans(tmp_path, 96)))
    program.render(str(tmp_path / "out"), size=(64, 48), quiet=True, workers=2, look="thesis")
    assert len(tasks) == 12 and len(shipped) == 12  # eight images a task, all in the pool
    for task, shapes in tasks:
        assert len(task.images) == 8 and not task.shapes  # shipped only when picked
        figures = [part for image in task.images for _cam, parts in image for part in parts if part[1] >= 0]
        assert len(figures) == 8 * 5
        assert task.matrices.shape == (sum(part[2] for part in figures), 4, 4)
        assert len(shapes) == 2  # the humans' one mesh table and the ground
    counts: dict = {}
    for picked in shipped:
        for key in picked:
            counts[key] = counts.get(key, 0) + 1
    assert len(counts) == 2 and all(n <= 4 for n in counts.values())  # at most the tasks in flight
    # What an image costs to send: its link matrices against its world triangles before.
    task, shapes = tasks[-1]
    (table,) = [shape for shape in shapes.values() if isinstance(shape, MeshTable)]
    assert task.matrices.nbytes < 8 * 5 * table.triangles.nbytes / 3


def test_a_task_naming_a_shape_the_worker_lacks_is_answered_missing_then_drawn_with_it():
    M._kept.clear()
    table = _table(np.arange(27.0).reshape(3, 3, 3), np.array([0, 0, 1]))
    ground = (np.ones((2, 3, 3)), np.array([90, 90], dtype=np.uint8), np.array([True, False]))
    image = [(((0.0, 0.0, 10.0), 10.0), [ground, M.Posed(table, np.stack([np.eye(4)] * 2), False)])]
    keys = M.Keys()
    task, shapes = M.pack([image], keys, (SIZE, 1, False, False, "thesis"))
    assert task.matrices.shape == (2, 4, 4) and not task.shapes
    assert M.resolve(task) == M.Missing(tuple(sorted(shapes)))
    drawn = M.resolve(task.shipping(shapes))
    assert isinstance(drawn, list)
    assert M.resolve(task) != M.Missing(tuple(sorted(shapes)))  # kept since
    ((camera, parts),) = drawn[0]
    assert parts[0] is ground and np.array_equal(parts[1][0], table.triangles)
    # Keys are digests of the content: an equal shape built afresh has the same key, a different one not.
    copy = (ground[0].copy(), ground[1].copy(), ground[2].copy())
    assert keys.key(copy) == keys.key(ground)
    assert keys.key((ground[0] * 2, ground[1], ground[2])) != keys.key(ground)


def test_a_kept_shape_still_draws_when_the_task_s_own_shapes_fill_the_store():
    M._kept.clear()
    old = (np.ones((1, 3, 3)), np.array([10], dtype=np.uint8), np.array([False]))
    new = (np.full((1, 3, 3), 2.0), np.array([20], dtype=np.uint8), np.array([False]))
    camera = ((0.0, 0.0, 10.0), 10.0)
    keys = M.Keys()
    task, shapes = M.pack([[(camera, [old])]], keys, (SIZE, 1, False, False, "thesis"))
    M.resolve(task.shipping(shapes))  # ``old`` is kept
    for i in range(M.KEPT - 1):
        M._keep({f"filler{i}": old})
    assert len(M._kept) == M.KEPT
    task, shapes = M.pack([[(camera, [old, new])]], keys, (SIZE, 1, False, False, "thesis"))
    fresh = {k: v for k, v in shapes.items() if v is new}
    drawn = M.resolve(task.shipping(fresh))  # keeping ``new`` clears the store ``old`` was found in
    assert drawn[0][0][1] == [old, new]
    M._kept.clear()


def test_shapes_kept_and_shipped_stay_bounded():
    M._kept.clear()
    ship = M.Shipping()
    shapes = {f"b{i}": (np.zeros((1, 3, 3)), np.zeros(1, dtype=np.uint8), np.zeros(1, dtype=bool)) for i in range(3)}
    assert ship.pick(shapes, 2) == shapes and ship.pick(shapes, 2) == shapes and ship.pick(shapes, 2) == {}
    for i in range(M.KEPT + 10):
        M._keep({f"k{i}": shapes["b0"]})
    assert 0 < len(M._kept) <= M.KEPT
    M._kept.clear()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="pipe sizes are a Linux setting")
def test_the_results_come_back_through_a_pipe_of_a_megabyte():
    import fcntl

    pool = ProcessPoolExecutor(max_workers=1)
    try:
        fd = pool._result_queue._reader.fileno()
        assert fcntl.fcntl(fd, 1032) == 65536  # F_GETPIPE_SZ: the default
        R._widen_result_pipe(pool)
        allowed = int(pathlib.Path("/proc/sys/fs/pipe-max-size").read_text())
        assert fcntl.fcntl(fd, 1032) == (R._RESULT_PIPE if allowed >= R._RESULT_PIPE else 65536)
    finally:
        pool.shutdown()
