"""A loaded library at run time: its compiled module, run once, and its values.

Generated modules carry each library they LOAD as the text of its own
compiled module (see compiler/lower.py), so they stay standalone. The text
is executed when first needed and its main program run once per process;
every program that loads the same text shares the result, which is safe
because models, motions and graphical objects are values that are never
changed in place.
"""

from __future__ import annotations

import hashlib
import io

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure.tree import Figure, LinkSource
from liganimate.runtime.loader import exec_module

_runs: dict = {}  # sha256 of the module text -> (namespace, variables, warnings)


class Library:
    """One library, as a generated module names it (``_LIB0 = _host.Library(...)``).

    Parameters
    ----------
    name : str
        How diagnostics name it, e.g. ``stdlib/humanoid.lig``.
    python : str
        Its compiled module text.
    """

    def __init__(self, name: str, python: str, names: dict | None = None):
        self.name = name
        self.python = python
        # MODEL -> {SEGMENT: (source name, channels, end)}: the library's name tables
        # (lang/name_table.py), handed to the model's links as it is loaded.
        self.names = names or {}
        self._key = hashlib.sha256(python.encode()).hexdigest()

    def _namespace(self) -> dict:
        entry = _runs.get(self._key)
        if entry is None:
            namespace = {"__name__": f"liganimate_library_{self._key[:12]}"}
            exec_module(self.python, f"<liganimate library {self.name}>", namespace)
            entry = _runs[self._key] = [namespace, None, ()]
        return entry[0]

    def _run(self):
        namespace = self._namespace()
        entry = _runs[self._key]
        if entry[1] is None:
            program = namespace["program"]
            # A library's PRINTs are for its author; loading it stays quiet.
            lrt = program.execute("check", stdout=io.StringIO())
            values = {}
            for name, value in lrt.variables.items():
                if name.startswith("_"):
                    continue
                values[name] = lrt.finished(value)
            entry[1], entry[2] = values, tuple(lrt.warnings)
        return entry

    def value(self, rt, name: str, at: int):
        """The value the library gives ``name``; its run-time warnings join ``rt``'s once."""
        _, values, warnings = self._run()
        seen = rt.__dict__.setdefault("_library_warnings", set())
        if self._key not in seen:
            seen.add(self._key)
            rt.warnings.extend(w for w in warnings if w not in rt.warnings)
        try:
            value = values[name]
        except KeyError:
            raise LigError(f"{self.name} no longer defines {name}", "recompile the program") from None
        table = self.names.get(name.upper())
        if table and isinstance(value, Figure):
            value = value.with_sources({seg: LinkSource(*row) for seg, row in table.items()})
        return value

    def primitive(self, name: str):
        """A callable ``f(rt, **arguments)`` drawing the library's PRIMITIVE ``name``.

        Diagnostics raised inside it point into the library's own source.
        """
        library = self

        def call(rt, **arguments):
            namespace = library._namespace()
            return namespace[f"_prim_{name}"](rt.for_program(namespace["program"]), **arguments)

        call.__name__ = f"_prim_{name}"
        call.__doc__ = f"PRIMITIVE {name} from {self.name}."
        return call
