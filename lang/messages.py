"""Sentences that more than one stage says: each rule worded once.

The checker reports what it can see in the text (literal frames); the
runtime reports the same rule for computed values. Both call these, so the
program's author reads one sentence for one rule, whichever stage found it.
"""

from __future__ import annotations

from collections.abc import Iterable

from .numbers import MIN_FRAME_GAP


def closest(name: str, candidates: Iterable[str], n: int = 3, cutoff: float = 0.6) -> list:
    """The known names closest to ``name`` (compared upper-cased), best first, for 'did you mean' hints."""
    import difflib  # only a wrong name needs it: a correct program's start does not pay for it

    return difflib.get_close_matches(name.upper(), sorted({c.upper() for c in candidates}), n=n, cutoff=cutoff)


def did_you_mean(name: str, candidates: Iterable[str], cutoff: float = 0.6) -> str | None:
    """The one 'did you mean' hint: a sentence naming the closest known names, or None if none is close."""
    near = closest(name, candidates, cutoff=cutoff)
    if not near:
        return None
    if len(near) == 1:
        return f"did you mean {near[0]}?"
    return "did you mean " + ", ".join(near[:-1]) + " or " + near[-1] + "?"


def sentence(message: str) -> str:
    """A message as liganimate prints it: no final period, a lower-case start unless it opens with a word in capitals.

    Runtime libraries write full sentences (``"The VIEW WIDTH must be
    positive."``); a diagnostic and ``liganimate: error:`` print them in the
    house style: ``the VIEW WIDTH must be positive``.
    """
    message = message.strip()
    if message.endswith(".") and not message.endswith(".."):
        message = message[:-1]
    return message[:1].lower() + message[1:] if message[:2] != message[:2].upper() else message


def _num(x) -> str:
    return str(x) if isinstance(x, int) else f"{x:g}"


def _frame(frame, where: str | None) -> str:
    return f"frame {_num(frame)} ({where})" if where else f"frame {_num(frame)}"


def keyframes_out_of_order(frame, previous, where: str | None = None) -> str:
    """Keyframes must ascend: ``frame`` comes after a keyframe at ``previous``.

    ``where`` names the keyframe when the statement alone does not
    (``"keyframe 3 of joint 2"``).
    """
    return f"keyframes must be in ascending frame order: {_frame(frame, where)} comes after frame {_num(previous)}"


def keyframes_too_close(frame, previous, where: str | None = None) -> str:
    """Two keyframes closer than :data:`~.numbers.MIN_FRAME_GAP` frames apart (and not a step)."""
    return f"{_frame(frame, where)} is too close after frame {_num(previous)}"


#: The hint under :func:`keyframes_too_close`.
GAP_HINT = f"two keyframes of a joint share a frame (a step) or lie at least {MIN_FRAME_GAP:g} frames apart"
