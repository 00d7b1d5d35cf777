"""Retargeting and big captures: foot slide and clamped frames per real capture; import, check, render against length.

Part 1, per capture (bvhtoolbox's mocapbank and Mixamo takes, bvhtools'
Rigify take), retargeted onto the library HUMANOID with
``liganimate import --onto humanoid``: the contact frames held, the most a
held ankle moves in a frame (mm, measured with the runtime's kinematics),
the joint-frames clamped into HUMANOID's extremes, how far the figure turns
(its ROOT ORIENTATION's heading, first frame to last) beside how far the
actor does (the hips' heading, from the BVH's own rotations), and the time.

Part 2, against capture length: a capture of 30 joints (a Mixamo-style
skeleton) of 1,000, 5,000 and 20,000 frames, made by repeating bvhtools'
7,184-frame take; for each, the wall and CPU seconds and the peak memory
(resident set size of the child process) of ``liganimate import``, of
``liganimate check`` of a program that LOADs the result, and of
``liganimate run`` rendering its first frame, each in a fresh process.
bvhio, the peer a user would otherwise read a BVH file with, reads the
same file in a fresh process beside it. The 20,000-frame row must stay
under 10 s of CPU time and 400 MB for each step (issue 19); wall time is
printed beside it.

Usage: ``python benchmarks/retarget.py [--quick]`` (``--quick``: 1,000 and
5,000 frames, and the mocapbank and Mixamo captures only). The last line printed is one
JSON object with every figure.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests"))

from captures import capture  # noqa: E402  (the tests' fetcher: pip download of the sdists)

PLAY = """\
      LOAD {model}, {motion} FROM '{lib}'
      INITIALIZE SCENE 1
        VIEW POINT = (0.0, 100.0, 600.0)
        VIEW WIDTH = 500.0
      STARTSCENE LENGTH 1
        ANIMATE {model} FROM 0 TO 0 USING {motion}
      ENDSCENE
      SHOOTSCENES
"""


# Runs a module (or code) and reports its own peak RSS and CPU time, so each figure is the step's alone.
_WRAP = """
import resource, runpy, sys
kind, target = sys.argv[1], sys.argv[2]
sys.argv = [target] + sys.argv[3:]
code = 0
try:
    if kind == "module":
        runpy.run_module(target, run_name="__main__", alter_sys=True)
    else:
        exec(target, {"__name__": "__main__"})
except SystemExit as e:
    code = e.code or 0
u = resource.getrusage(resource.RUSAGE_SELF)
print("RUSAGE", u.ru_maxrss, u.ru_utime + u.ru_stime, code, file=sys.stderr)
"""


def _child(kind: str, target: str, args: list, cwd: str) -> dict:
    """Run a module (``kind`` "module") or code in a fresh process: wall and CPU seconds, peak RSS in MB."""
    t = time.perf_counter()
    r = subprocess.run(
        [sys.executable, "-W", "ignore", "-c", _WRAP, kind, target, *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=900,
    )
    wall = time.perf_counter() - t
    usage = [line.split() for line in r.stderr.splitlines() if line.startswith("RUSAGE")]
    if r.returncode != 0 or not usage or usage[-1][3] != "0":
        raise SystemExit(f"{target} {' '.join(args)} failed:\n{r.stderr[-2000:]}")
    return {
        "wall_s": round(wall, 3),
        "cpu_s": round(float(usage[-1][2]), 3),
        "peak_mb": round(int(usage[-1][1]) / 1024.0, 1),
    }


def _long_capture(path: str, frames: int) -> None:
    """bvhtools' long take (22 joints) with 8 more joints at the end of the hierarchy: 30 joints, ``frames`` frames.

    The take's frames are repeated as needed; the extra joints (markers
    under the hips, as some exporters write them) turn a little, so every
    channel moves.
    """
    text = open(capture("long"), encoding="utf-8").read()
    head, motion = text.split("MOTION", 1)
    lines = [line.split() for line in motion.splitlines()[3:] if line.strip()]
    extra = "".join(
        f"  JOINT Marker{k}\n  {{\n    OFFSET {k} 2 0\n    CHANNELS 3 Zrotation Yrotation Xrotation\n"
        "    End Site\n    {\n      OFFSET 0 2 0\n    }\n  }\n"
        for k in range(1, 9)
    )
    close = head.rstrip().rindex("}")  # the ROOT's closing brace: the new joints' channels come last
    head = head[:close] + extra + head[close:]
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(head + f"MOTION\nFrames: {frames}\nFrame Time: 0.033333\n")
        for f in range(frames):
            row = lines[f % len(lines)]
            wiggle = f" {f % 7} 0 0" * 8
            fh.write(" ".join(row) + wiggle + "\n")


def length_rows(lengths: list, folder: str) -> list:
    """Import, check and render-first-frame cost for each capture length (part 2)."""
    out = []
    for n in lengths:
        bvh = os.path.join(folder, f"cap{n}.bvh")
        _long_capture(bvh, n)
        row = {"frames": n, "file_mb": round(os.path.getsize(bvh) / 1e6, 2)}
        args = ["import", bvh, "-o", f"cap{n}.lig", "--model", "FIG", "--motion", "MOT"]
        row["import"] = _child("module", "liganimate", args, folder)
        row["library_mb"] = round(os.path.getsize(os.path.join(folder, f"cap{n}.lig")) / 1e6, 2)
        with open(os.path.join(folder, f"play{n}.lig"), "w") as fh:
            fh.write(PLAY.format(model="FIG", motion="MOT", lib=f"cap{n}.lig"))
        env_cache = os.path.join(folder, f"cache{n}")
        os.environ["LIGANIMATE_CACHE"] = env_cache  # a cold library cache: the first LOAD compiles
        row["check"] = _child("module", "liganimate", ["check", f"play{n}.lig"], folder)
        os.environ["LIGANIMATE_CACHE"] = env_cache + "-run"
        args = ["run", f"play{n}.lig", "-o", f"frames{n}", "--quiet"]
        row["render_first_frame"] = _child("module", "liganimate", args, folder)
        bvhio_code = f"import bvhio; bvhio.readAsBvh({bvh!r})"
        row["bvhio_read"] = _child("code", bvhio_code, [], folder)
        # Judged on CPU time: the wall clock of a shared machine measures the neighbours too.
        steps = ("import", "check", "render_first_frame")
        row["within_limits"] = all(row[k]["cpu_s"] < 10 and row[k]["peak_mb"] < 400 for k in steps)
        print(
            f"{n:>6} frames: import {row['import']['wall_s']:6.2f} s (cpu {row['import']['cpu_s']:.2f}) "
            f"{row['import']['peak_mb']:6.0f} MB | check {row['check']['wall_s']:6.2f} s "
            f"(cpu {row['check']['cpu_s']:.2f}) {row['check']['peak_mb']:6.0f} MB | first frame "
            f"{row['render_first_frame']['wall_s']:6.2f} s (cpu {row['render_first_frame']['cpu_s']:.2f}) "
            f"{row['render_first_frame']['peak_mb']:6.0f} MB | "
            f"bvhio read {row['bvhio_read']['wall_s']:6.2f} s (cpu {row['bvhio_read']['cpu_s']:.2f}) "
            f"{row['bvhio_read']['peak_mb']:6.0f} MB | library {row['library_mb']} MB"
        )
        out.append(row)
    return out


def actor_turn(clip) -> float:
    """Degrees the capture's hips turn about the file's Y, first frame to last, from the BVH's rotations alone."""
    import numpy as np

    from liganimate.runtime.exchange._clip import clip_pose
    from liganimate.runtime.figure.kinematics import matrix_from_euler_zyx

    pose = clip_pose(clip, "drop")
    Q = matrix_from_euler_zyx(pose.angles[:, int(np.flatnonzero(clip.parents < 0)[0])])
    axis = int(np.argmin([np.abs(Q[:, 1, a]).mean() for a in range(3)]))  # the hips' most horizontal axis
    heading = np.degrees(np.unwrap(np.arctan2(Q[:, 0, axis], Q[:, 2, axis])))
    return float(heading[-1] - heading[0])


def capture_rows(names: list) -> list:
    """Foot slide and clamped frames of each real capture retargeted onto HUMANOID (part 1)."""
    from liganimate.runtime import exchange as X
    from liganimate.runtime.exchange._onto import foot_slide, joint_map, load_figure

    out = []
    for name in names:
        clip = X.read_bvh(capture(name))
        if name == "rigify":
            clip = X.cut_frames(clip, 0, 999)
        t = time.process_time()
        options = X.OntoOptions(library="humanoid", motion="TAKE", retarget=X.RetargetOptions(joint_translation="drop"))
        _, _, result = X.retarget_library(clip, options)
        cpu = time.process_time() - t
        _, fig, _ = load_figure("humanoid")
        jmap = joint_map(clip, fig, None)
        slide = foot_slide(fig, result, jmap) * 1000.0
        row = {
            "capture": name,
            "frames": int(clip.data.shape[0]),
            "held_contact_frames": {s: int(m.sum()) for s, m in result.planted.items()},
            "max_slide_mm_per_frame": round(slide, 4),
            "clamped_joint_frames": int(sum(result.clamped.values())),
            "figure_turn_deg": round(float(result.orientation[-1, 1] - result.orientation[0, 1]), 2),
            "actor_turn_deg": round(actor_turn(clip), 2),
            "retarget_cpu_s": round(cpu, 3),
        }
        print(
            f"{name:>9}: {row['frames']} frames, held contacts {row['held_contact_frames']}, "
            f"worst slide {slide:.4f} mm/frame, clamped {row['clamped_joint_frames']} joint-frames, "
            f"turns {row['figure_turn_deg']:+.1f} deg (actor {row['actor_turn_deg']:+.1f}), {cpu:.2f} s CPU"
        )
        out.append(row)
    return out


def main() -> None:
    quick = "--quick" in sys.argv
    folder = tempfile.mkdtemp(prefix="retarget-bench-")
    captures = capture_rows(["mocapbank", "mixamo"] if quick else ["mocapbank", "mixamo", "rigify", "long"])
    lengths = length_rows([1000, 5000] if quick else [1000, 5000, 20000], folder)
    print(json.dumps({"benchmark": "retarget", "quick": quick, "captures": captures, "lengths": lengths}))


if __name__ == "__main__":
    main()
