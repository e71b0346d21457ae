"""Balancing a design: the certified optimum of its ``[balance]`` problem, and trade-off fronts."""

from __future__ import annotations

from ..balance.front import Against, Front
from ..balance.optimizer import Backend
from ..balance.optimizer import optimize as run_optimizer
from ..balance.pareto import pareto_front
from ..balance.result import BalanceResult
from ..model import Design


def optimize(design: Design, *, backend: Backend = "nlp") -> BalanceResult:
    """The balanced design of the spec's ``[balance]`` problem.

    ``backend`` ``"nlp"`` (the certified convex optimum, then IPOPT on the designer's own
    parameters) or ``"convex"``. See :func:`balancer.balance.optimizer.optimize`.
    """
    return run_optimizer(design, backend)


def pareto(design: Design, *, against: Against, points: int = 11) -> Front:
    """The exact front of least RMS shaking moment against ``against``.

    ``against``: ``"driving-torque"``, ``"added-mass"`` or ``"shaking-force"``. An engine's
    front (``[balance.counterweights]``, ``[[balance.shafts]]``) is of its weighted shaking
    against the mass·radius it adds (``"added-mass"``; :mod:`balancer.balance.rotor_front`).
    See :func:`balancer.balance.pareto.pareto_front`.
    """
    return pareto_front(design, against, points)
