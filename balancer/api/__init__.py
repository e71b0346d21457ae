"""The Python API in a few calls, for scripts and notebooks.

>>> from balancer import load_design, analyze
>>> design = load_design("examples/meijaard2020.toml")
>>> analysis = analyze(design)
>>> analysis.summary.shaking_moment.rms  # doctest: +SKIP

Each call takes a :class:`~balancer.model.Design` (from :func:`~balancer.spec.load_design`) and
returns a result object; nothing here prints or writes files. The calls live in modules by
what they need (:mod:`.analysis`, :mod:`.balancing`, :mod:`.motion`, :mod:`.results`,
:mod:`.examples`, :mod:`.drawings`), each
loaded when one of its names is first used (PEP 562): a command that analyses does not load
the optimisers.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..lazy import lazy_exports

#: Where each name lives.
_EXPORTS = {
    "analyze": "analysis",
    "analyze_motions": "analysis",
    "flywheel": "analysis",
    "phasors": "analysis",
    "search": "arrangements",
    "cycle_analyses": "analysis",
    "example": "examples",
    "motion_drawing": "drawings",
    "optimize": "balancing",
    "pareto": "balancing",
    "plan": "planning",
    "codesign": "planning",
    "planned_design": "planning",
    "simulate": "motion",
    "simulate_motion": "motion",
    "verify": "motion",
    "to_dict": "results",
    "to_table": "results",
}

__all__ = [
    "analyze",
    "analyze_motions",
    "flywheel",
    "phasors",
    "search",
    "cycle_analyses",
    "example",
    "motion_drawing",
    "optimize",
    "pareto",
    "plan",
    "codesign",
    "planned_design",
    "simulate",
    "simulate_motion",
    "to_dict",
    "to_table",
    "verify",
]


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())


if TYPE_CHECKING:  # for type checkers and editors: the names as they are
    from .analysis import analyze, analyze_motions, cycle_analyses, flywheel, phasors
    from .arrangements import search
    from .balancing import optimize, pareto
    from .drawings import motion_drawing
    from .examples import example
    from .motion import simulate, simulate_motion, verify
    from .planning import codesign, plan, planned_design
    from .results import to_dict, to_table
