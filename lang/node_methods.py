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
module). :func:`node`, the syntax tree's, is ``record(slots=True)``.

Nor does a class whose fields are as the module records them go through
``@dataclass`` at all: its inspection of every annotation and default was
most of what remained (about 40 microseconds a class). The fields are read
from the class as written (:func:`written_shape`) and, when they match, the
class is assembled directly (:func:`_assembled`: the same ``Field`` objects,
parameters, ``__match_args__``, slots, and a frozen class's ``__setattr__``
and ``__delattr__``). tests/lang/test_node_methods.py holds every record to
what ``@dataclass`` makes of the same fields. The module is generated from
the classes themselves::

    python -m liganimate.lang.node_methods          # rewrite lang/_node_methods.py
    python -m liganimate.lang.node_methods --check  # exit 1 if it is stale

A class whose fields differ from what the module was written for (an edited
class not yet regenerated) gets its methods compiled here, from the same
source, at the old cost, and by ``@dataclass``; tests/lang/test_node_methods.py
fails until the module is regenerated.
Fields are plain: a default or a default factory at most (no ``init=False``,
``repr=False``, ``compare=False`` or keyword-only fields); ``__init__`` calls
the class's ``__post_init__`` if it has one, as ``@dataclass``'s does. A
class that needs more keeps ``@dataclass``.
"""

from __future__ import annotations

import copy
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
#: Those of them made from the written-out module without @dataclass (the others: an edited class, not yet written out).
WRITTEN: set = set()


def shape(cls: type) -> tuple:
    """What a class's generated methods depend on: its options, and each field's name, kind of default and annotation.

    The options are ``("options", frozen, eq, post_init)``: frozen, compared
    by value (``eq``, else by identity, as ``@dataclass(eq=False)``), and
    whether ``__init__`` ends by calling the class's ``__post_init__``.
    """
    params = cls.__dataclass_params__  # type: ignore[attr-defined]
    out: list = [_options(params.frozen, params.eq, hasattr(cls, "__post_init__"))]
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
        out.append(_entry(f.name, kind, f.type if isinstance(f.type, str) else repr(f.type), f.hash))
    return tuple(out)


def _options(frozen: bool, eq: bool, post_init: bool) -> tuple:
    return ("options", frozen, eq, post_init)


def _entry(name: str, kind: str, annotation: str, hashed: bool | None) -> tuple:
    # A field declared field(hash=False) is left out of the hash, as @dataclass leaves it out.
    return (name, kind, annotation) if hashed is not False else (name, kind, annotation, "unhashed")


def source(cls: type, maker: str) -> str:
    """The source of the function ``maker`` that makes ``cls``'s ``__init__``, ``__repr__``, ``__eq__`` and ``__hash__``.

    It is what ``@dataclass`` writes, given the fields' defaults (``_d``)
    and factories (``_f``) by name; ``__hash__`` is None but for a frozen
    class. Field names are Python identifiers declared in the classes,
    never program text.
    """
    (_, frozen, eq, post_init), *spec = shape(cls)
    params, body = ["self"], []
    for name, kind, *_ in spec:
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
    if post_init:
        body.append("        self.__post_init__()")
    names = [name for name, *_ in spec]
    hashed = "".join(f"self.{name}," for name, _, _, *unhashed in spec if not unhashed)
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
            *(_eq_lines(frozen, mine, theirs, hashed) if eq else ["    __eq__ = __hash__ = None", ""]),
            "    return __init__, __repr__, __eq__, __hash__",
            "",
        ]
    )


def _eq_lines(frozen: bool, mine: str, theirs: str, hashed: str) -> list:
    # Compared by value; only a frozen class is hashable (by the same fields).
    return [
        "    def __eq__(self, other):",
        "        if other.__class__ is self.__class__:",
        f"            return ({mine}) == ({theirs})",
        "        return NotImplemented",
        "",
        *(
            ["    def __hash__(self):", f"        return hash(({hashed}))", ""]
            if frozen
            else ["    __hash__ = None", ""]
        ),
    ]


def _compiled(cls: type):
    namespace: dict = {}
    exec(source(cls, "make"), namespace)  # noqa: S102 - made from the class's own field names, as @dataclass does
    return namespace["make"]


def _signature_doc(cls: type) -> str:
    # @dataclass's docstring for a class without one: its name and __init__'s signature.
    return cls.__name__ + str(inspect.signature(cls)).replace(" -> None", "")


def _makers() -> dict:
    if "makers" not in _WRITTEN_OUT:
        try:
            from . import _node_methods
        except ImportError:  # not generated yet: every class is compiled as it is made
            return {}
        _WRITTEN_OUT["makers"] = _node_methods.MAKERS
    return _WRITTEN_OUT["makers"]


_WRITTEN_OUT: dict = {}  # "makers": lang/_node_methods.py's MAKERS, once imported


_C = TypeVar("_C", bound=type)


def _key(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


#: What a field's value in the class body cannot be for the written-out path: what only @dataclass handles.
_ONLY_DATACLASS = ("ClassVar", "InitVar", "KW_ONLY")


def _plain(f: dataclasses.Field) -> bool:
    # What shape() accepts of a field (a field(...) not yet processed has kw_only MISSING: positional).
    return f.init and f.repr and f.compare and f.kw_only in (dataclasses.MISSING, False)


def _kind(f: dataclasses.Field) -> str:
    if f.default_factory is not dataclasses.MISSING:
        return "factory"
    return "required" if f.default is dataclasses.MISSING else "default"


def written_shape(cls: type, frozen: bool, eq: bool = True) -> tuple | None:
    """:func:`shape` of the class ``@record`` would make, read from the class as written, before any ``@dataclass``.

    None where only ``@dataclass`` can say (a ``ClassVar``, ``InitVar`` or
    keyword-only marker, a field that is not plain, a mutable default, a
    base frozen otherwise): such a class is made by ``@dataclass``, which
    also raises its errors.
    """
    if "__slots__" in cls.__dict__:
        return None  # slots of its own: @dataclass(slots=True) refuses them, and plain @dataclass keeps them
    out: list = [_options(frozen, eq, hasattr(cls, "__post_init__"))]
    inherited: dict = {}
    for base in cls.__mro__[-1:0:-1]:  # as @dataclass collects them: the farthest base first
        base_fields = base.__dict__.get("__dataclass_fields__")
        if base_fields is None:
            continue
        if base.__dict__["__dataclass_params__"].frozen != frozen:
            return None
        for f in base_fields.values():
            if f._field_type is not _FIELD or not _plain(f) or not isinstance(f.type, str):
                return None
            inherited[f.name] = _entry(f.name, _kind(f), f.type, f.hash)
    body = cls.__dict__
    for name, annotation in body.get("__annotations__", {}).items():
        if not isinstance(annotation, str) or any(word in annotation for word in _ONLY_DATACLASS):
            return None
        value = body.get(name, dataclasses.MISSING)
        hashed = None
        if isinstance(value, dataclasses.Field):
            if not _plain(value):
                return None
            kind, hashed = _kind(value), value.hash
        elif value is dataclasses.MISSING:
            kind = "required"
        elif value.__class__.__hash__ is None:  # a mutable default: @dataclass refuses it
            return None
        else:
            kind = "default"
        inherited[name] = _entry(name, kind, annotation, hashed)
    return (*out, *inherited.values())


#: A class @dataclass made with no methods: its field kind and parameters are what :func:`_assembled` sets.
# (With a docstring of its own: else @dataclass computes one with inspect.signature, whose first call costs 2 ms.)
_PLAIN: Any = dataclasses.dataclass(init=False, repr=False, eq=False)(
    type("Plain", (), {"__annotations__": {"x": "int"}, "__doc__": "One field."})
)
#: The kind of an ordinary field (dataclasses marks each field: ordinary, ClassVar or InitVar).
_FIELD = dataclasses.fields(_PLAIN)[0]._field_type  # type: ignore[attr-defined]
_PARAMS: dict = {}
#: What @dataclass gives every class as ``__replace__`` (from Python 3.13; None before).
_REPLACE = _PLAIN.__dict__.get("__replace__")


def _params(frozen: bool, slots: bool, eq: bool) -> Any:
    """``__dataclass_params__`` as ``@dataclass(frozen=frozen, slots=slots, eq=eq)`` sets it."""
    key = (frozen, slots, eq)
    if key not in _PARAMS:
        params = copy.copy(_PLAIN.__dataclass_params__)
        params.init, params.repr, params.eq, params.frozen = True, True, eq, frozen
        if hasattr(params, "slots"):  # recorded since Python 3.12
            params.slots = slots
        _PARAMS[key] = params
    return _PARAMS[key]


def _slots_of(cls: type) -> tuple:
    slots = cls.__dict__.get("__slots__", ())
    return (slots,) if isinstance(slots, str) else tuple(slots)


def _frozen_setattr(cls: type, names: frozenset) -> tuple:
    def __setattr__(self, name, value):
        if type(self) is cls or name in names:
            raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")
        super(cls, self).__setattr__(name, value)

    def __delattr__(self, name):
        if type(self) is cls or name in names:
            raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")
        super(cls, self).__delattr__(name)

    return __setattr__, __delattr__


def _getstate(self) -> list:
    return [getattr(self, f.name) for f in dataclasses.fields(self)]


def _setstate(self, state) -> None:
    for f, value in zip(dataclasses.fields(self), state, strict=True):
        object.__setattr__(self, f.name, value)  # a frozen class's own __setattr__ refuses


def _methods(qualname: str, fields, maker, own: set) -> dict:
    """The methods ``maker`` makes for a class of these fields, by name, but those the class defines itself."""
    defaults = {f.name: f.default for f in fields if f.default is not dataclasses.MISSING}
    factories = {f.name: f.default_factory for f in fields if f.default_factory is not dataclasses.MISSING}
    init, repr_, eq, hash_ = maker(defaults, factories, FACTORY)
    init.__annotations__ = {**{f.name: f.type for f in fields}, "return": None}
    made = {"__init__": init, "__repr__": reprlib.recursive_repr("...")(repr_), "__eq__": eq, "__hash__": hash_}
    for name, fn in made.items():
        if fn is not None:
            fn.__qualname__ = f"{qualname}.{name}"
    # A mutable class with __eq__ is unhashable (__hash__ None), as @dataclass makes it.
    return {name: fn for name, fn in made.items() if name not in own}


def _assembled(cls: Any, frozen: bool, slots: bool, eq: bool, maker, own: set) -> Any:
    """The class ``@dataclass`` would make of ``cls``, with the methods ``maker`` makes.

    What ``dataclasses.dataclass(cls, frozen=frozen, slots=slots, eq=eq)``
    does (its fields, parameters, slots, frozen attributes), for a class
    whose :func:`written_shape` is known, without its inspection of each
    annotation and default (most of a node class's cost). A class with slots
    is made again, as @dataclass makes it, and then with its methods already
    in it (setting each afterwards costs as much again).
    """
    fields: dict = {}
    for base in cls.__mro__[-1:0:-1]:
        fields.update(base.__dict__.get("__dataclass_fields__", {}))
    for name, annotation in cls.__dict__.get("__annotations__", {}).items():
        value = cls.__dict__.get(name, dataclasses.MISSING)
        f: Any = value if isinstance(value, dataclasses.Field) else dataclasses.field(default=value)
        f.name, f.type, f._field_type = name, annotation, _FIELD
        if f.kw_only is dataclasses.MISSING:
            f.kw_only = False
        fields[name] = f
        if value is not f:
            continue
        if f.default is dataclasses.MISSING:  # as @dataclass: a field(...) leaves its default, or nothing, behind
            delattr(cls, name)
        else:
            setattr(cls, name, f.default)
    cls.__dataclass_params__ = _params(frozen, slots, eq)
    cls.__dataclass_fields__ = fields
    if "__match_args__" not in cls.__dict__:
        cls.__match_args__ = tuple(fields)  # type: ignore[misc]
    methods = _methods(cls.__qualname__, fields.values(), maker, own)
    if _REPLACE is not None and "__replace__" not in cls.__dict__:
        methods["__replace__"] = _REPLACE  # copy.replace(), which @dataclass supports from Python 3.13
    if slots:
        body = {**cls.__dict__, **methods}
        inherited = {name for base in cls.__mro__[1:-1] for name in _slots_of(base)}
        body["__slots__"] = tuple(name for name in fields if name not in inherited)
        for name in (*fields, "__dict__", "__weakref__"):
            body.pop(name, None)
        qualname = cls.__qualname__
        cls = type(cls)(cls.__name__, cls.__bases__, body)
        cls.__qualname__ = qualname
        if frozen:
            cls.__getstate__, cls.__setstate__ = _getstate, _setstate
    else:
        for name, fn in methods.items():
            setattr(cls, name, fn)
    if frozen:
        cls.__setattr__, cls.__delattr__ = _frozen_setattr(cls, frozenset(fields))
    return cls


def _make(cls: Any, frozen: bool, slots: bool, eq: bool = True) -> Any:
    made: Any = _makers().get(_key(cls))
    own_doc = cls.__dict__.get("__doc__")
    # What the class defines itself, @dataclass keeps: so do we. A __hash__ of None beside an own
    # __eq__ is Python's doing, not the class's.
    own = {name for name in ("__init__", "__repr__", "__eq__") if name in cls.__dict__}
    if not eq:
        own |= {"__eq__", "__hash__"}  # compared by identity: object's, as @dataclass(eq=False) leaves them
    class_hash = cls.__dict__.get("__hash__", dataclasses.MISSING)
    if not (class_hash is dataclasses.MISSING or (class_hash is None and "__eq__" in cls.__dict__)):
        own.add("__hash__")
    if made is not None and not own_doc and made[2] is not None:
        cls.__doc__ = made[2]  # set first: @dataclass would compute it through inspect.signature
    stale = made is None or made[0] != written_shape(cls, frozen, eq)
    if stale:
        # @dataclass makes the fields, the slots and a frozen class's __setattr__ and __delattr__.
        cls = dataclasses.dataclass(cls, frozen=frozen, slots=slots, init=False, repr=False, eq=False)
        cls.__dataclass_params__ = _params(frozen, slots, eq)  # the methods it left out are ours:
        for name, fn in _methods(cls.__qualname__, dataclasses.fields(cls), _compiled(cls), own).items():
            setattr(cls, name, fn)
    else:
        cls = _assembled(cls, frozen, slots, eq, made[1], own)
        WRITTEN.add(cls)
    if not own_doc and (stale or made[2] is None):
        cls.__doc__ = _signature_doc(cls)
    if own_doc:
        _OWN_DOC.add(cls)
    MADE.append(cls)
    return cls


@overload
def record(cls: _C, /) -> _C: ...
@overload
def record(*, frozen: bool = False, slots: bool = False, eq: bool = True) -> Callable[[_C], _C]: ...
@dataclass_transform(field_specifiers=(dataclasses.field,))
def record(cls=None, /, *, frozen=False, slots=False, eq=True):
    """``@dataclass`` (``frozen``, ``slots``, ``eq`` as there), with the methods written out in lang/_node_methods.py."""

    def wrap(cls):
        return _make(cls, frozen, slots, eq)

    return wrap if cls is None else wrap(cls)


@dataclass_transform(field_specifiers=(dataclasses.field,))  # field(metadata=...) is no default
def node(cls: _C) -> _C:
    """A syntax tree node's class: ``@record(slots=True)``."""
    return _make(cls, False, True)


#: The packages whose modules may declare records (a module is written out when it uses @record or @node).
PACKAGES = ("liganimate.lang", "liganimate.compiler", "liganimate.runtime")
_USES = r"^@(?:record|node)\b"  # compiled by users(), which only the generator runs


def users() -> list:
    """The names of the modules of :data:`PACKAGES` that declare records, sorted."""
    found = []
    uses = re.compile(_USES, re.MULTILINE)
    for package in PACKAGES:
        spec = importlib.util.find_spec(package)
        assert spec is not None and spec.submodule_search_locations
        for root in spec.submodule_search_locations:
            for folder, _, files in os.walk(root):
                for name in files:
                    path = os.path.join(folder, name)
                    if name.endswith(".py") and uses.search(Path(path).read_text(encoding="utf-8")):
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
