"""Cheaper durable frames: renamed without an fsync each, flushed to disk in batches (runtime/files.py)."""

from __future__ import annotations

import os

from test_render import pngs, program

from liganimate.compiler import load_program
from liganimate.runtime import files
from liganimate.runtime.render import frames


def test_frames_are_not_synced_one_by_one(tmp_path, monkeypatch):
    synced = []
    real = os.fsync

    def fsync(fd):
        synced.append(os.readlink(f"/proc/self/fd/{fd}"))
        return real(fd)

    monkeypatch.setattr(files.os, "fsync", fsync)
    prog, _ = load_program(str(program(tmp_path, 60)))
    prog.render(str(tmp_path / "out"), size=(32, 24), quiet=True, workers=1, poses=str(tmp_path / "p.jsonl"))
    assert len(pngs(tmp_path / "out")) == 60
    synced_pngs = [p for p in synced if p.endswith(".png") or ".png." in p]
    # The old renderer synced each of the 60 frames before its rename.
    assert len(synced_pngs) < 10, synced_pngs
    # The pose record is still synced before its rename, and the folders after the frames.
    assert any(".p.jsonl." in p for p in synced)
    assert str(tmp_path / "out" / "scene1") in synced


def test_a_batch_is_flushed_every_n_files_and_at_the_end(tmp_path, monkeypatch):
    flushed = []
    monkeypatch.setattr(files, "_sync", lambda fs, folders: flushed.append((list(fs), list(folders))))
    batch = files.SyncBatch(every=3)
    paths = [tmp_path / f"{i}.png" for i in range(7)]
    for p in paths:
        files.write_atomic(p, b"data", fsync=False)
        batch.add(p)
        if batch._thread is not None:
            batch._thread.join()
    batch.add_folder(tmp_path)
    batch.sync()
    names = [[os.path.basename(f) for f in fs] for fs, _ in flushed]
    assert names == [["0.png", "1.png", "2.png"], ["3.png", "4.png", "5.png"], ["6.png"]]
    assert flushed[-1][1] == [str(tmp_path)]


def test_the_renderer_flushes_every_sync_every_frames(tmp_path, monkeypatch):
    flushed = []
    monkeypatch.setattr(files, "_sync", lambda fs, folders: flushed.append(len(fs)))
    monkeypatch.setattr(frames, "SYNC_EVERY", 16)
    prog, _ = load_program(str(program(tmp_path, 50)))
    prog.render(str(tmp_path / "out"), size=(32, 24), quiet=True, workers=1)
    assert sum(flushed) == 50 and max(flushed) >= 16 and len(flushed) >= 3
