"""Dataclasses made quickly: their methods written out once, not compiled at every start.

``@dataclass`` writes each class's ``__init__``, ``__repr__`` and ``__eq__``
(and a frozen one's ``__hash__``) as Python source and compiles it with
``exec`` when the class is made, at every start: for the sixty-odd node
classes of lang/ast.py and the twenty-odd records a ``liganimate check``
also makes (the vocabulary's entries, the checker's scopes, the host's
arguments) that was about 30 ms, a third of what a cold check cost beyond
importing NumPy and Lark. :func:`record` makes the same class: it is still
a dataclass (``dataclasses.fields``, ``replace`` and the field metadata
work as before, with slots or frozen as asked), but those methods come from
``lang/_node_methods.py``, where the source dataclasses would write is kept
already compiled (as pycparser keeps its node classes in a generated
module). :func:`node`, the syntax tree's, is ``record(slots=True)``. The
module is generated from the classes themselves::

    python -m liganimate.lang.node_methods          # rewrite lang/_node_methods.py
    python -m liganimate.lang.node_methods --check  # exit 1 if it is stale

A class whose fields differ from what the module was written for (an edited
class not yet regenerated) gets its methods compiled here, from the same
source, at the old cost; tests/lang/test_node_methods.py fails until the
module is regenerated, and checks the methods behave as ``@dataclass``'s.
Fields are plain: a default or a default factory at most (no ``init=False``,
``repr=False``, ``compare=False`` or keyword-only fields, no ``__post_init__``);
a class that needs more keeps ``@dataclass``.
"""

from __future__ import annotations

import dataclasses
import importlib
import importlib.util
import inspect
import os
import re
import reprlib
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, dataclass_transform, overload

_MODULE = "_node_methods.py"


class _Factory:
    """The default of a field made by a factory (``@dataclass`` shows it as ``<factory>`` too)."""

    def __repr__(self) -> str:
        return "<factory>"


#: Stands for "call the field's default factory" in a generated ``__init__``.
FACTORY = _Factory()

#: Every class made by :func:`record`, in the order they were made (what the generator writes out).
MADE: list = []
#: Those of them with a docstring of their own (the others get @dataclass's, their signature).
_OWN_DOC: set = set()


def shape(cls: type) -> tuple:
    """What a class's generated methods depend on: frozen or not, and each field's name, kind of default and annotation."""
    if hasattr(cls, "__post_init__"):
        raise TypeError(f"{cls.__qualname__}: a record has no __post_init__ (use @dataclass)")
    out: list = [("frozen", cls.__dataclass_params__.frozen)]  # type: ignore[attr-defined]
    for f in dataclasses.fields(cls):
        if f.default_factory is not dataclasses.MISSING:
            kind = "factory"
        elif f.default is not dataclasses.MISSING:
            kind = "default"
        else:
            kind = "required"
        if not (f.init and f.repr and f.compare) or f.kw_only:
            raise TypeError(
                f"{cls.__qualname__}.{f.name}: a record's fields are plain (init, repr, compare, positional)"
            )
        out.append((f.name, kind, f.type if isinstance(f.type, str) else repr(f.type)))
    return tuple(out)


def source(cls: type, maker: str) -> str:
    """The source of the function ``maker`` that makes ``cls``'s ``__init__``, ``__repr__``, ``__eq__`` and ``__hash__``.

    It is what ``@dataclass`` writes, given the fields' defaults (``_d``)
    and factories (``_f``) by name; ``__hash__`` is None but for a frozen
    class. Field names are Python identifiers declared in the classes,
    never program text.
    """
    (_, frozen), *spec = shape(cls)
    params, body = ["self"], []
    for name, kind, _ in spec:
        value = name
        if kind == "required":
            params.append(name)
        elif kind == "default":
            params.append(f"{name}=_d[{name!r}]")
        else:
            params.append(f"{name}=FACTORY")
            value = f"_f[{name!r}]() if {name} is FACTORY else {name}"
        # A frozen class's own __setattr__ refuses: @dataclass sets its fields through object's.
        body.append(f"        _set(self, {name!r}, {value})" if frozen else f"        self.{name} = {value}")
    names = [name for name, _, _ in spec]
    shown = ", ".join(f"{n}={{self.{n}!r}}" for n in names)
    mine = "".join(f"self.{n}," for n in names)
    theirs = "".join(f"other.{n}," for n in names)
    return "\n".join(
        [
            f"def {maker}(_d, _f, FACTORY, _set=object.__setattr__):",
            f"    def __init__({', '.join(params)}):",
            *(body or ["        pass"]),
            "",
            "    def __repr__(self):",
            f'        return self.__class__.__qualname__ + f"({shown})"',
            "",
            "    def __eq__(self, other):",
            "        if other.__class__ is self.__class__:",
            f"            return ({mine}) == ({theirs})",
            "        return NotImplemented",
            "",
            *(
                ["    def __hash__(self):", f"        return hash(({mine}))", ""]
                if frozen
                else ["    __hash__ = None", ""]
            ),
            "    return __init__, __repr__, __eq__, __hash__",
            "",
        ]
    )


def _compiled(cls: type):
    namespace: dict = {}
    exec(source(cls, "make"), namespace)  # noqa: S102 - made from the class's own field names, as @dataclass does
    return namespace["make"]


def _signature_doc(cls: type) -> str:
    # @dataclass's docstring for a class without one: its name and __init__'s signature.
    return cls.__name__ + str(inspect.signature(cls)).replace(" -> None", "")


def _makers() -> dict:
    try:
        from . import _node_methods
    except ImportError:  # not generated yet: every class is compiled as it is made
        return {}
    return _node_methods.MAKERS


_C = TypeVar("_C", bound=type)


def _key(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _make(cls: Any, frozen: bool, slots: bool) -> Any:
    made: Any = _makers().get(_key(cls))
    own_doc = cls.__dict__.get("__doc__")
    # What the class defines itself, @dataclass keeps: so do we. A __hash__ of None beside an own
    # __eq__ is Python's doing, not the class's.
    own = {name for name in ("__init__", "__repr__", "__eq__") if name in cls.__dict__}
    class_hash = cls.__dict__.get("__hash__", dataclasses.MISSING)
    if not (class_hash is dataclasses.MISSING or (class_hash is None and "__eq__" in cls.__dict__)):
        own.add("__hash__")
    if made is not None and not own_doc and made[2] is not None:
        cls.__doc__ = made[2]  # set first: @dataclass would compute it through inspect.signature
    # @dataclass still makes the fields, the slots and a frozen class's __setattr__ and __delattr__.
    cls = dataclasses.dataclass(cls, frozen=frozen, slots=slots, init=False, repr=False, eq=False)
    stale = made is None or made[0] != shape(cls)
    maker = _compiled(cls) if stale else made[1]
    fields = dataclasses.fields(cls)
    defaults = {f.name: f.default for f in fields if f.default is not dataclasses.MISSING}
    factories = {f.name: f.default_factory for f in fields if f.default_factory is not dataclasses.MISSING}
    init, repr_, eq, hash_ = maker(defaults, factories, FACTORY)
    init.__annotations__ = {**{f.name: f.type for f in fields}, "return": None}
    methods = [(init, "__init__"), (reprlib.recursive_repr("...")(repr_), "__repr__"), (eq, "__eq__")]
    for fn, name in [*methods, (hash_, "__hash__")]:
        if name in own:
            continue
        if fn is not None:
            fn.__qualname__ = f"{cls.__qualname__}.{name}"
        setattr(cls, name, fn)  # a mutable class with __eq__ is unhashable (__hash__ None), as @dataclass makes it
    if not own_doc and (stale or made[2] is None):
        cls.__doc__ = _signature_doc(cls)
    if own_doc:
        _OWN_DOC.add(cls)
    MADE.append(cls)
    return cls


@overload
def record(cls: _C, /) -> _C: ...
@overload
def record(*, frozen: bool = False, slots: bool = False) -> Callable[[_C], _C]: ...
@dataclass_transform(field_specifiers=(dataclasses.field,))
def record(cls=None, /, *, frozen=False, slots=False):
    """``@dataclass`` (``frozen``, ``slots`` as there), with the methods written out in lang/_node_methods.py."""

    def wrap(cls):
        return _make(cls, frozen, slots)

    return wrap if cls is None else wrap(cls)


@dataclass_transform(field_specifiers=(dataclasses.field,))  # field(metadata=...) is no default
def node(cls: _C) -> _C:
    """A syntax tree node's class: ``@record(slots=True)``."""
    return _make(cls, False, True)


#: The packages whose modules may declare records (a module is written out when it uses @record or @node).
PACKAGES = ("liganimate.lang", "liganimate.compiler", "liganimate.runtime")
_USES = re.compile(r"^@(?:record|node)\b", re.MULTILINE)


def users() -> list:
    """The names of the modules of :data:`PACKAGES` that declare records, sorted."""
    found = []
    for package in PACKAGES:
        spec = importlib.util.find_spec(package)
        assert spec is not None and spec.submodule_search_locations
        for root in spec.submodule_search_locations:
            for folder, _, files in os.walk(root):
                for name in files:
                    path = os.path.join(folder, name)
                    if name.endswith(".py") and _USES.search(Path(path).read_text(encoding="utf-8")):
                        rel = os.path.relpath(path, root)[: -len(".py")].replace(os.sep, ".")
                        found.append(f"{package}.{rel}".removesuffix(".__init__"))
    return sorted(found)


def module_text() -> str:
    """The source of ``_node_methods.py`` for the records as their modules declare them now."""
    from . import node_methods  # this module as imported (run as __main__ it is a second copy)

    modules = users()
    for name in modules:
        importlib.import_module(name)  # makes the classes
    parts = [
        '"""Methods of the records (lang/ast.py\'s nodes and others), generated by ``python -m liganimate.lang.node_methods``.',
        "",
        "Do not edit: lang/node_methods.py explains why they are written out.",
        '"""',
        "",
        "# ruff: noqa",
        "",
    ]
    entries = []
    made = {_key(cls): cls for cls in node_methods.MADE if cls.__module__ in modules}
    for key in sorted(made, key=lambda k: (modules.index(made[k].__module__), node_methods.MADE.index(made[k]))):
        cls = made[key]
        fn = key.removeprefix("liganimate.").replace(".", "_").replace(":", "__")  # module-level classes: a name
        parts += ["", source(cls, fn)]
        # @dataclass's docstring, when the class has none of its own and it names no object's address
        # (a default such as <Silent object at 0x...>: then it is made at import, to keep this file the same).
        doc = None if cls in node_methods._OWN_DOC else _signature_doc(cls)
        doc = None if doc is None or " at 0x" in doc else doc
        entries.append(f"    {key!r}: ({shape(cls)!r}, {fn}, {doc!r}),")
    parts += ["", "#: module:class -> (its fields as shape() gives them, the maker of its methods, its signature doc)"]
    parts += ["MAKERS = {", *entries, "}", ""]
    return "\n".join(parts)


def main(argv=None) -> int:
    """Regenerate ``lang/_node_methods.py`` (or with ``--check``, report whether it is current)."""
    from .generated import regenerate

    return regenerate(
        argv, "liganimate.lang.node_methods", [(Path(__file__).with_name(_MODULE), module_text)], main.__doc__ or ""
    )


if __name__ == "__main__":
    raise SystemExit(main())
