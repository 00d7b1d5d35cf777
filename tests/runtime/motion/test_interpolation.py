"""The interpolation registry, the built-in ease curves and plugin loading."""

from __future__ import annotations

import importlib.metadata

import numpy as np
import pytest

from liganimate.runtime.errors import MotionError
from liganimate.runtime.motion import interpolation as I
from liganimate.runtime.motion.algebra import Motion
from liganimate.runtime.motion.keyframe import Keyframe

BUILTINS = ["LINEAR", "ACCELERATE", "DECELERATE", "ACCDCC"]
U = np.linspace(0.0, 1.0, 101)


@pytest.fixture
def fresh_registry(monkeypatch):
    """Let a test register methods or reload plugins without leaking into others."""
    monkeypatch.setattr(I, "_registry", dict(I._BUILTINS))
    monkeypatch.setattr(I, "_plugins_loaded", False)


def make_smoothstep(name="SMOOTHSTEP"):
    return I.Method(
        name,
        name,  # 3u^2 - 2u^3 is symmetric in time
        lambda u: u * u * (3 - 2 * u),
        lambda u: 6 * u * (1 - u),
        lambda u: 6 - 12 * u,
    )


@pytest.mark.parametrize("name", BUILTINS)
def test_ease_curves_run_from_0_to_1(name):
    e, de, d2e = I.get(name).ease(U)
    assert e.shape == de.shape == d2e.shape == U.shape
    assert e[0] == 0.0 and e[-1] == 1.0
    assert np.all(np.diff(e) >= 0)


@pytest.mark.parametrize("name", BUILTINS)
def test_ease_derivatives_match_finite_differences(name):
    u = np.array([0.1, 0.3, 0.45, 0.55, 0.7, 0.9])  # away from ACCDCC's switch at 1/2
    h = 1e-6
    e, de, d2e = I.get(name).ease(u)
    ep, dep, _ = I.get(name).ease(u + h)
    em, dem, _ = I.get(name).ease(u - h)
    np.testing.assert_allclose(de, (ep - em) / (2 * h), atol=1e-7)
    np.testing.assert_allclose(d2e, (dep - dem) / (2 * h), atol=1e-6)


@pytest.mark.parametrize("name", BUILTINS)
def test_reverse_method_traces_the_curve_backwards(name):
    m = I.get(name)
    r = I.get(m.reverse)
    assert I.get(r.reverse) is m
    np.testing.assert_allclose(r.ease(U)[0], 1.0 - m.ease(1.0 - U)[0], atol=1e-15)


def test_boundary_velocities_of_the_builtins():
    starts = {n: I.get(n).ease(np.array([0.0, 1.0]))[1] for n in BUILTINS}
    assert list(starts["ACCELERATE"]) == [0.0, 2.0]  # starts at rest
    assert list(starts["DECELERATE"]) == [2.0, 0.0]  # ends at rest
    assert list(starts["ACCDCC"]) == [0.0, 0.0]  # both
    assert list(starts["LINEAR"]) == [1.0, 1.0]


def test_accdcc_is_symmetric_bit_for_bit():
    u = np.arange(65) / 64.0  # dyadic, so 1 - u is exact and the test sees only the curve's rounding
    e = I.ACCDCC.ease(u)[0]
    assert np.array_equal(I.ACCDCC.ease(1.0 - u)[0], 1.0 - e)
    assert I.ACCDCC.ease(np.array([0.5]))[0][0] == 0.5


def test_names_are_case_insensitive_and_unknown_names_raise_keyerror():
    assert I.get("linear") is I.LINEAR
    assert I.get("AccDcc") is I.ACCDCC
    with pytest.raises(KeyError):
        I.get("WOBBLE")
    assert set(BUILTINS) <= set(I.names())
    assert list(I.names()) == sorted(I.names())


def test_register_rejects_a_clash_and_bad_objects(fresh_registry):
    with pytest.raises(ValueError):
        I.register(I.Method("LINEAR", "LINEAR", lambda u: u, lambda u: 1 + 0 * u, lambda u: 0 * u))
    with pytest.raises(ValueError):
        I.register(I.Method("HALF", "HALF", lambda u: u / 2, lambda u: 0 * u + 0.5, lambda u: 0 * u))
    with pytest.raises(TypeError):
        I.register(object())
    with pytest.raises(ValueError):
        I.unregister("LINEAR")


def test_a_registered_method_drives_a_motion(fresh_registry):
    I.register(make_smoothstep())
    m = Motion.from_tracks({1: ((0, 0, 0), [Keyframe(10.0, (100.0, 0, -50.0), "smoothstep")])})
    x, v, a = m.evaluate_full(np.array([0.0, 2.5, 5.0, 7.5, 10.0]))
    u = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    np.testing.assert_allclose(x[:, 0, 0], 100 * u * u * (3 - 2 * u))
    np.testing.assert_allclose(x[:, 0, 2], -50 * u * u * (3 - 2 * u))
    np.testing.assert_allclose(v[1:4, 0, 0], 100 / 10 * 6 * u[1:4] * (1 - u[1:4]))
    np.testing.assert_allclose(a[1:4, 0, 0], 100 / 100 * (6 - 12 * u[1:4]))
    # It also reverses, because it names itself as its own reverse.
    back = m.scale_frames(-1)
    t = np.linspace(0, 10, 41)
    np.testing.assert_allclose(back.evaluate(t), m.evaluate(10 - t), atol=1e-12)
    assert back.keyframes(1)[1][-1].method == "SMOOTHSTEP"


def test_unknown_method_in_a_motion_is_a_motion_error_listing_known_ones(fresh_registry):
    with pytest.raises(MotionError) as err:
        Motion.from_tracks({4: ((0, 0, 0), [Keyframe(1.0, (1, 2, 3), "LINEAR"), Keyframe(2.0, (0, 0, 0), "WOBBLE")])})
    assert "joint 4" in err.value.message and "keyframe 2" in err.value.message
    assert "WOBBLE" in err.value.message and "ACCDCC" in err.value.hint


class FakeEntryPoint:
    def __init__(self, name, obj):
        self.name, self._obj, self.loads = name, obj, 0

    def load(self):
        self.loads += 1
        if isinstance(self._obj, Exception):
            raise self._obj
        return self._obj


def test_plugins_load_lazily_from_entry_points(fresh_registry, monkeypatch):
    plugin = FakeEntryPoint("smoothstep", make_smoothstep())
    broken = FakeEntryPoint("broken", ImportError("no such module"))
    groups = []

    def entry_points(*, group):
        groups.append(group)
        return [plugin, broken]

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)
    I.get("LINEAR")
    assert groups == [], "a known name must not touch the installed plugins"
    with pytest.warns(RuntimeWarning, match="broken"):
        assert I.get("SmoothStep").name == "SMOOTHSTEP"
    assert groups == [I.ENTRY_POINT_GROUP] and plugin.loads == 1
    with pytest.raises(KeyError):
        I.get("STILL-UNKNOWN")
    assert groups == [I.ENTRY_POINT_GROUP], "entry points are scanned only once"
    m = Motion.from_tracks({1: (None, [Keyframe(4.0, (8, 0, 0), "smoothstep")])})
    assert m.evaluate([2.0])[0, 0, 0] == pytest.approx(4.0)


def test_names_includes_plugins(fresh_registry, monkeypatch):
    monkeypatch.setattr(
        importlib.metadata, "entry_points", lambda *, group: [FakeEntryPoint("s", make_smoothstep("PLUGGED"))]
    )
    assert "PLUGGED" in I.names()


def test_a_plugin_does_not_replace_a_registered_method(fresh_registry, monkeypatch):
    mine = I.register(make_smoothstep("MINE"))
    theirs = FakeEntryPoint("mine", make_smoothstep("MINE"))
    monkeypatch.setattr(importlib.metadata, "entry_points", lambda *, group: [theirs])
    assert "MINE" in I.names()
    assert I.get("mine") is mine
