"""ANIMATE ... REPEAT plays a cycle as n * motion (issue 9): no stop at each junction."""

from __future__ import annotations

import pathlib

from exchange_support import pose_records

from liganimate.compiler import load_program

PROGRAM = """\
      GRAPHICAL ARM, BODY
      MODEL M
      MOTION CYC, THREE
      BODY :- BOX WIDTH 0.6, HEIGHT 1.0, DEPTH 0.4
      ARM :- BOX WIDTH 0.2, HEIGHT 0.8, DEPTH 0.2
      M :- JOINT 1, BODY, (0.3, 0.4, 0.0), ARM, (0.0, 0.4, 0.0),
               (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)
      STARTMOTION CYC
        JOINT 1 POSITION 0.0, 0.0, 0.0
          FRAME 4 POSITION 0.0, 0.0, 20.0
          FRAME 8 POSITION 0.0, 0.0, -20.0
          FRAME 12 POSITION 0.0, 0.0, 0.0
      ENDMOTION
      THREE = 3 * CYC
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 36
          ANIMATE M FROM 0 TO 35 USING CYC REPEAT
      ENDSCENE
      INITIALIZE SCENE 2
      STARTSCENE LENGTH 36
          ANIMATE M FROM 0 TO 35 USING THREE
      ENDSCENE
      SHOOTSCENES
      END
"""


def test_repeat_in_a_scene_equals_n_copies_and_keeps_moving_at_the_junction(tmp_path: pathlib.Path):
    src = tmp_path / "rep.lig"
    src.write_text(PROGRAM)
    program, _ = load_program(str(src))
    z = {}
    for r in pose_records(program, tmp_path):
        z[r["scene"], r["tick"]] = r["joints"]["1"][2]
    for tick in range(36):
        assert abs(z[1, tick] - z[2, tick]) < 1e-9, tick
    # Around the junction at tick 12 the arm keeps rising (5 deg/frame) instead of easing to a stop.
    assert z[1, 13] - z[1, 12] > 4.0 and z[1, 12] - z[1, 11] > 4.0
