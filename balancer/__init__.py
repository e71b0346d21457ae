"""balancer — dynamic balancing of planar linkages.

Analyse how hard a linkage shakes its frame, redesign its links' mass distributions and
counter-rotating inertias so that the shaking force vanishes exactly and the shaking moment is as
small as physics allows, and prove the result by simulation.

The main entry points::

    from balancer import load_design, analyze
    design = load_design("examples/meijaard2020.toml")
    analysis = analyze(design)

Theory: Meijaard & van der Wijk (2020), Wunderlich (1964), Bai, Xia & Ge (2024); equation
numbers in the docstrings are theirs.

The names below are imported when first used (PEP 562), so that ``import balancer`` — and the
command line's ``--help`` — does not pay for numpy, SciPy and CasADi before it needs them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: Where each public name lives.
_EXPORTS = {
    "analyze": "api",
    "example": "api",
    "optimize": "api",
    "Optimizer": "balance.optimizer",
    "pareto": "api",
    "simulate": "api",
    "to_dict": "api",
    "to_table": "api",
    "verify": "api",
    "sweep": "sweeps",
    "Vary": "sweeps",
    "Perturb": "sweeps",
    "SliderCrank": "model",
    "GasForce": "model",
    "Linkage": "model",
    "animate": "plots",
    "cycle_figure": "plots",
    "front_figure": "plots",
    "save_figure": "plots",
    "verification_figure": "plots",
    "AssemblyError": "errors",
    "BalancerError": "errors",
    "LockupError": "errors",
    "SolverError": "errors",
    "SpecError": "errors",
    "Design": "model",
    "FourBar": "model",
    "Link": "model",
    "Operation": "model",
    "SimulationSettings": "model",
    "dumps_design": "spec",
    "load_design": "spec",
    "loads_design": "spec",
    "save_design": "spec",
}

__all__ = [
    "example",
    "optimize",
    "Optimizer",
    "pareto",
    "simulate",
    "sweep",
    "to_dict",
    "to_table",
    "verify",
    "Vary",
    "Perturb",
    "SliderCrank",
    "GasForce",
    "Linkage",
    "animate",
    "cycle_figure",
    "front_figure",
    "save_figure",
    "verification_figure",
    "AssemblyError",
    "BalancerError",
    "Design",
    "FourBar",
    "Link",
    "LockupError",
    "Operation",
    "SimulationSettings",
    "SolverError",
    "SpecError",
    "analyze",
    "dumps_design",
    "load_design",
    "loads_design",
    "save_design",
]

__version__ = "0.1.0"


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'balancer' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})


if TYPE_CHECKING:  # for type checkers and editors: the names as they are
    from .api import analyze, example, optimize, pareto, simulate, to_dict, to_table, verify
    from .balance.optimizer import Optimizer
    from .errors import AssemblyError, BalancerError, LockupError, SolverError, SpecError
    from .model import (
        Design,
        FourBar,
        GasForce,
        Link,
        Linkage,
        Operation,
        SimulationSettings,
        SliderCrank,
    )
    from .plots import animate, cycle_figure, front_figure, save_figure, verification_figure
    from .spec import dumps_design, load_design, loads_design, save_design
    from .sweeps import Perturb, Vary, sweep
