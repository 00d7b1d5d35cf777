"""The studio tests' models: the standard library's HUMANOID and the Appendix A human, built once a module."""

import pytest

from liganimate.runtime.studio import studio_model


@pytest.fixture(scope="module")
def humanoid():
    """The standard library's HUMANOID, the model `liganimate studio` poses when it is given none."""
    fig, name, _ = studio_model(None, None)
    assert name == "HUMANOID"
    return fig


@pytest.fixture(scope="module")
def human():
    """The Appendix A human: other axes, repeated segment names, extremes that exclude 0."""
    return studio_model(None, "HUMAN")[0]
