"""Interpolation methods: the ease curves that carry a joint between keyframes.

A method object has a ``name``, the name of the method it becomes when time
runs backwards (``reverse``), and a vectorized ``ease(u)`` returning the
curve and its first two derivatives on ``0 <= u <= 1``.  The registry maps
case-insensitive names to methods.  Third-party packages add methods through
the ``liganimate.interpolations`` entry-point group; those are only imported
the first time a name is not found, so importing liganimate stays fast.

LINEAR is special: its ease curve is the straight line, but the motion layer
replaces it with a trapezoidal velocity profile.  Every other method is used
with its exact ease curve ("fixed shape") where its neighbours meet it at
its natural velocities ``(D/T) e'(0)`` and ``(D/T) e'(1)``, and as a
monotone cubic Hermite where the velocity adjustment gives it others (see
``docs/semantics-motion.md`` and ``liganimate.runtime.motion.track``).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Protocol, runtime_checkable

import numpy as np

ENTRY_POINT_GROUP = "liganimate.interpolations"

__all__ = [
    "ACCDCC",
    "ACCELERATE",
    "DECELERATE",
    "ENTRY_POINT_GROUP",
    "LINEAR",
    "InterpolationMethod",
    "Method",
    "get",
    "names",
    "register",
    "unregister",
]


@runtime_checkable
class InterpolationMethod(Protocol):
    """What the motion runtime needs from an interpolation method.

    Attributes
    ----------
    name : str
        Upper-case name used in programs (``INTERPOLATE name``).
    reverse : str
        Name of the method that traces this curve backwards, i.e. whose ease
        is ``1 - e(1 - u)``.  A method symmetric in time names itself.
    """

    name: str
    reverse: str

    def ease(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Ease curve ``e(u)`` with ``e(0) = 0`` and ``e(1) = 1``.

        Parameters
        ----------
        u : ndarray, shape (N,)
            Normalized times in ``[0, 1]``.

        Returns
        -------
        e, de, d2e : ndarray, each shape (N,)
            ``e(u)``, ``de/du`` and ``d2e/du2``.
        """
        ...


class Method:
    """An interpolation method built from three vectorized functions.

    Parameters
    ----------
    name : str
        Method name; stored upper-case.
    reverse : str
        Name of the time-reversed method; stored upper-case.
    e, de, d2e : callable
        Each maps an ndarray of shape (N,) to an ndarray of shape (N,).
    """

    __slots__ = ("_d2e", "_de", "_e", "name", "reverse")

    def __init__(
        self,
        name: str,
        reverse: str,
        e: Callable[[np.ndarray], np.ndarray],
        de: Callable[[np.ndarray], np.ndarray],
        d2e: Callable[[np.ndarray], np.ndarray],
    ):
        self.name = name.upper()
        self.reverse = reverse.upper()
        self._e, self._de, self._d2e = e, de, d2e

    def ease(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Ease curve and derivatives.

        Parameters
        ----------
        u : array_like, shape (N,)
            Normalized times in ``[0, 1]``.

        Returns
        -------
        e, de, d2e : ndarray, each shape (N,)
        """
        u = np.asarray(u, dtype=float)
        return (
            np.broadcast_to(self._e(u), u.shape).astype(float),
            np.broadcast_to(self._de(u), u.shape).astype(float),
            np.broadcast_to(self._d2e(u), u.shape).astype(float),
        )

    def __reduce__(self):
        # Pickled by name: the curves are lambdas, and a registered name means the same curve.
        return (get, (self.name,))

    def __repr__(self) -> str:
        return f"Method({self.name!r}, reverse={self.reverse!r})"


def _accdcc(u: np.ndarray) -> np.ndarray:
    # Written from the nearer end so e(1 - u) = 1 - e(u) holds bit for bit.
    return np.where(u < 0.5, 2.0 * u * u, 1.0 - 2.0 * (1.0 - u) ** 2)


LINEAR = Method("LINEAR", "LINEAR", lambda u: u, lambda u: np.ones_like(u), lambda u: np.zeros_like(u))
ACCELERATE = Method("ACCELERATE", "DECELERATE", lambda u: u * u, lambda u: 2.0 * u, lambda u: np.full_like(u, 2.0))
DECELERATE = Method(
    "DECELERATE",
    "ACCELERATE",
    lambda u: 1.0 - (1.0 - u) ** 2,
    lambda u: 2.0 * (1.0 - u),
    lambda u: np.full_like(u, -2.0),
)
ACCDCC = Method(
    "ACCDCC",
    "ACCDCC",
    _accdcc,
    lambda u: np.where(u < 0.5, 4.0 * u, 4.0 * (1.0 - u)),
    lambda u: np.where(u < 0.5, 4.0, -4.0),
)

_BUILTINS = {m.name: m for m in (LINEAR, ACCELERATE, DECELERATE, ACCDCC)}
_registry: dict[str, InterpolationMethod] = dict(_BUILTINS)
_plugins_loaded = False


def _check(method: InterpolationMethod) -> InterpolationMethod:
    """Reject objects that would fail later, deep inside an evaluation.

    The annotation is what :func:`register`'s caller promises; plugins are
    not type-checked, so every part of the promise is verified here.
    """
    for attr in ("name", "reverse"):
        if not isinstance(getattr(method, attr, None), str):
            raise TypeError(f"interpolation method {method!r} needs a string attribute {attr!r}")
    if not callable(getattr(method, "ease", None)):
        raise TypeError(f"interpolation method {method.name!r} needs an ease(u) method")
    e, de, d2e = method.ease(np.array([0.0, 1.0]))
    if not (np.shape(e) == np.shape(de) == np.shape(d2e) == (2,)):
        raise TypeError(f"{method.name}.ease must return three arrays shaped like its input")
    if not np.allclose(e, [0.0, 1.0], atol=1e-12):
        raise ValueError(f"{method.name}.ease must satisfy e(0) = 0 and e(1) = 1")
    return method


def register(method: InterpolationMethod) -> InterpolationMethod:
    """Add an interpolation method to the registry.

    Parameters
    ----------
    method : InterpolationMethod
        Object with ``name``, ``reverse`` and ``ease(u)``.

    Returns
    -------
    InterpolationMethod
        The method itself, so this can be used as a decorator-style call.

    Raises
    ------
    ValueError
        If another method is already registered under the same name (built-ins
        cannot be replaced: saved motions must keep meaning what they meant).
    """
    _check(method)
    key = method.name.upper()
    existing = _registry.get(key)
    if existing is not None and existing is not method:
        raise ValueError(f"an interpolation method named {key} is already registered")
    _registry[key] = method
    return method


def unregister(name: str) -> None:
    """Remove a non-built-in method (mostly for tests and interactive sessions).

    Parameters
    ----------
    name : str
        Method name, any case.
    """
    key = name.upper()
    if key in _BUILTINS:
        raise ValueError(f"the built-in method {key} cannot be removed")
    _registry.pop(key, None)


def _load_plugins() -> None:
    """Import every entry point of the group once; a broken plugin only warns."""
    global _plugins_loaded
    if _plugins_loaded:
        return
    _plugins_loaded = True
    # Imported here: importlib.metadata (and the email package it pulls in)
    # costs a cold start ~10 ms, and only a name no built-in has needs it.
    import importlib.metadata

    for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        try:
            method = ep.load()
            if method.name.upper() in _registry:
                continue  # an explicit register() wins over an installed plugin
            register(method)
        except Exception as exc:  # noqa: BLE001 - one bad plugin must not break the others
            warnings.warn(f"interpolation plugin {ep.name!r} could not be loaded: {exc}", RuntimeWarning, stacklevel=2)


def get(name: str) -> InterpolationMethod:
    """Look up a method by name, loading plugins the first time a name is missing.

    Parameters
    ----------
    name : str
        Method name, any case.

    Returns
    -------
    InterpolationMethod

    Raises
    ------
    KeyError
        If no built-in, registered or installed method has that name.
    """
    key = str(name).upper()
    method = _registry.get(key)
    if method is None:
        _load_plugins()
        method = _registry.get(key)
    if method is None:
        raise KeyError(key)
    return method


def names() -> tuple[str, ...]:
    """All known method names, installed plugins included.

    Returns
    -------
    tuple of str
        Sorted upper-case names.
    """
    _load_plugins()
    return tuple(sorted(_registry))
