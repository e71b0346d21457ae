"""Design specs in TOML: read into model objects (:mod:`.reader`) and written back (:mod:`.writer`).

The key names are fixed (see the project's DESIGN.md); every error names the file, the key and
the value; unknown keys are errors (a typo such as ``mas`` must not be silently ignored). Each
mechanism's tables are read and written by the ``spec`` module in its folder, found through
the registry (:mod:`.codecs`); the linkages' ``[balance]`` table by :mod:`.balance`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..lazy import lazy_exports
from .codecs import MECHANISM_TYPES
from .reader import design_from_dict, load_design, loads_design

if TYPE_CHECKING:
    from .writer import dumps_design, save_design

#: The writer, loaded when a spec is written (a command that only reads one does not).
_EXPORTS = {"dumps_design": "writer", "save_design": "writer"}

__all__ = [
    "MECHANISM_TYPES",
    "design_from_dict",
    "dumps_design",
    "load_design",
    "loads_design",
    "save_design",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())
