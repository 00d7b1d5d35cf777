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
