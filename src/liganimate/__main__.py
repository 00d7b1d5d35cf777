"""``python -m liganimate``, and the smallest possible entry point for the ``liganimate`` command."""

import sys


def run() -> int:
    """Import and run the command; a Ctrl-C that lands while it is still importing ends it quietly (status 130).

    Once :func:`liganimate.cli.main` runs, it handles SIGINT and SIGTERM
    itself; before that (importing the command takes a few tens of
    milliseconds) a KeyboardInterrupt would otherwise print a traceback.
    """
    try:
        from liganimate.lang import collector

        with collector.paused():  # importing the command makes no garbage for the collector to look for
            from liganimate.cli import main

        return main()
    except KeyboardInterrupt:
        sys.stderr.write("\nliganimate: interrupted; nothing was written\n")
        return 130


if __name__ == "__main__":
    sys.exit(run())
