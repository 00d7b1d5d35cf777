"""The work budgets of a scene: how much one scene may ask for, estimated before the work is done.

Legal input can ask for more than a machine gives in a sitting: a humanoid
walk of the longest scene (``LENGTH 10000000``) takes hours to check. So the
runtime estimates a scene's work when its ticks begin and refuses, at the
scene's LENGTH, one whose estimate is over its budget, naming the budget and
the environment variable that raises it (docs/security.md, "The resource
model", lists every budget):

* **joint-ticks**: each tick of a scene poses every model its ANIMATE
  statements name, so a scene costs about ``ticks x (joints posed a tick + 1)``
  (a humanoid of 14 joints is checked at some 80,000 joint-ticks a second).
  The estimate is made after the scene's first tick and again every
  :data:`~liganimate.runtime.host.PROGRESS_TICKS` ticks (the work done, plus
  the rest of the scene at the rate of the latest ticks), so an ANIMATE that
  starts late is counted when it starts. ``$LIGANIMATE_MAX_JOINT_TICKS``,
  default 50,000,000 (about ten minutes).
* **frames**: the frames one scene of a render draws, ``ceil(LENGTH /
  SAMEFRAME)``. ``$LIGANIMATE_MAX_FRAMES``, default 1,000,000 (eleven hours of
  film at 24 frames a second).

And one budget of a model:

* **joints of a model**: a model is a value, so each JOINT that grows one
  copies its joints (at C speed, but the copies of a model built one JOINT at
  a time add up with the square of its joints: 20,000 joints take about 9 s
  of CPU). A JOINT or STARTMODEL block that would make a model of more
  joints is refused at its place. ``$LIGANIMATE_MAX_MODEL_JOINTS``, default
  25,000.
"""

from __future__ import annotations

import os

from liganimate.runtime.errors import LigError

#: The environment variable that sets the joint-ticks one scene may take.
JOINT_TICKS_ENV = "LIGANIMATE_MAX_JOINT_TICKS"
#: The default budget of joint-ticks of one scene.
DEFAULT_JOINT_TICKS = 50_000_000
#: The environment variable that sets the frames one scene of a render may draw.
FRAMES_ENV = "LIGANIMATE_MAX_FRAMES"
#: The default budget of frames of one scene.
DEFAULT_FRAMES = 1_000_000
#: The environment variable that sets the joints one model may have.
MODEL_JOINTS_ENV = "LIGANIMATE_MAX_MODEL_JOINTS"
#: The default budget of joints of one model (a 20,000-joint chain builds in about 9 s of CPU).
DEFAULT_MODEL_JOINTS = 25_000


def budget(env: str, default: int) -> int:
    """The whole number in ``$env``, or ``default`` when it is unset or empty.

    Raises
    ------
    LigError
        When the variable is set to something other than a whole number from 1.
    """
    text = os.environ.get(env, "").strip()
    if not text:
        return default
    if not text.isdigit() or int(text) < 1:
        raise LigError(f"{env}={text!r} is not a budget; give a whole number such as {default}")
    return int(text)


def check_joint_ticks(length: int, tick: int, done: int, rate: float) -> None:
    """Refuse a scene whose estimated work is over the budget of joint-ticks.

    Parameters
    ----------
    length : int
        The scene's LENGTH.
    tick : int
        Ticks run so far (at least 1).
    done : int
        Joint-ticks of work done in them (the joints posed, plus one a tick).
    rate : float
        Joint-ticks a tick in the most recent ticks, the rate assumed for the rest.

    Raises
    ------
    LigError
        One sentence naming the estimate and the budget, and a hint naming the variable.
    """
    limit = budget(JOINT_TICKS_ENV, DEFAULT_JOINT_TICKS)
    need = int(done + (length - tick) * rate)
    if need > limit:
        raise LigError(
            f"this scene of {length:,} ticks poses about {rate:,.0f} joints a tick, some {need:,} "
            f"joint-ticks of work, over the budget of {limit:,} joint-ticks for one scene",
            f"shorten the scene or animate fewer joints, or raise the budget with {JOINT_TICKS_ENV}={need}",
        )


def check_frames(length: int, sameframe: int) -> None:
    """Refuse a scene of a render whose frames, ``ceil(length / sameframe)``, are over the budget.

    Raises
    ------
    LigError
        One sentence naming the frames and the budget, and a hint naming the variable.
    """
    limit = budget(FRAMES_ENV, DEFAULT_FRAMES)
    frames = -(-length // sameframe)
    if frames > limit:
        raise LigError(
            f"this scene would draw {frames:,} frames, over the budget of {limit:,} frames for one scene",
            f"shorten the scene, show each frame longer with SAMEFRAME, or raise the budget with {FRAMES_ENV}={frames}",
        )


def check_model_joints(count: int) -> None:
    """Refuse a model of more joints than the budget allows, before it is built.

    Parameters
    ----------
    count : int
        The joints the model would have.

    Raises
    ------
    LigError
        One sentence naming the count and the limit, and a hint naming the variable.
    """
    limit = budget(MODEL_JOINTS_ENV, DEFAULT_MODEL_JOINTS)
    if count > limit:
        raise LigError(
            f"this model would have {count:,} joints, over the limit of {limit:,} joints for one model",
            "each JOINT copies the model it grows, so the cost of building one grows with the square "
            f"of its joints; split the figure, or raise the limit with {MODEL_JOINTS_ENV}={count}",
        )
