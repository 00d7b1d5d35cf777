"""Shared test options: --regen-golden rewrites golden images and compiled modules on purpose.

Property tests are derandomized: Hypothesis draws the same examples on every
run and keeps no example database, so CI and a laptop test the same cases
and a failure is reproduced by running the test again. Set
LIGANIMATE_HYPOTHESIS=explore to draw fresh examples when hunting for bugs.
"""

import os

import pytest
from hypothesis import settings

settings.register_profile("reproducible", derandomize=True, database=None)
settings.register_profile("explore", database=None)
settings.load_profile("explore" if os.environ.get("LIGANIMATE_HYPOTHESIS") == "explore" else "reproducible")


def pytest_addoption(parser):
    parser.addoption(
        "--regen-golden",
        action="store_true",
        default=False,
        help="rewrite tests/golden/ from the current renderer (commit with a message saying why)",
    )


@pytest.fixture
def regen_golden(request):
    return request.config.getoption("--regen-golden")


@pytest.fixture(autouse=True, scope="session")
def _private_library_cache(tmp_path_factory):
    """Compiled libraries go to a folder of this run, never the user's ~/.cache (subprocesses inherit it)."""
    import os

    old = os.environ.get("LIGANIMATE_CACHE")
    os.environ["LIGANIMATE_CACHE"] = str(tmp_path_factory.mktemp("library-cache"))
    yield
    if old is None:
        os.environ.pop("LIGANIMATE_CACHE", None)
    else:
        os.environ["LIGANIMATE_CACHE"] = old
