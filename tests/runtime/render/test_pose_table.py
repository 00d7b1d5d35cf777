"""The renderer's pose table: a REPEATed motion is evaluated once per frame of its period, bit for bit."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
from paths import ROOT_DIR

from liganimate.compiler import load_program
from liganimate.runtime.figure.pose import joint_angles
from liganimate.runtime.render import frames as R
from liganimate.runtime.render.options import RenderOptions


@pytest.fixture(scope="module")
def scene():
    prog, _ = load_program(str(pathlib.Path(ROOT_DIR) / "benchmarks" / "five_humans.lig"))
    rt = prog.execute("check")
    fig = rt.variables["H1"]
    fig = getattr(fig, "figure", fig)
    return rt, fig


def renderer(tmp_path) -> R.Renderer:
    return R.Renderer(RenderOptions(out=str(tmp_path / "frames"), size=(64, 48), workers=1, quiet=True))


@pytest.mark.parametrize(("motion", "scale"), [("WALK", 1.0), ("WALK", 1.5), ("SQUAT_UP_DOWN", 3.0), ("WALK", 1.3)])
def test_pose_table_gives_the_angles_of_every_frame(tmp_path, scene, motion, scale):
    rt, fig = scene
    base = rt._motion(rt.variables[motion], 0).scale_frames(scale)
    ticks = 1000
    repeated = base.repeat(int((ticks - 1) // base.length) + 1)  # as ANIMATE ... REPEAT plays it
    assert repeated.cycle is not None and repeated.cycle[1] == base.length
    r = renderer(tmp_path)
    try:
        batches = [list(map(float, range(t, min(t + 32, ticks)))) for t in range(0, ticks, 32)]
        got = np.concatenate([r._joint_angles(fig, repeated, b) for b in batches])
        want = joint_angles(fig, repeated, np.arange(ticks, dtype=np.float64))
        np.testing.assert_array_equal(got, want)  # bit for bit, not approximately
        period = base.length
        if scale == 1.3:  # a period that is not exact in binary is never wrapped
            assert r.angle_frames == ticks
        else:
            # The first copy, one middle copy, the last copy and the junction frames.
            assert r.angle_frames <= 3 * period + repeated.cycle[0] + 1
            assert r.angle_frames < ticks / 2
    finally:
        r.close()


def test_wrapped_frame_keeps_first_last_and_junctions():
    assert R.wrapped_frame(5.0, 10, 10.0) == 5.0  # first copy
    assert R.wrapped_frame(15.0, 10, 10.0) == 15.0  # copy 1 stands for itself
    assert R.wrapped_frame(25.0, 10, 10.0) == 15.0
    assert R.wrapped_frame(85.0, 10, 10.0) == 15.0  # copy 8, the last middle one
    assert R.wrapped_frame(95.0, 10, 10.0) == 95.0  # last copy: it meets a neighbour on one side only
    assert R.wrapped_frame(30.0, 10, 10.0) == 30.0  # a junction
    assert R.wrapped_frame(25.0, 3, 10.0) == 25.0  # no two middle copies
    assert R.wrapped_frame(25.1, 10, 10.0) == 25.1  # not exact in binary


def test_a_motion_that_is_not_repeated_has_no_cycle(scene):
    rt, _fig = scene
    walk = rt._motion(rt.variables["WALK"], 0)
    assert walk.cycle is None and walk.repeat(1).cycle is None
    assert walk.repeat(3).cycle == (3, walk.length)
