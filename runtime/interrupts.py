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

    @property
    def exit_status(self) -> int:
        """128 + the signal's number, as a shell reports a command stopped by it (130, 143)."""
        return 128 + int(self.signum)

    @property
    def name(self) -> str:
        """The signal's name, e.g. ``SIGTERM``."""
        return signal.Signals(self.signum).name


_owner = None  # the process whose handlers these are (a forked child ignores them)
_stopping = False


def _on_signal(signum, frame) -> None:
    global _stopping
    if os.getpid() != _owner or _stopping:
        # A forked worker before its own set-up, or a signal after the first: the stop is under way.
        return
    _stopping = True
    ignore_signals()
    raise Interrupted(signum)


def ignore_signals() -> None:
    """Ignore SIGINT and SIGTERM from now on in this process (cleanup must run to its end)."""
    for s in SIGNALS:
        signal.signal(s, signal.SIG_IGN)


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


__all__ = ["Interrupted", "ignore_signals", "restore_signals", "stop_on_signals"]
