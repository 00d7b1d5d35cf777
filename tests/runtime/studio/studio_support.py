"""A running studio for the studio's tests: a session served on loopback from a thread of the test process."""

from __future__ import annotations

import contextlib
import pathlib
from collections.abc import Iterator

from liganimate.runtime.studio import Session, StudioServer, start_in_thread, studio_page


@contextlib.contextmanager
def running_studio(fig, model: str, save: pathlib.Path, seed: int) -> Iterator[tuple[StudioServer, Session]]:
    """Serve a studio session that poses ``fig`` and saves the motion POSES to ``save``.

    Parameters
    ----------
    fig : Figure
        The model to pose.
    model : str
        Its name, as the page and the saved library give it.
    save : pathlib.Path
        The library file Save writes.
    seed : int
        The Generator's seed, so that the candidates are the same on every run.

    Yields
    ------
    (StudioServer, Session)
        The server, already answering at ``server.url``, and its session.  On
        leaving the block the server is shut down and its socket closed.
    """
    session = Session(fig, model, "POSES", str(save), seed=seed)
    server = StudioServer(session, studio_page(session.generator, model))
    start_in_thread(server)
    try:
        yield server, session
    finally:
        server.shutdown()
        server.server_close()
