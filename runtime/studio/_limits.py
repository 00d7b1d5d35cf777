"""The studio server's limits: how many requests it works on, holds and waits for, in one value.

Every number here bounds a cost up front, so that a crowd of clients, a
slow one or a hostile one gets an answer (or is dropped) instead of
growing the server's threads and memory (issue 24).  The defaults suit one
person at one browser with room to spare; each can be changed with an
environment variable, read once when ``liganimate studio`` starts
(:meth:`StudioLimits.from_environment`).  ``docs/security.md`` states them.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, fields

from liganimate.runtime.errors import LigError

__all__ = ["ENVIRONMENT", "StudioLimits"]


@dataclass(frozen=True)
class StudioLimits:
    """How much the studio's server takes on at once, and how long it waits.

    Attributes
    ----------
    workers : int
        Threads that answer requests (a fixed pool, started with the server).
    queue : int
        Whole requests that may wait for a worker; one more is answered
        503 with ``Retry-After``.
    connections : int
        Open connections; one more is answered 503 at once and closed.
    request_timeout : float
        Seconds from a request's first byte to its last: a client that
        sends slower (one byte a second, say) gets 408 and is dropped.
    idle_timeout : float
        Seconds a kept-alive connection may stay silent between requests.
    write_timeout : float
        Seconds a client has to read its answer.
    max_head : int
        Bytes of a request line and headers (over: 431).
    max_body : int
        Bytes of a body (over: 413, the body is not read).
    """

    workers: int = 4
    queue: int = 64
    connections: int = 128
    request_timeout: float = 10.0
    idle_timeout: float = 30.0
    write_timeout: float = 30.0
    max_head: int = 64 * 1024
    max_body: int = 64 * 1024

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
                raise ValueError(f"the studio's {f.name} must be a positive number, not {value!r}")

    @classmethod
    def from_environment(cls, env: Mapping[str, str] | None = None) -> StudioLimits:
        """The defaults, with any ``LIGANIMATE_STUDIO_*`` variable of :data:`ENVIRONMENT` applied.

        Parameters
        ----------
        env : mapping, optional
            The environment (default ``os.environ``).

        Raises
        ------
        LigError
            When a variable is set to something that is not a positive number.
        """
        env = os.environ if env is None else env
        values: dict = {}
        for name, var in ENVIRONMENT.items():
            text = env.get(var, "").strip()
            if not text:
                continue
            whole = isinstance(getattr(cls, name), int)
            try:
                value = int(text) if whole else float(text)
            except ValueError:
                value = 0
            if not 0 < value < 10**9:
                kind = "whole number" if whole else "number of seconds"
                raise LigError(
                    f"{var}={text!r} is not a positive {kind}.", f"unset it for the default {getattr(cls, name)}"
                )
            values[name] = value
        return cls(**values)


#: The environment variable that sets each limit.
ENVIRONMENT = {f.name: "LIGANIMATE_STUDIO_" + f.name.upper() for f in fields(StudioLimits)}
