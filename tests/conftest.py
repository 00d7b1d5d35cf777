"""Shared test options: --regen-golden rewrites golden images and compiled modules on purpose."""

import pytest


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
