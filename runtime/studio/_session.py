"""One studio session: the Generator, the library it saves, and the JSON the page exchanges.

The page sends choices as ``{"action": ..., ...}`` objects; :meth:`Session.act`
checks every field before anything changes and answers with the whole
state (:meth:`Session.state`).  All the posing logic is the
:class:`~._generator.Generator`'s; this module only translates.

Many threads may use one session (the server's workers and its slow
lane): every action holds :attr:`Session.lock` for as long as it takes to
change the poses and describe them, never longer.  A Save takes a copy of
what it writes under the lock and compiles and writes it outside
(:meth:`Session.save`), so a slow disk never holds up the page's state.
"""

from __future__ import annotations

import base64
import hashlib
import json
import math
import os
import threading
from dataclasses import dataclass

import numpy as np

from liganimate.runtime.motion.interpolation import names as interpolation_names

from ._generator import KEPT_MAX, MODES, POPULATION, SEED_MAX, Generator
from ._library import library

__all__ = ["ACTIONS", "RequestError", "Session"]

ACTIONS = (
    "state",
    "next",
    "take",
    "set",
    "freeze",
    "undo",
    "keep",
    "stand",
    "seed",
    "settings",
    "recall",
    "delete",
    "move",
    "frame",
    "interpolation",
    "play",
    "save",
)
#: Frames a played motion may have at most (its matrices go to the page).
MAX_PLAY_FRAMES = 2400


class RequestError(ValueError):
    """A request the studio refuses: the page gets it with this message and :attr:`status` (400, or 409 at a cap).

    Parameters
    ----------
    message : str
        One sentence.
    status : int
        The HTTP status the server answers with.
    """

    def __init__(self, message: str, status: int = 400):
        super().__init__(message)
        self.status = status


@dataclass(frozen=True)
class _Snapshot:
    """What a Save writes, copied under the session lock: the kept poses, their frames, how they are joined."""

    kept: tuple
    frames: tuple
    method: str
    seed: int

    @property
    def key(self) -> bytes:
        """Equal for equal contents: whether the file on disk holds these poses."""
        h = hashlib.sha256(np.ascontiguousarray(np.asarray(self.kept, dtype=np.float64)).tobytes())
        h.update(repr((self.frames, self.method)).encode("ascii"))
        return h.digest()


def _b64(a) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype="<f4").tobytes()).decode("ascii")


def _number(v) -> bool:
    """Whether ``v`` is a finite JSON number (a bool is not; a whole number past a double's range is not)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return False
    try:
        return math.isfinite(float(v))
    except OverflowError:
        return False


def _int(body: dict, key: str, lo: int, hi: int) -> int:
    v = body.get(key)
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise RequestError(f"'{key}' must be a whole number from {lo} to {hi}")
    return v


class Session:
    """The state behind one ``liganimate studio``.

    Parameters
    ----------
    figure : Figure
    model, motion : str
        The names the saved library gives the model and the motion.
    save_path : str
        The one library file Save writes.
    seed : int
    spacing : int
        Frames between kept poses in the saved motion.
    """

    def __init__(self, figure, model: str, motion: str, save_path: str, seed: int = 1, spacing: int = 24):
        self.generator = Generator(figure, seed=seed)
        self.model, self.motion = model, motion
        self.save_path = os.path.abspath(save_path)
        self.spacing = spacing
        self.method = "LINEAR"  # how the saved motion reaches each kept pose
        self.lock = threading.Lock()
        self._save_lock = threading.Lock()  # one Save writes at a time, outside self.lock
        self._saves_asked = 0  # Saves asked for; a Save is done when a write begun after it asked has ended
        self._saves_done = 0
        self._written: _Snapshot | None = None  # what the file holds (None: nothing written yet)
        self._state_json: bytes | None = None  # the state as GET /api/state sends it, until the next change
        # Digests of PRIMITIVE texts (Library.shapes) a whole library with them has compiled with.
        self._shapes_ok: set = set()
        self._warming: threading.Thread | None = None

    def warm(self) -> None:
        """Check, in a background thread, the library Save will write, so that Save need not.

        Almost all of a saved library is the figure's PRIMITIVEs, the same
        at every Save; compiling all of it took seconds for the humanoid.
        Once a whole library with these PRIMITIVEs has compiled, a Save
        compiles the library with each PRIMITIVE cut to one triangle
        instead (the rest, which the kept poses change, in full).
        """
        if self._warming is not None:
            return
        g = self.generator
        pose = g.current.copy()

        def check():
            lib = library(g.figure, self.model, self.motion, [pose], self.spacing)
            try:
                check_library(lib.text, self.save_path)
            except Exception:  # noqa: BLE001 - Save then checks the whole library itself, and reports
                return
            self._shapes_ok.add(_digest(lib.shapes))

        self._warming = threading.Thread(target=check, name="liganimate-studio-warm", daemon=True)
        self._warming.start()

    # ---------------------------------------------------------------- state
    @property
    def saved(self) -> bool:
        """Whether the library on disk holds the kept poses as they are now."""
        w = self._written
        return w is not None and w.key == self._snapshot().key

    @property
    def has_saved(self) -> bool:
        """Whether this session has written its library (``GET /library.lig`` then serves it)."""
        return self._written is not None

    def state_json(self) -> bytes:
        """:meth:`state` with no message as UTF-8 JSON, made once per change (the page asks for it often)."""
        with self.lock:
            if self._state_json is None:
                self._state_json = json.dumps(self.state(), allow_nan=False).encode("utf-8")
            return self._state_json

    def state(self, message: str = "") -> dict:
        """The whole state as the page shows it (JSON-ready)."""
        g = self.generator
        poses = np.concatenate([g.current[None], g.candidates])
        X = g.transforms(poses)[:, :, :3, :]  # (10, L, 3, 4)
        return {
            "seed": g.seed,
            "generation": g.generation,
            "intensity": g.intensity,
            "mode": g.mode,
            "kept": len(g.kept),
            "canUndo": g.can_undo,
            "frozen": g.frozen.tolist(),
            "saved": self.saved,
            "savePath": self.save_path,
            "message": message,
            "matrices": _b64(X),
            "angles": np.round(poses, 4).tolist(),
            "levels": g.levels.tolist(),
            "keptFrames": list(g.kept_frames),
            "keptMatrices": _b64(g.transforms(np.asarray(g.kept))[:, :, :3, :]) if g.kept else "",
            "interpolation": self.method,
            "interpolations": list(interpolation_names()),
        }

    # -------------------------------------------------------------- actions
    def act(self, body) -> dict:
        """Apply one request from the page; return the new state.

        Raises
        ------
        RequestError
            For anything malformed: not an object, an unknown action, a
            missing or out-of-range field.  Nothing has changed then.
        """
        if not isinstance(body, dict):
            raise RequestError("the request must be a JSON object")
        action = body.get("action")
        if not isinstance(action, str) or action not in ACTIONS:
            raise RequestError(f"unknown action {str(action)[:40]!r}; the actions are " + ", ".join(ACTIONS))
        if action == "save":
            return self.save()
        g = self.generator
        with self.lock:
            message = getattr(self, "_do_" + action)(g, body)
            self._state_json = None
            state = self.state(message or "")
            snap = self._snapshot()
        if action == "play":
            state["play"] = self.played(snap)  # outside the lock: up to 2,400 frames take a tenth of a second
        return state

    def played(self, snap: _Snapshot | None = None) -> dict:
        """The kept poses as the saved motion plays them: segment matrices for every frame from 0 to the last.

        Parameters
        ----------
        snap : optional
            The kept poses to play, copied under :attr:`lock` (default: as they are now).

        Raises
        ------
        RequestError
            When no pose is kept, or the motion is longer than :data:`MAX_PLAY_FRAMES`.
        """
        from liganimate.runtime.motion import algebra as M
        from liganimate.runtime.motion.keyframe import Keyframe

        g = self.generator
        if snap is None:
            with self.lock:
                snap = self._snapshot()
        kept, frames, method = snap.kept, snap.frames, snap.method
        if not kept:
            raise RequestError("keep a pose first: the motion is made of the kept poses")
        if frames[-1] + 1 > MAX_PLAY_FRAMES:
            raise RequestError(
                f"the motion is {frames[-1] + 1} frames long; the studio plays at most {MAX_PLAY_FRAMES}"
            )
        spec = {}
        for k, j in enumerate(g.figure.joints):
            start = tuple(float(a) for a in kept[0][k])
            keys = [Keyframe(frames[n], _three(kept[n][k]), method) for n in range(1, len(frames))]
            spec[j.id] = (start, keys)
        motion = M.Motion.from_tracks(spec)
        times = np.arange(frames[-1] + 1, dtype=np.float64)
        angles = motion.evaluate(times, g.figure.joint_ids)
        return {"frames": len(times), "matrices": _b64(g.transforms(angles)[:, :, :3, :])}

    def _settings(self, g, body) -> None:
        intensity, mode = body.get("intensity"), body.get("mode")
        if intensity is not None and (not _number(intensity) or not 0 <= intensity <= 1):
            raise RequestError("'intensity' must be a number from 0 to 1")
        if mode is not None and mode not in MODES:
            raise RequestError("'mode' must be 'flexion' or 'twist'")
        if intensity is not None:
            g.set_intensity(float(intensity))
        if mode is not None:
            g.set_mode(mode)

    def _do_state(self, g, body):
        return ""

    def _do_settings(self, g, body):
        self._settings(g, body)

    def _do_next(self, g, body):
        self._settings(g, body)
        g.next_generation()
        return f"generation {g.generation}"

    def _link_joint(self, g, body) -> tuple:
        link = _int(body, "link", 0, g.figure.n_links - 1)
        joint = g.joint_of_link(link)
        name = g.figure.links[link].label
        if joint is None:
            raise RequestError(f"{name} is the main link: no joint moves it")
        return joint, name

    def _do_take(self, g, body):
        candidate = _int(body, "candidate", 0, POPULATION - 1)
        joint, name = self._link_joint(g, body)
        g.take(candidate, joint)
        return f"took {name} (joint {g.figure.joints[joint].id}) from candidate {candidate + 1}"

    def _do_freeze(self, g, body):
        joint, name = self._link_joint(g, body)
        g.toggle_frozen(joint)
        return f"{name} {'will not move' if g.frozen[joint] else 'moves again'}"

    def _do_undo(self, g, body):
        return "undone" if g.undo() else "nothing to undo"

    def _do_set(self, g, body):
        joint, name = self._link_joint(g, body)
        angles = body.get("angles")
        if not isinstance(angles, list) or len(angles) != 3 or not all(_number(a) for a in angles):
            raise RequestError("'angles' must be three numbers (degrees about X, Y and Z)")
        g.set_angles(joint, angles)
        a = g.current[joint]
        return f"{name} (joint {g.figure.joints[joint].id}) set to X {a[0]:.2f} Y {a[1]:.2f} Z {a[2]:.2f}"

    def _kept_index(self, g, body, key: str = "index") -> int:
        if not g.kept:
            raise RequestError("no pose is kept yet")
        return _int(body, key, 0, len(g.kept) - 1)

    def _do_recall(self, g, body):
        k = self._kept_index(g, body)
        g.recall(k)
        return f"kept pose {k + 1} is the current pose"

    def _do_delete(self, g, body):
        k = self._kept_index(g, body)
        g.delete_kept(k)
        return f"deleted kept pose {k + 1}"

    def _do_move(self, g, body):
        k, to = self._kept_index(g, body), self._kept_index(g, body, "to")
        g.move_kept(k, to)
        return f"kept pose {k + 1} moved to place {to + 1}"

    def _do_frame(self, g, body):
        k = self._kept_index(g, body)
        try:
            g.set_kept_frame(k, _int(body, "frame", 0, 10**6))
        except ValueError as exc:
            raise RequestError(str(exc)) from None
        return f"kept pose {k + 1} at frame {g.kept_frames[k]}"

    def _do_interpolation(self, g, body):
        method = body.get("method")
        if method not in interpolation_names():
            raise RequestError("'method' must be one of " + ", ".join(interpolation_names()))
        self.method = method
        return f"the kept poses are joined by {method} interpolation"

    def _do_play(self, g, body):
        return "playing"  # the state answered carries the frames (see act)

    def _do_keep(self, g, body):
        if len(g.kept) >= KEPT_MAX:
            raise RequestError(
                f"the studio keeps at most {KEPT_MAX} poses and {KEPT_MAX} are kept; delete one to keep another", 409
            )
        g.keep(self.spacing)
        return f"kept pose {len(g.kept)}"

    def _do_stand(self, g, body):
        g.stand()
        return "standing"

    def _do_seed(self, g, body):
        g.set_seed(_int(body, "seed", 0, SEED_MAX))
        return f"seed {g.seed}: generation 1"

    # ----------------------------------------------------------------- save
    def _snapshot(self) -> _Snapshot:
        g = self.generator
        return _Snapshot(tuple(g.kept), tuple(g.kept_frames), self.method, g.seed)

    def ask_save(self) -> int:
        """Ask for a Save: its ticket for :meth:`save`, or RequestError now if there is nothing to save.

        A Save is done when a write that began after it was asked has
        ended; so Saves asked while another is being written are written
        once, together.
        """
        with self.lock:
            if not self.generator.kept:
                raise RequestError("keep a pose first: the saved motion is made of the kept poses")
            self._saves_asked += 1
            return self._saves_asked

    def save(self, ticket: int | None = None) -> dict:
        """Write the library (model and kept poses) and return the state; Saves asked at once write once.

        The poses are copied under :attr:`lock`; the library is made,
        compiled and written outside it, so the page's state and actions
        go on meanwhile.  Saves asked while another writes wait for it;
        then the first of them writes the poses as they are by then, and
        the others find their Save done (they asked before it began).

        Parameters
        ----------
        ticket : int, optional
            From :meth:`ask_save` when the Save was asked earlier (the
            server asks when the request comes, and saves in turn).

        Raises
        ------
        RequestError
            When no pose is kept.
        LigDiagnostics
            If the library does not compile (nothing is written then).
        OSError
            If it cannot be written (the old file stays).
        """
        if ticket is None:
            ticket = self.ask_save()
        with self._save_lock:
            if self._saves_done < ticket:
                with self.lock:
                    snap, covers = self._snapshot(), self._saves_asked
                if not snap.kept:
                    raise RequestError("keep a pose first: the saved motion is made of the kept poses")
                self._write(snap)
                with self.lock:
                    self._written, self._saves_done = snap, covers
                    self._state_json = None
            written = self._written
        assert written is not None
        with self.lock:
            return self.state(f"saved {len(written.kept)} pose(s) to {self.save_path}")

    def _write(self, snap: _Snapshot) -> None:
        lib = library(
            self.generator.figure,
            self.model,
            self.motion,
            list(snap.kept),
            self.spacing,
            note=f"Seed {snap.seed}, {len(snap.kept)} pose(s) kept.",
            frames=list(snap.frames),
            method=snap.method,
        )
        if self._warming is not None:
            self._warming.join()  # at most once: the first Save waits for the check it would make itself
        digest = _digest(lib.shapes)
        known = digest in self._shapes_ok
        write_library(self.save_path, lib.text, checked_as=lib.head + lib.skeleton + lib.body if known else None)
        self._shapes_ok.add(digest)


def _digest(text: str) -> bytes:
    return hashlib.sha256(text.encode("utf-8")).digest()


def check_library(text: str, path: str) -> None:
    """Compile ``text`` as the library at ``path``; LigDiagnostics if it does not compile."""
    from liganimate.compiler import compile_source
    from liganimate.lang.source import prepare

    compile_source(prepare(text, path), path=path)


def write_library(path: str, text: str, checked_as: str | None = None) -> None:
    """Check that ``text`` compiles as a library at ``path``, then write it atomically.

    ``checked_as``, if given, is compiled instead: ``text`` with its
    PRIMITIVEs' drawing cut short (:class:`._library.Library`), whose
    full PRIMITIVEs have compiled before.

    Raises
    ------
    LigDiagnostics
        If it does not compile (nothing is written then).
    OSError
        If it cannot be written (the old file stays).
    """
    from liganimate.runtime.exchange import write_files

    check_library(text if checked_as is None else checked_as, path)
    write_files([(path, text.encode("utf-8"))])


def _three(values) -> tuple[float, float, float]:
    """A joint's kept value (three angles, or a slide's three lengths) as plain floats."""
    x, y, z = (float(a) for a in values)
    return (x, y, z)
