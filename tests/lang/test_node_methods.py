"""Records (the syntax tree's node classes and others): dataclasses whose methods come from lang/_node_methods.py.

* The generated module is the one the classes give today (as lang/_tables.py is for the grammar).
* Every record took its methods from it: none paid for compiling them at import, nor for
  ``@dataclass``'s inspection of its fields (the class is assembled from what was written out).
* The methods behave as ``@dataclass``'s own (frozen and slots as asked), class by class: the
  same signature and docstring, repr, equality, hashing, immutability, defaults and factories.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import os
import pickle
from typing import ClassVar

import pytest
from paths import ROOT_DIR

from liganimate.lang import ast as A
from liganimate.lang import node_methods as N


def node_classes() -> list:
    """Every record of the modules that declare records."""
    modules = N.users()
    for name in modules:
        importlib.import_module(name)
    return [c for c in N.MADE if c.__module__ in modules]


def test_generated_methods_are_the_ones_the_classes_give():
    with open(os.path.join(ROOT_DIR, "lang", "_node_methods.py"), encoding="utf-8") as fh:
        shipped = fh.read()
    assert shipped == N.module_text(), "run: python -m liganimate.lang.node_methods"


def test_every_node_class_took_its_methods_from_the_generated_module():
    makers = N._makers()
    classes = node_classes()
    assert len(classes) > 70 and A.Program in classes and A.Num in classes
    assert {"liganimate.lang.ast", "liganimate.lang.vocabulary", "liganimate.compiler.scopes"} <= set(N.users())
    for cls in classes:
        assert makers[N._key(cls)][0] == N.shape(cls), cls.__qualname__
        assert cls.__init__.__code__.co_filename.endswith("_node_methods.py"), cls.__qualname__
        assert cls in N.WRITTEN, cls.__qualname__  # assembled without @dataclass


def twin(cls: type) -> type:
    """``cls`` as @dataclass makes it from the same fields and options (the reference)."""
    spec = []
    for f in dataclasses.fields(cls):
        extra: dict = {"hash": f.hash}
        if f.default is not dataclasses.MISSING:
            extra["default"] = f.default
        if f.default_factory is not dataclasses.MISSING:
            extra["default_factory"] = f.default_factory
        spec.append((f.name, f.type, dataclasses.field(**extra)))
    params = cls.__dataclass_params__
    slots = "__slots__" in cls.__dict__
    return dataclasses.make_dataclass(cls.__name__, spec, slots=slots, frozen=params.frozen, eq=params.eq)


def _described(cls: type) -> list:
    """What ``dataclasses.fields`` tells of each field (the metadata aside: the twin has none)."""
    keys = ("name", "type", "default", "default_factory", "init", "repr", "hash", "compare", "kw_only")
    return [tuple(getattr(f, k) for k in keys) for f in dataclasses.fields(cls)]


def test_methods_behave_as_dataclass_ones():
    for cls in node_classes():
        ref = twin(cls)
        name = cls.__qualname__
        assert dataclasses.is_dataclass(cls), name
        assert str(inspect.signature(cls)) == str(inspect.signature(ref)), name
        if not cls.__doc__ or cls.__doc__.startswith(cls.__name__ + "("):  # no docstring of its own
            assert cls.__doc__ == ref.__doc__, name
        assert cls.__match_args__ == ref.__match_args__, name
        assert _described(cls) == _described(ref), name
        for option in ("init", "repr", "eq", "order", "unsafe_hash", "frozen"):
            assert getattr(cls.__dataclass_params__, option) == getattr(ref.__dataclass_params__, option), (
                name,
                option,
            )
        if hasattr(cls, "__post_init__"):
            continue  # its own checks refuse made-up values: tested with the class (and below)
        assert ("__slots__" in cls.__dict__) == ("__slots__" in ref.__dict__), name
        assert hasattr(cls, "__replace__") == hasattr(ref, "__replace__"), name  # copy.replace, Python 3.13
        names = [f.name for f in dataclasses.fields(cls)]
        values = [f"v{i}" for i in range(len(names))]
        mine, theirs = cls(*values), ref(*values)
        if ref.__hash__ is None:
            assert cls.__hash__ is None, name
        else:
            assert hash(mine) == hash(theirs) == hash(cls(*values)), name
        if cls.__dataclass_params__.frozen and names:
            with pytest.raises(dataclasses.FrozenInstanceError):
                setattr(mine, names[0], "changed")
        assert repr(mine) == repr(theirs).replace(ref.__qualname__, cls.__qualname__, 1), name
        assert mine == cls(*values) and not (mine != cls(*values)), name
        assert mine != theirs, name  # another class: never equal, as dataclasses compare
        if names:
            other = cls(*values[:-1], "different")
            assert mine != other and (mine == other) is False, name
            assert dataclasses.replace(mine, **{names[-1]: "different"}) == other, name
            assert cls(**dict(zip(names, values, strict=True))) == mine, name


def test_defaults_and_factories():
    a = A.Program(A.NOWHERE, "f.lig", "", [])
    b = A.Program(A.NOWHERE, "f.lig", "", [])
    assert a.primitives == [] and a.primitives is not b.primitives  # a fresh list each time
    assert A.PrimitiveDef(A.NOWHERE, A.Name(A.NOWHERE, "P"), []).pattern is None
    assert repr(A.Num(A.NOWHERE, 1, "1")) == f"Num(pos={A.NOWHERE!r}, value=1, text='1')"


def test_a_changed_class_gets_compiled_methods(monkeypatch):
    # An edited node whose module is stale still gets @dataclass's methods (compiled at import, as before).
    monkeypatch.setattr(N, "_makers", lambda: {})

    @N.node
    class Edited(A.Node):
        name: str
        items: list = dataclasses.field(default_factory=list)

    ref = twin(Edited)
    assert str(inspect.signature(Edited)) == str(inspect.signature(ref))
    assert Edited.__doc__ == ref.__doc__
    e = Edited(A.NOWHERE, "X")
    assert e == Edited(A.NOWHERE, "X", []) and e.items == [] and e.items is not Edited(A.NOWHERE, "X").items
    assert (
        repr(e) == f"test_a_changed_class_gets_compiled_methods.<locals>.Edited(pos={A.NOWHERE!r}, name='X', items=[])"
    )
    N.MADE.remove(Edited)


def test_a_frozen_record_and_methods_of_its_own(monkeypatch):
    monkeypatch.setattr(N, "_makers", lambda: {})

    @N.record(frozen=True)
    class Pair:
        a: int
        b: int = 2

        def __repr__(self) -> str:  # its own: kept, as @dataclass keeps it
            return "pair"

    p = Pair(1)
    assert (p.b, repr(p), p == Pair(1, 2), hash(p) == hash(Pair(1, 2))) == (2, "pair", True, True)
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.a = 3  # type: ignore[misc]
    assert dataclasses.replace(p, b=5) == Pair(1, 5)
    N.MADE.remove(Pair)

    @N.record
    class Unhashable:
        a: int

    assert Unhashable.__hash__ is None and Unhashable(1) == Unhashable(1) != Unhashable(2)
    N.MADE.remove(Unhashable)


def test_a_record_refuses_what_it_does_not_write():
    with pytest.raises(TypeError, match="plain"):

        @N.record
        class Hidden:
            a: int = dataclasses.field(default=0, repr=False)


def test_fields_as_declared():
    # What the passes read of a field (its metadata: binds, holds, parts) and the defaults left on a class.
    (target,) = [f for f in dataclasses.fields(A.Assign) if f.name == "target"]
    assert target.metadata["binds"] == "assigns" and target.type == "Name"
    assert dataclasses.fields(A.Node)[0].name == "pos" and "pos" in A.Node.__slots__
    assert A.BinOp.__slots__ == ("op", "left", "right", "op_pos") and not hasattr(
        A.BinOp(A.NOWHERE, "+", 1, 2), "__dict__"
    )
    assert A.Program.__match_args__ == ("pos", "filename", "source", "body", "primitives")


def test_a_frozen_slots_record_pickles_and_refuses_changes():
    from liganimate.runtime.host import JointArgs

    assert JointArgs in N.WRITTEN
    names = [f.name for f in dataclasses.fields(JointArgs)]
    value = JointArgs(*range(len(names)))
    assert pickle.loads(pickle.dumps(value)) == value
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(value, names[0], 5)
    with pytest.raises(dataclasses.FrozenInstanceError):
        delattr(value, names[0])


def test_an_edited_class_is_made_by_dataclass(monkeypatch):
    # Its module was written out for other fields: the written methods do not fit, so @dataclass makes it.
    written = dict(N._makers())
    key = f"{__name__}:test_an_edited_class_is_made_by_dataclass.<locals>.Edited"
    written[key] = written["liganimate.lang.ast:Var"]  # (pos, name): the class below has one more field
    monkeypatch.setattr(N, "_makers", lambda: written)

    @N.node
    class Edited(A.Node):
        name: str
        extra: int = 0

    assert Edited not in N.WRITTEN and Edited(A.NOWHERE, "X").extra == 0
    assert str(inspect.signature(Edited)) == str(inspect.signature(twin(Edited)))
    N.MADE.remove(Edited)

    @N.node
    class Edited(A.Node):  # type: ignore[no-redef]  # now as written out: assembled
        name: str

    assert Edited in N.WRITTEN and repr(Edited(A.NOWHERE, "X")).endswith(f"Edited(pos={A.NOWHERE!r}, name='X')")
    N.MADE.remove(Edited)
    N.WRITTEN.discard(Edited)


def test_what_only_dataclass_handles_is_left_to_it():
    # A ClassVar, a mutable default, slots of its own: not read from the class as written (None), so
    # @dataclass makes (or refuses) such a class, never the written-out path.
    class Counted:
        count: ClassVar[int] = 0  # noqa: RUF012
        name: str

    class Listed:
        items: list = []  # noqa: RUF012

    class Slotted:
        __slots__ = ("name",)
        name: str

    for cls in (Counted, Listed, Slotted):
        assert N.written_shape(cls, False) is None, cls.__name__

    class Plain:
        name: str
        size: int = 1
        items: list = dataclasses.field(default_factory=list)

        def __post_init__(self) -> None:
            pass

    assert N.written_shape(Plain, True, eq=False) == (
        ("options", True, False, True),
        ("name", "required", "str"),
        ("size", "default", "int"),
        ("items", "factory", "list"),
    )


def test_compared_by_identity_and_checked_after_init():
    # @record(eq=False) compares and hashes as object does; __init__ ends with the class's __post_init__,
    # as runtime/figure/tree.py's Link, Joint and Figure need.
    seen = []

    @N.record(frozen=True, eq=False)
    class Checked:
        a: int
        b: int = 2

        def __post_init__(self) -> None:
            seen.append((self.a, self.b))
            object.__setattr__(self, "b", self.b * 10)

    one, two = Checked(1), Checked(1)
    assert seen == [(1, 2), (1, 2)] and one.b == 20 and repr(one).endswith("Checked(a=1, b=20)")
    assert one != two and one == one and hash(one) == object.__hash__(one)
    assert Checked.__eq__ is object.__eq__ and not Checked.__dataclass_params__.eq
    assert str(inspect.signature(Checked)) == str(inspect.signature(twin(Checked)))
    with pytest.raises(dataclasses.FrozenInstanceError):
        one.a = 3  # type: ignore[misc]
    assert dataclasses.replace(one, a=5).a == 5 and seen[-1] == (5, 20)
    N.MADE.remove(Checked)
