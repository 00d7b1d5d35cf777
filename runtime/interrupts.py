"""SIGINT and SIGTERM as one clean stop: the first signal interrupts, later ones cannot cut the cleanup short.

The ``liganimate`` command installs :func:`stop_on_signals`.  The first
SIGINT or SIGTERM raises :class:`Interrupted` in the main thread, wherever
it is; the ``finally`` blocks on the way out then wait for the images being
written, stop the worker processes and remove temporary files.  From that
first signal on, both signals are ignored: ``timeout -s INT`` sends SIGINT
twice (to the command and to its process group) within a millisecond, and
a second KeyboardInterrupt raised inside the cleanup would skip the rest of
it and print a traceback.
"""

from __future__ import annotations

import os
import signal
import threading

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupted(KeyboardInterrupt):
    """A stop asked for by a signal.  A KeyboardInterrupt, so code that lets Ctrl-C through lets this through.

    Parameters
    ----------
    signum : int
        The signal received (``signal.SIGINT`` or ``signal.SIGTERM``).
    """

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


_owner = None  # the process whose handlers these are (a forked child ignores them)
_stopping = False
_received: list = []  # every signal noted since stop_on_signals, in the order handled


def _on_signal(signum, frame) -> None:
    global _stopping
    if os.getpid() != _owner:
        return  # a forked worker before its own set-up
    _received.append(signum)
    if _stopping:
        return  # the stop is under way: note the signal, let the cleanup finish
    _stopping = True
    raise Interrupted(signum)


def ignore_signals() -> None:
    """From now on SIGINT and SIGTERM are only noted (cleanup must run to its end).

    The handler stays installed rather than becoming SIG_IGN: CPython
    raises "Signal N ignored due to race condition" for a signal already
    received when its handler is changed to SIG_IGN, which is exactly the
    case of two signals at once.
    """
    global _stopping
    _stopping = True


def stopped_by() -> int:
    """The signal to report for the stop: SIGTERM if one came at all (termination was asked), else SIGINT."""
    return signal.SIGTERM if signal.SIGTERM in _received else signal.SIGINT


def stop_on_signals() -> bool:
    """Make the first SIGINT or SIGTERM raise :class:`Interrupted`; False if not possible (not the main thread).

    A signal whose disposition was SIG_IGN when the command started (a
    background job of a non-interactive shell ignores SIGINT) stays ignored,
    as it does for any well-behaved program.
    """
    global _owner, _stopping
    if threading.current_thread() is not threading.main_thread():
        return False
    _owner, _stopping = os.getpid(), False
    _received.clear()
    for s in SIGNALS:
        if signal.getsignal(s) is not signal.SIG_IGN:
            signal.signal(s, _on_signal)
    return True


def restore_signals() -> None:
    """Give SIGINT and SIGTERM back their usual handlers (after a run that was not interrupted)."""
    global _owner
    if threading.current_thread() is not threading.main_thread():
        return
    for s, default in ((signal.SIGINT, signal.default_int_handler), (signal.SIGTERM, signal.SIG_DFL)):
        if signal.getsignal(s) is _on_signal:
            signal.signal(s, default)
    _owner = None


__all__ = ["Interrupted", "ignore_signals", "restore_signals", "stop_on_signals", "stopped_by"]
