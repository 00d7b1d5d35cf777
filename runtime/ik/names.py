"""The solvers' names, apart from the solvers: what the compiler and the host read at start-up.

The compiler checks a REACH block's SOLVER word and the host builds
:class:`.options.ReachOptions` with a default solver; neither solves
anything, so neither should import :mod:`.solvers` (a thousand lines and
numpy's linear algebra) to learn three names. :mod:`.solvers` checks, when
it is imported, that its table :data:`.solvers.SOLVERS` has exactly these
names and keywords, so the two cannot drift apart.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

__all__ = ["DEFAULT_SOLVER", "SOLVER_KEYWORDS"]

#: The solver used when none is named (the language's default too).
DEFAULT_SOLVER = "dls"

#: The language's solver words -> the runtime's names (``{"DLS": "dls", ...}``), in the order of ``SOLVERS``.
SOLVER_KEYWORDS: Mapping[str, str] = MappingProxyType({"DLS": "dls", "TRANSPOSE": "transpose", "CCD": "ccd"})
