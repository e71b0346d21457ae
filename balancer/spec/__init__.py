"""Design specs in TOML: read into model objects (:mod:`.reader`) and written back (:mod:`.writer`).

The key names are fixed (see the project's DESIGN.md); every error names the file, the key and
the value; unknown keys are errors (a typo such as ``mas`` must not be silently ignored). The
``[balance]`` table has its own reader and writer (:mod:`.balance`).
"""

from __future__ import annotations

from .reader import MECHANISM_TYPES, MECHANISMS, design_from_dict, load_design, loads_design
from .writer import dumps_design, save_design

__all__ = [
    "MECHANISMS",
    "MECHANISM_TYPES",
    "design_from_dict",
    "dumps_design",
    "load_design",
    "loads_design",
    "save_design",
]
