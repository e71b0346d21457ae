"""The masses and the time law together: each lever's certified problem in turn.

With the time law fixed, the links' mass distribution is the balancing problem of ``[balance]``
along the motion (convex: :mod:`balancer.balance`); with the masses fixed, the time law is the
plan's transcription (convex: :mod:`.transcription`). Their joint problem is not convex (the
loads are products of the masses and the motion), so the two are solved in turn — block
coordinate descent on one objective, the plan's ``J`` — until neither improves it by more
than :data:`IMPROVEMENT`. From the first masses on, ``J`` never rises (each step's optimum is at
most its start's); the first masses step rises where the spec's masses do not meet
``[balance]``'s constraints (its force balance: it projects onto them). The result is a point
where neither lever alone can do better, not a certified joint optimum.

Reported beside it, what each lever buys alone from the spec: the masses at the spec's own time
law (the balancing), the time law at the spec's masses (the plan).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..balance.optimizer import Optimizer
from ..balance.result import BalanceResult
from ..errors import SolverError, SpecError
from ..mechanisms import mechanism_of
from ..model import Design
from ..model.balance import BalanceProblem, Objective
from ..model.motions import MotionSpec
from ..model.plan import PlanSpec, PlanWeights
from ..motion_analysis import MotionAnalysis, motion_analysis
from . import Plan, objective_of, path_of, plan_motion, weights_of

#: Rounds stop where ``J`` falls by less than this share of itself.
IMPROVEMENT = 1e-6
#: Rounds at most.
MAX_ROUNDS = 12
#: The four cases a co-design compares: as specified, each lever alone, both.
LEVERS = ("spec", "masses", "motion", "both")


@dataclass(frozen=True)
class CoDesign:
    """The masses and the time law chosen together, and what each lever buys.

    Attributes
    ----------
    plan
        The last round's plan: the time law at the chosen masses (its ``before`` the spec's
        time law at them).
    balance
        The last round's balancing: the masses along the planned motion.
    design
        The spec with the chosen masses (its unbalanced original kept as ``[original]``).
    objectives
        ``J`` (the plan's objective along the motion, in its squared units) as specified, with
        the masses alone, with the time law alone, and with both: keys :data:`LEVERS`.
    analyses
        The loads along the motion in each of those four cases.
    rounds
        ``J`` after each step, in order (a time law, then masses, …).
    """

    plan: Plan
    balance: BalanceResult
    design: Design
    objectives: dict[str, float]
    analyses: dict[str, MotionAnalysis]
    rounds: tuple[float, ...]

    @property
    def projected(self) -> bool:
        """Whether the first masses step raised ``J``.

        The spec's masses do not meet ``[balance]``'s constraints, and the descent starts from
        the first masses.
        """
        return len(self.rounds) > 1 and self.rounds[1] > self.rounds[0]


def _mass_objective(weights: PlanWeights, like: Objective) -> Objective:
    """The balancing's objective weighing what the plan weighs, and nothing else."""
    return replace(like, shaking_moment=weights.shaking_moment,
                   driving_torque=weights.torque, shaking_force=weights.shaking_force,
                   shaking_force_x=weights.shaking_force_x,
                   shaking_force_y=weights.shaking_force_y,
                   rocking_couple=weights.rocking_couple, added_mass=0.0, unbalance=0.0)


def _balanced(design: Design, problem: BalanceProblem, motion: MotionSpec) -> BalanceResult:
    """The masses of ``problem`` along ``motion`` alone (the certified convex optimum)."""
    along = replace(design, motions=(replace(motion, name="plan"),), plan=None,
                    balance=replace(problem, motion_weights=()))
    result = Optimizer.of(along, along=True).run("convex")
    if not result.success:
        raise SolverError(f"the balancing along the planned motion failed: {result.message}")
    return result


def codesign(design: Design, spec: PlanSpec, motion: str | None = None, *,
             gravity: tuple[float, float] = (0.0, 0.0)) -> CoDesign:
    """The masses of ``[balance]`` and the time law of ``spec`` together (module docstring).

    Raises
    ------
    SpecError
        If the spec has no ``[balance]``, or the plan measures a peak.
    SolverError
        If a step fails.
    """
    if spec.measure != "rms":
        raise SpecError("chooses the masses for a mean square (the balancing's objective): "
                        "plan the masses and the time law with measure = \"rms\"",
                        key="plan.measure", value=spec.measure)
    mech = mechanism_of(design.mechanism)
    problem = design.balance
    if not isinstance(problem, BalanceProblem):
        raise SpecError("chooses the masses of the spec's [balance] with the time law: the "
                        "spec has none", key="balance")
    path = path_of(design, motion if motion is not None else spec.motion)
    problem = replace(problem, objective=_mass_objective(spec.objective, problem.objective))
    weights = weights_of(("shaking_force_x", "shaking_force_y", "shaking_moment",
                          "rocking_couple_x", "rocking_couple_y",
                          *(f"torque_{n}" for n in mech.linkage.inputs)), spec.objective)

    def measured(model_design: Design, along: MotionSpec) -> float:
        return objective_of(mechanism_of(model_design.mechanism), along, weights, spec.measure,
                            gravity)

    spec_j = measured(design, path)
    masses = _balanced(design, problem, path)
    masses_design = masses.balanced_design(design)
    masses_j = measured(masses_design, path)
    planned = alone = plan_motion(mech, path, spec, gravity=gravity)
    rounds = [planned.objective_after]
    current, result = design, masses
    for _ in range(MAX_ROUNDS):
        result = _balanced(current, problem, planned.planned)
        current = result.balanced_design(design)
        rounds.append(measured(current, planned.planned))
        planned = plan_motion(mechanism_of(current.mechanism), path, spec, gravity=gravity)
        rounds.append(planned.objective_after)
        if rounds[-3] - rounds[-1] <= IMPROVEMENT * abs(rounds[-3]):
            break
    along = motion_analysis(mechanism_of(masses_design.mechanism), path, gravity=gravity)
    return CoDesign(plan=planned, balance=result, design=current,
                    objectives={"spec": spec_j, "masses": masses_j, "motion": rounds[0],
                                "both": rounds[-1]},
                    analyses={"spec": alone.before, "masses": along, "motion": alone.after,
                              "both": planned.after},
                    rounds=tuple(rounds))
