"""balancer — dynamic balancing of planar linkages.

Analyse how hard a linkage shakes its frame, redesign its links' mass distributions and
counter-rotating inertias so that the shaking force vanishes exactly and the shaking moment is as
small as physics allows, and prove the result by simulation.

The main entry points::

    from balancer import load_design, analyze
    design = load_design("examples/meijaard2020.toml")
    analysis = analyze(design)

Every call, model type, result type and option type a user meets is a name of this package.
Theory: Meijaard & van der Wijk (2020), Wunderlich (1964), Bai, Xia & Ge (2024); equation
numbers in the docstrings are theirs.

The names below are imported when first used (PEP 562), so that ``import balancer`` — and the
command line's ``--help`` — does not pay for numpy, SciPy and CasADi before it needs them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .lazy import lazy_exports

#: Where each public name lives.
_EXPORTS = {
    "analyze": "api",
    "analyze_motions": "api",
    "flywheel": "api",
    "phasors": "api",
    "search": "api",
    "cycle_analyses": "api",
    "example": "api",
    "motion_drawing": "api",
    "optimize": "api",
    "pareto": "api",
    "simulate": "api",
    "simulate_motion": "api",
    "to_dict": "api",
    "to_table": "api",
    "verify": "api",
    "plan": "api",
    "planned_design": "api",
    "codesign": "api",
    "CoDesign": "planning.codesign",
    "Plan": "planning",
    "PlanSpec": "model.plan",
    "PlanWeights": "model.plan",
    "InputLimits": "model.plan",
    "plan_figure": "plots",
    "Optimizer": "balance.optimizer",
    "Backend": "balance.optimizer",
    "sweep": "sweeps",
    "Vary": "sweeps",
    "Perturb": "sweeps",
    "SweepResult": "sweeps",
    "dumps_design": "spec",
    "load_design": "spec",
    "loads_design": "spec",
    "save_design": "spec",
    "animate": "plots",
    "cycle_figure": "plots",
    "motion_figure": "plots",
    "MotionDrawing": "plots",
    "orders_figure": "plots",
    "phasors_figure": "plots",
    "front_figure": "plots",
    "save_figure": "plots",
    "sweep_figure": "plots",
    "verification_figure": "plots",
    "Design": "model",
    "Operation": "model",
    "SimulationSettings": "model",
    "Drive": "model",
    "FourBar": "mechanisms.fourbar.model",
    "SliderCrank": "mechanisms.slidercrank.model",
    "Engine": "mechanisms.engine.model",
    "Linkage": "model",
    "Branch": "model",
    "Link": "model",
    "GasForce": "model",
    "Body": "model",
    "Slider": "model",
    "Spring": "model",
    "AssemblyRange": "model",
    "LinkageClass": "mechanisms.fourbar.assembly",
    "BalanceProblem": "model.balance",
    "Objective": "model.balance",
    "ObjectiveTerm": "model.balance",
    "LinkFreedom": "model.balance",
    "CounterweightFreedom": "model.balance",
    "CycleAnalysis": "cycle",
    "CycleSummary": "cycle",
    "Reactions": "linkage.loads",
    "InputState": "linkage.inputs",
    "MotionAnalysis": "motion_analysis",
    "AlongMotions": "motion_analysis",
    "Flywheel": "speed_fluctuation",
    "Phasors": "phasors",
    "Search": "arrangements",
    "Arrangement": "arrangements",
    "WorkspaceCheck": "motion_analysis",
    "MotionSpec": "model.motions",
    "Workspace": "model.motions",
    "Figure": "cycle",
    "Trajectory": "simulation",
    "Verification": "verification",
    "MotionRun": "simulation.motions",
    "MotionVerification": "motion_verification",
    "MotionCheck": "motion_verification",
    "RunCheck": "verification",
    "BalanceResult": "balance.result",
    "Status": "balance.result",
    "StageReport": "balance.result",
    "InfeasibleError": "balance.result",
    "Front": "balance.front",
    "FrontPoint": "balance.front",
    "Against": "balance.front",
    "Counterweight": "balance.counterweights",
    "Mechanism": "mechanisms.base",
    "Route": "mechanisms.base",
    "mechanism_of": "mechanisms",
    "Method": "formulations",
    "BalancerError": "errors",
    "SpecError": "errors",
    "OutputError": "errors",
    "AssemblyError": "errors",
    "SolverError": "errors",
    "LockupError": "errors",
}

__all__ = [
    "Against",
    "analyze",
    "analyze_motions",
    "flywheel",
    "phasors",
    "search",
    "animate",
    "AssemblyError",
    "AssemblyRange",
    "Backend",
    "BalanceProblem",
    "BalancerError",
    "BalanceResult",
    "Body",
    "Branch",
    "Counterweight",
    "CounterweightFreedom",
    "cycle_analyses",
    "cycle_figure",
    "CycleAnalysis",
    "CycleSummary",
    "Design",
    "Drive",
    "dumps_design",
    "Engine",
    "example",
    "Figure",
    "FourBar",
    "Front",
    "front_figure",
    "FrontPoint",
    "GasForce",
    "InfeasibleError",
    "Link",
    "Linkage",
    "LinkageClass",
    "LinkFreedom",
    "load_design",
    "loads_design",
    "LockupError",
    "Mechanism",
    "mechanism_of",
    "Method",
    "Objective",
    "ObjectiveTerm",
    "Operation",
    "optimize",
    "Optimizer",
    "orders_figure",
    "phasors_figure",
    "OutputError",
    "pareto",
    "Perturb",
    "plan",
    "codesign",
    "CoDesign",
    "plan_figure",
    "planned_design",
    "Plan",
    "PlanSpec",
    "PlanWeights",
    "InputLimits",
    "Reactions",
    "InputState",
    "MotionAnalysis",
    "MotionDrawing",
    "motion_drawing",
    "motion_figure",
    "AlongMotions",
    "Flywheel",
    "Phasors",
    "Search",
    "Arrangement",
    "WorkspaceCheck",
    "MotionSpec",
    "Workspace",
    "Route",
    "RunCheck",
    "save_design",
    "save_figure",
    "simulate",
    "simulate_motion",
    "SimulationSettings",
    "Slider",
    "SliderCrank",
    "SolverError",
    "SpecError",
    "Spring",
    "StageReport",
    "Status",
    "sweep",
    "sweep_figure",
    "SweepResult",
    "to_dict",
    "to_table",
    "Trajectory",
    "Vary",
    "Verification",
    "MotionRun",
    "MotionVerification",
    "MotionCheck",
    "verification_figure",
    "verify",
]

__version__ = "0.1.0"


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())


if TYPE_CHECKING:  # for type checkers and editors: the names as they are
    from .api import (
        analyze,
        analyze_motions,
        codesign,
        cycle_analyses,
        example,
        flywheel,
        motion_drawing,
        optimize,
        pareto,
        phasors,
        plan,
        planned_design,
        search,
        simulate,
        simulate_motion,
        to_dict,
        to_table,
        verify,
    )
    from .arrangements import Arrangement, Search
    from .balance.counterweights import Counterweight
    from .balance.front import Against, Front, FrontPoint
    from .balance.optimizer import Backend, Optimizer
    from .balance.result import BalanceResult, InfeasibleError, StageReport, Status
    from .cycle import CycleAnalysis, CycleSummary, Figure
    from .errors import (
        AssemblyError,
        BalancerError,
        LockupError,
        OutputError,
        SolverError,
        SpecError,
    )
    from .formulations import Method
    from .linkage.inputs import InputState
    from .linkage.loads import Reactions
    from .mechanisms import mechanism_of
    from .mechanisms.base import Mechanism, Route
    from .mechanisms.engine.model import Engine
    from .mechanisms.fourbar.assembly import LinkageClass
    from .mechanisms.fourbar.model import FourBar
    from .mechanisms.slidercrank.model import SliderCrank
    from .model import (
        AssemblyRange,
        Body,
        Branch,
        Design,
        Drive,
        GasForce,
        Link,
        Linkage,
        Operation,
        SimulationSettings,
        Slider,
        Spring,
    )
    from .model.balance import (
        BalanceProblem,
        CounterweightFreedom,
        LinkFreedom,
        Objective,
        ObjectiveTerm,
    )
    from .model.motions import MotionSpec, Workspace
    from .model.plan import InputLimits, PlanSpec, PlanWeights
    from .motion_analysis import AlongMotions, MotionAnalysis, WorkspaceCheck
    from .motion_verification import MotionCheck, MotionVerification
    from .phasors import Phasors
    from .planning import Plan
    from .planning.codesign import CoDesign
    from .plots import (
        MotionDrawing,
        animate,
        cycle_figure,
        front_figure,
        motion_figure,
        orders_figure,
        phasors_figure,
        plan_figure,
        save_figure,
        sweep_figure,
        verification_figure,
    )
    from .simulation import Trajectory
    from .simulation.motions import MotionRun
    from .spec import dumps_design, load_design, loads_design, save_design
    from .speed_fluctuation import Flywheel
    from .sweeps import Perturb, SweepResult, Vary, sweep
    from .verification import RunCheck, Verification
