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
"""

from .api import analyze
from .errors import AssemblyError, BalancerError, LockupError, SolverError, SpecError
from .model import Design, FourBar, Link, Operation, SimulationSettings
from .spec import dumps_design, load_design, loads_design, save_design

__all__ = [
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
