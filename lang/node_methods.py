"""The syntax tree's node classes made quickly: dataclasses whose methods were written out once.

``@dataclass`` writes each class's ``__init__``, ``__repr__`` and ``__eq__``
as Python source and compiles it with ``exec`` when the class is made, at
every start: for the sixty-odd node classes of lang/ast.py that was about
20 ms of a cold ``liganimate check`` (a sixth of what it costs beyond
importing NumPy and Lark). :func:`node` makes the same class: it is still a
dataclass (``dataclasses.fields``, ``replace`` and the field metadata work
as before, with slots), but its three methods come from
``lang/_node_methods.py``, where the source dataclasses would write is kept
already compiled (as pycparser keeps its node classes in a generated
module). That module is generated from the classes themselves::

    python -m liganimate.lang.node_methods          # rewrite lang/_node_methods.py
    python -m liganimate.lang.node_methods --check  # exit 1 if it is stale

A class whose fields differ from what the module was written for (an edited
node not yet regenerated) gets its methods compiled here, from the same
source, at the old cost; tests/lang/test_node_methods.py fails until the
module is regenerated, and checks the methods behave as ``@dataclass``'s.
"""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import reprlib
import sys
from pathlib import Path
from typing import Any, TypeVar, dataclass_transform

_MODULE = "_node_methods.py"


class _Factory:
    """The default of a field made by a factory (``@dataclass`` shows it as ``<factory>`` too)."""

    def __repr__(self) -> str:
        return "<factory>"


#: Stands for "call the field's default factory" in a generated ``__init__``.
FACTORY = _Factory()

#: Every class made by :func:`node`, in the order they were made (what the generator writes out).
MADE: list = []


def shape(cls: type) -> tuple:
    """What a class's generated methods depend on: each field's name, kind of default and annotation."""
    out = []
    for f in dataclasses.fields(cls):
        if f.default_factory is not dataclasses.MISSING:
            kind = "factory"
        elif f.default is not dataclasses.MISSING:
            kind = "default"
        else:
            kind = "required"
        if not (f.init and f.repr and f.compare) or f.kw_only:
            raise TypeError(f"{cls.__qualname__}.{f.name}: node fields are plain (init, repr, compare, positional)")
        out.append((f.name, kind, f.type if isinstance(f.type, str) else repr(f.type)))
    return tuple(out)


def source(cls: type, maker: str) -> str:
    """The source of the function ``maker`` that makes ``cls``'s ``__init__``, ``__repr__`` and ``__eq__``.

    It is what ``@dataclass`` writes, given the fields' defaults (``_d``)
    and factories (``_f``) by name. Field names are Python identifiers
    declared in lang/ast.py, never program text.
    """
    spec = shape(cls)
    params, body = ["self"], []
    for name, kind, _ in spec:
        if kind == "required":
            params.append(name)
            body.append(f"        self.{name} = {name}")
        elif kind == "default":
            params.append(f"{name}=_d[{name!r}]")
            body.append(f"        self.{name} = {name}")
        else:
            params.append(f"{name}=FACTORY")
            body.append(f"        self.{name} = _f[{name!r}]() if {name} is FACTORY else {name}")
    names = [name for name, _, _ in spec]
    shown = ", ".join(f"{n}={{self.{n}!r}}" for n in names)
    mine = "".join(f"self.{n}," for n in names)
    theirs = "".join(f"other.{n}," for n in names)
    return "\n".join(
        [
            f"def {maker}(_d, _f, FACTORY):",
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
            "    return __init__, __repr__, __eq__",
            "",
        ]
    )


def _compiled(cls: type):
    namespace: dict = {}
    exec(source(cls, "make"), namespace)  # noqa: S102 - made from field names declared in lang/ast.py, as @dataclass does
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


@dataclass_transform(field_specifiers=(dataclasses.field,))  # field(metadata=...) is no default
def node(cls: _C) -> _C:
    """``@dataclass(slots=True)``, with the methods written out in lang/_node_methods.py."""
    made: Any = _makers().get(cls.__qualname__)
    own_doc = cls.__dict__.get("__doc__")
    if made is not None and not own_doc:
        cls.__doc__ = made[2]  # set first: @dataclass would compute it through inspect.signature
    made_cls: Any = dataclasses.dataclass(cls, slots=True, init=False, repr=False, eq=False)
    cls = made_cls
    stale = made is None or made[0] != shape(cls)
    maker = _compiled(cls) if stale else made[1]
    fields = dataclasses.fields(cls)
    defaults = {f.name: f.default for f in fields if f.default is not dataclasses.MISSING}
    factories = {f.name: f.default_factory for f in fields if f.default_factory is not dataclasses.MISSING}
    init, repr_, eq = maker(defaults, factories, FACTORY)
    init.__annotations__ = {**{f.name: f.type for f in fields}, "return": None}
    for fn, name in ((init, "__init__"), (reprlib.recursive_repr("...")(repr_), "__repr__"), (eq, "__eq__")):
        fn.__qualname__ = f"{cls.__qualname__}.{name}"
        setattr(cls, name, fn)
    made_cls.__hash__ = None  # as @dataclass leaves a mutable class with __eq__ (unhashable)
    if stale and not own_doc:
        cls.__doc__ = _signature_doc(cls)
    MADE.append(cls)
    return cls


def module_text() -> str:
    """The source of ``_node_methods.py`` for the node classes as lang/ast.py declares them now."""
    from . import (
        ast,  # noqa: F401 - makes the classes
        node_methods,  # this module as imported (run as __main__ it is a second copy)
    )

    parts = [
        '"""Methods of the syntax tree\'s node classes, generated by ``python -m liganimate.lang.node_methods``.',
        "",
        "Do not edit: lang/node_methods.py explains why they are written out.",
        '"""',
        "",
        "# ruff: noqa",
        "",
    ]
    entries = []
    seen = set()
    for cls in node_methods.MADE:
        if cls.__module__ != "liganimate.lang.ast" or cls.__qualname__ in seen:
            continue
        seen.add(cls.__qualname__)
        fn = cls.__qualname__.replace(".", "_")  # the module's classes, so a name
        parts += ["", source(cls, fn)]
        doc = _signature_doc(cls)  # the class's __init__ is made from its shape, however it was made
        entries.append(f"    {cls.__qualname__!r}: ({shape(cls)!r}, {fn}, {doc!r}),")
    parts += ["", "#: class name -> (its fields as shape() gives them, the maker of its methods, its signature doc)"]
    parts += ["MAKERS = {", *entries, "}", ""]
    return "\n".join(parts)


def main(argv=None) -> int:
    """Regenerate ``lang/_node_methods.py`` (or with ``--check``, report whether it is current)."""
    ap = argparse.ArgumentParser(prog="python -m liganimate.lang.node_methods", description=main.__doc__)
    ap.add_argument("--check", action="store_true", help="only check; exit 1 if the module is stale")
    args = ap.parse_args(argv)
    path = Path(__file__).with_name(_MODULE)
    text = module_text()
    current = path.read_text(encoding="utf-8") if path.exists() else None
    if args.check:
        if current != text:
            print(f"{path} is stale: run python -m liganimate.lang.node_methods", file=sys.stderr)
            return 1
        print(f"{path} is current")
        return 0
    if current != text:
        path.write_text(text, encoding="utf-8")
        print(f"wrote {path}")
    else:
        print(f"{path} already current")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
