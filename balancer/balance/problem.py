"""The redesign problem in numbers: regressors, bounds, force balance, objective, feasibility.

**Inertial balancing only.** With the crank at constant speed every reaction, the shaking force,
the shaking moment and the driving torque are linear in the design vector of the mechanism's
layout (:class:`balancer.linkage.dynamics.Layout`: per link ``m``, ``m·e``, ``m·f`` and ``J``
about the frame's origin, then the counter-rotors' inertias). Applied loads are not (a force at
a centre of mass that the redesign moves), so the redesign balances the **inertial** shaking;
the loads stay on the links of the balanced design as they were.

The spec's side (:class:`~balancer.model.balance.BalanceProblem`, the ``[balance]`` schema)
becomes :class:`NumericProblem` by :func:`numeric_problem`: the regressors over the revolution
(:mod:`.regressors`), per-link bounds (:class:`~.bounds.LinkBounds`), the force-balance
conditions (:mod:`balancer.force_balance`), the objective, and the feasibility checks that the
optimisers and the tests rely on. Its parts, one module each:

=====================  ============================================================================
``problem_data``       what the problem holds, and the parts of its design vector
``objective_terms``    the objective's least-squares rows and its value
``objective_scale``    the scale a gap in the objective is measured by, and its rounding
``settling``           the values of the entries that the objective does not see
``physical``           design vectors as each link's physical values in their bounds, and back
``feasibility``        the bounds and force balance a design must meet
=====================  ============================================================================

This module imports neither CVXPY nor CasADi.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import cast

import numpy as np
from numpy.typing import NDArray

from .. import validate as v
from ..cycle import sample_angles
from ..errors import SpecError
from ..force_balance import ForceBalance, force_balance_along
from ..linkage import trajectory
from ..linkage.dynamics import TURNING
from ..linkage.inputs import InputState
from ..linkage.vectors import V
from ..mechanisms import Mechanism, mechanism_of
from ..mechanisms.base import require_full_revolution
from ..model import Design
from ..model.balance import BalanceProblem, RotorBalanceProblem
from ..motion_analysis import motion_weights, stacked_torques
from .bounds import check_problem, resolve_link
from .feasibility import Feasibility, force_balance_system
from .objective_scale import ObjectiveScale
from .objective_terms import objective_rows
from .physical import PhysicalValues
from .regressors import CycleRegressors, cycle_regressors_at
from .settling import Settling
from .sites import Sites, site_columns, sites_of


class NumericProblem(Feasibility, PhysicalValues, Settling, ObjectiveScale):
    """The redesign problem in numbers, built once by :func:`numeric_problem`.

    Its data and design vector (:class:`~.problem_data.ProblemData`, whose attributes it
    has), its objective (:class:`~.objective_terms.ObjectiveTerms`) and that objective's
    scale (:class:`~.objective_scale.ObjectiveScale`), the values of its inert entries
    (:class:`~.settling.Settling`), physical values (:class:`~.physical.PhysicalValues`) and
    feasibility (:class:`~.feasibility.Feasibility`).
    """

    def with_problem(self, problem: BalanceProblem) -> NumericProblem:
        """The same design at the same operating point under another redesign problem.

        For new bounds (or other links free, another objective) without rebuilding what does
        not depend on them: the regressors, the force-balance conditions and the rows of
        :attr:`acceleration_factor` are kept; with the same objective weights also their
        reduction (:attr:`rows`, :attr:`factor`, :attr:`inert`) and the objective's scales.
        The result equals what :func:`numeric_problem` builds for the design with ``problem``
        as its ``[balance]``.

        Raises
        ------
        SpecError
            If ``problem`` is contradictory (:func:`check_problem`).
        """
        if self.sites is not None:
            raise SpecError("an engine's counterweights and shafts: build its problem from its "
                            "design (numeric_problem)", key="balance")
        problem = _checked_problem(problem)
        mech = self.mechanism
        check_problem(problem, mech)
        links = tuple(resolve_link(mech, name, problem.link(name))
                      for name in mech.linkage.link_names)
        same_objective = problem.objective == self.problem.objective
        if same_objective:
            rows, factor, inert = self.rows, self.factor, self.inert
        else:
            rows, factor, inert = objective_rows(self.regressors, problem.objective, links,
                                                  self.size)
        fb = None
        if problem.force_balance:
            same_scope = problem.force_scope == cast("BalanceProblem", self.problem).force_scope
            if self.force_balance is not None and same_scope:
                fb = self.force_balance
            elif problem.force_scope == "motion":
                raise ValueError("force balance along the motions: build the problem from "
                                 "its design (numeric_problem), which has them")
            else:
                fb = force_balance_system(mech)
        new = replace(self, problem=problem, links=links, rows=rows, factor=factor,
                      force_balance=fb, inert=inert)
        kept = ["acceleration_factor", "scales", "original_mass"]
        if same_objective:
            kept += ["objective_reference", "inertial_scale", "objective_scale",
                     "original_objective"]
        if fb is not None and fb is self.force_balance:
            kept.append("_force_balance_sizes")
        for name in kept:  # cached properties that the new problem shares (made once)
            new.__dict__[name] = getattr(self, name)
        return new


def numeric_problem(design: Design, *, along: bool = False) -> NumericProblem:
    """Build the numeric redesign problem of a design spec once.

    For the same design under other bounds, :meth:`NumericProblem.with_problem` reuses what
    does not depend on them. A linkage with several inputs is balanced along its motions; one
    with one input over a revolution at the operating speed, or along its motions where
    ``along`` (a time law that varies the crank's speed: ``plan --with-masses``); an engine's
    counterweights and shafts (:class:`~balancer.model.balance.RotorBalanceProblem`) are
    mass·radius sites after its links' entries (:mod:`.sites`), over a revolution.

    Raises
    ------
    SpecError
        If the spec has no ``[balance]`` or no ``[operation]`` section, or the problem is
        contradictory (see :func:`check_problem`).
    AssemblyError
        If the crank cannot turn a full revolution.
    """
    if isinstance(design.balance, RotorBalanceProblem) and not along:
        return _engine_problem(design, design.balance)
    problem = _checked_problem(design.balance)
    mech = mechanism_of(design.mechanism)
    if len(mech.linkage.inputs) > 1 or along:
        check_problem(problem, mech)
        return _along_motions(design, problem, mech)
    if design.operation is None:
        raise SpecError(
            "missing required key: the balancing objective is evaluated at the operating speed",
            key="operation.speed",
        )
    check_problem(problem, mech)
    require_full_revolution(mech, "balancing")
    speed = design.operation.speed
    angles = sample_angles(design.operation.samples)
    # (At unit crank acceleration too, for the counter-rotors' settling: in the same pass;
    # its shaking moment alone is used, so its driving torque at rest is not computed.)
    reg, unit = cycle_regressors_at(mech, angles, [(speed, 0.0), (0.0, 1.0)],
                                    torque_at_rest=not abs(speed) > TURNING)
    return _problem(problem, mech, speed, InputState.crank(angles, speed), reg, unit)


def _problem(problem: BalanceProblem, mech: Mechanism, speed: float | None,
             states: InputState, reg: CycleRegressors, unit: CycleRegressors | None,
             along: ForceBalance | None = None) -> NumericProblem:
    """The problem of ``mech`` whose samples are ``states`` with regressors ``reg``.

    The links' bounds, the objective's rows and the force balance are the same whatever the
    samples are: a revolution at ``speed``, or motions (``speed`` ``None``).
    """
    links = tuple(resolve_link(mech, name, problem.link(name)) for name in mech.linkage.link_names)
    rows, factor, inert = objective_rows(reg, problem.objective, links, mech.layout.size)
    return NumericProblem(
        problem=problem,
        mechanism=mech,
        speed=speed,
        states=states,
        regressors=reg,
        links=links,
        x0=mech.layout.vector(mech.linkage),
        rows=rows,
        factor=factor,
        force_balance=_force_balance(problem, mech, along),
        inert=inert,
        unit_acceleration=unit,
    )


def _engine_problem(design: Design, problem: RotorBalanceProblem) -> NumericProblem:
    """The problem of an engine's counterweights and shafts: its links held, its sites chosen.

    The design vector is the linkage's entries (every link as it is) then two per mass·radius
    site (:func:`.sites.sites_of`: the chosen ones, then the masses kept); the regressors are
    the linkage's over the revolution at the operating speed with the sites' columns beside
    them (:func:`.sites.site_columns`), so that ``J(x0)`` is the original's and the chosen
    sites' columns the loads each mass·radius makes.
    """
    mech = mechanism_of(design.mechanism)
    sites, site_values = sites_of(design, mech.layout.size)
    assert design.operation is not None, "sites_of checked it"
    speed = design.operation.speed
    angles = sample_angles(design.operation.samples)
    (linkage,) = cycle_regressors_at(mech, angles, [(speed, 0.0)])
    force, moment, couple = site_columns(sites.sites, angles, speed)
    supports = None
    w = problem.objective
    if w.main_bearing_load or w.largest_bearing_load or problem.max_bearing_load is not None:
        supports = _support_rows(mech, sites, angles, speed, force)
    reg = CycleRegressors(  # no driving torque from a site at constant speed
        shaking_force=np.hstack([linkage.shaking_force, force]),
        shaking_moment=np.hstack([linkage.shaking_moment, moment]),
        driving_torque=np.hstack([linkage.driving_torque, np.zeros(moment.shape)]),
        rocking_couple=np.hstack([linkage.rocking_couple, couple]), supports=supports)
    links = tuple(resolve_link(mech, name, None) for name in mech.linkage.link_names)
    x0 = np.concatenate([mech.layout.vector(mech.linkage), site_values])
    rows, factor, inert = objective_rows(reg, problem.objective, links, x0.size, sites)
    if supports is not None:  # (a rod's inertia moves its guide's force: the bound sees it)
        seen = np.any(supports != 0, axis=0)
        inert = tuple(bool(i and not seen[k]) for k, i in enumerate(inert))
    return NumericProblem(problem=problem, mechanism=mech, speed=speed,
                          states=InputState.crank(angles, speed), regressors=reg, links=links,
                          x0=x0, rows=rows, factor=factor, force_balance=None, inert=inert,
                          sites=sites)


def _support_rows(mech: Mechanism, sites: Sites, angles: NDArray[np.float64], speed: float,
                  force: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """The supports' (an engine's main bearings') loads over the design vector, ``(S·N, P)``.

    The linkage's entries by the supports' regressors
    (:meth:`~balancer.mechanisms.base.Supports.regressors`); each mass·radius on the
    crankshaft (:meth:`.sites.Site.on_crank`) its centrifugal force ``force``'s columns shared
    by :meth:`~balancer.mechanisms.base.Supports.shares`; a shaft's, coaxial or not, on its
    own bearings.
    """
    supports = mech.supports
    if supports is None:
        raise SpecError("needs the main bearings' planes: [mechanism] main_bearings",
                        key="balance")
    with np.errstate(all="ignore"):
        per = supports.regressors(mech.motion(angles, speed, 0.0))
    rows = []
    frame = mech.linkage.ground.points
    for j, linkage_rows in enumerate(per):
        cols = np.zeros(force.shape, complex)
        for i, site in enumerate(sites.sites):
            if site.on_crank(frame):
                share = dict(supports.shares(site.z, site.at)).get(j, 0.0)
                cols[:, 2 * i : 2 * i + 2] = share * force[:, 2 * i : 2 * i + 2]
        rows.append(np.hstack([linkage_rows, cols]))
    return np.vstack(rows)


def _along_motions(design: Design, problem: BalanceProblem, mech: Mechanism) -> NumericProblem:
    """The problem of a linkage with several inputs, its objective along the spec's motions.

    The states of every motion one after another (:func:`balancer.linkage.trajectory.
    input_state`), each motion weighted equally (its rows by
    :func:`balancer.motion_analysis.motion_weights`); the regressors from the core's inverse
    dynamics (:func:`balancer.linkage.dynamics.regressors`), every input's torque stacked
    under ``driving_torque`` times ``√m`` (``m`` inputs: its mean square the sum of the
    inputs'). Force balance: the total centre of mass still for every motion (the conditions
    of :mod:`balancer.force_balance`, over the inputs' space). What the frame feels as the
    inputs accelerate is the objective's own (the motions accelerate): the counter-rotors'
    settling weighs the shaking moment along them.
    """
    if not design.motions:
        raise SpecError("balancing a linkage with several inputs weighs its loads along its "
                        "motions: the spec has no [[motion]]", key="motion")
    parts = []
    for i, motion in enumerate(design.motions):
        with v.under(v.item("motion", i)):
            parts.append(trajectory.input_state(mech.structure, motion))
    states = InputState.join(parts)
    weights = problem.weights_of([m.name for m in design.motions])
    scale = motion_weights([p.count for p in parts], weights)[:, None]
    with np.errstate(all="ignore"):
        f = mech.regressors(mech.motion_at(states))
    complex_rows = cast("Callable[[V], NDArray[np.complex128]]",
                        lambda vector: np.asarray(vector.complex(), dtype=complex) * scale)
    reg = CycleRegressors(
        shaking_force=complex_rows(f.shaking_force),
        shaking_moment=np.asarray(f.shaking_moment) * scale,
        driving_torque=stacked_torques(f.input_torques, scale),
        rocking_couple=complex_rows(f.rocking_couple))
    along = force_balance_along(mech, parts) if problem.force_scope == "motion" else None
    return _problem(problem, mech, None, states, reg, reg, along)


def _force_balance(problem: BalanceProblem, mech: Mechanism,
                   along: ForceBalance | None = None
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """``(A, b)`` of the problem's force balance, or none.

    Over the inputs' space, or ``along`` the motions (``[balance] force = "motion"``).
    """
    if not problem.force_balance:
        return None
    if problem.force_scope == "motion":
        assert along is not None, "the motions' conditions"
        return along.matrix, np.zeros(along.count)
    return force_balance_system(mech)


def _checked_problem(problem: object) -> BalanceProblem:
    """``problem`` if it is a redesign problem; :class:`SpecError` if there is none."""
    if problem is None:
        raise SpecError("missing required table: the redesign problem ([balance])",
                        key="balance")
    if not isinstance(problem, BalanceProblem):
        raise TypeError(f"design.balance must be a BalanceProblem, not {type(problem).__name__}")
    return problem
