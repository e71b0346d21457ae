"""Balancing a linkage with several inputs: force balance for every motion, the objective along
the spec's motions (:func:`balancer.balance.problem.numeric_problem`'s ``_along_motions``).

Each optimum against a second route: the least added mass that force-balances the parallelogram
five-bar with a counterweight on each crank, in closed form (each crank must carry the first
moment that cancels its direction's: its counterweight's mass that moment's magnitude over its
radius); the balanced design's centre of mass over the workspace, by the forward kinematics of
the redesigned linkage; the objective along the motions, from the redesigned linkage's own
inverse dynamics along each motion (not the problem's regressors), each motion weighted alike.
"""

from __future__ import annotations

import copy
import tomllib

import cvxpy as cp
import numpy as np
import pyarrow.parquet as pq
import pytest
from linkage.several_inputs_specs import A, B, parallelogram

from balancer.balance.certificate import _bounded_below_box
from balancer.balance.optimizer import optimize
from balancer.balance.pareto import pareto_front
from balancer.balance.problem import numeric_problem
from balancer.balance.result import GAP_TOLERANCE
from balancer.errors import SpecError
from balancer.motion_analysis import along_motions, workspace_check
from balancer.spec.reader import design_from_dict
from balancer.spec.writer import dumps_design
from balancer.sweeps import Vary, sweep

RADIUS = 0.1

MOTIONS = [
    {"name": "wave", "times": [0.0, 0.5, 1.0], "path": [[0.0, 0.0], [0.2, -0.1], [0.0, 0.0]],
     "law": "spline", "samples": 48},
    {"name": "swing", "times": [0.0, 0.6, 1.2], "path": [[0.0, 0.0], [-0.15, 0.25], [0.1, 0.0]],
     "law": "quintic", "samples": 40},
]


def spec(objective: dict, counter_rotor: bool = False) -> dict:
    out = parallelogram()
    cw = {"counterweight": {"mass": [0.0, 3.0], "radius": RADIUS}}
    if counter_rotor:
        cw["counter_rotor"] = [0.0, 0.01]
    out["balance"] = {"force_balance": True, "objective": objective,
                      "p": copy.deepcopy(cw), "q": copy.deepcopy(cw)}
    out["motion"] = copy.deepcopy(MOTIONS)
    out["workspace"] = {"p": [-0.5, 0.5], "q": [-0.5, 0.5], "samples": 11}
    return out


def _first_moment(link: dict) -> complex:
    return link["mass"] * complex(link["com"]["e"], link["com"]["f"])


def _missing_first_moments() -> tuple[complex, complex]:
    """What each arm must add: along p's direction p, r (at A from p's pivot) and s carry
    first moments, along q's q, s (at B) and r; each arm cancels its direction's."""
    links = parallelogram()["links"]
    need_p = -(A * links["r"]["mass"] + _first_moment(links["s"])) - _first_moment(links["p"])
    need_q = -(B * links["s"]["mass"] + _first_moment(links["r"])) - _first_moment(links["q"])
    return need_p, need_q


def _least_added_mass() -> float:
    """Each arm's counterweight at its radius: its missing first moment over the radius, kg."""
    return sum(abs(need) for need in _missing_first_moments()) / RADIUS


def test_the_least_added_mass_is_each_cranks_missing_first_moment_over_its_radius():
    data = spec({"added_mass": 1.0, "shaking_moment": 0.0})
    result = optimize(design_from_dict(data))
    assert result.success and str(result.status) == "optimal"
    need_p, need_q = _missing_first_moments()
    assert result.added_mass == pytest.approx(_least_added_mass(), rel=10 * GAP_TOLERANCE)
    # each counterweight at its radius, opposite what it cancels
    for name, need in (("p", need_p), ("q", need_q)):
        w = result.counterweights[name]
        assert abs(complex(w.e, w.f)) == pytest.approx(RADIUS, rel=1e-6)
        assert w.mass * complex(w.e, w.f) == pytest.approx(need, rel=1e-6, abs=1e-9)


def test_the_balanced_design_keeps_its_centre_of_mass_over_the_workspace():
    design = design_from_dict(spec({"added_mass": 1.0, "shaking_moment": 0.0}))
    result = optimize(design)
    check = workspace_check(result.linkage, design.workspace)
    assert check.states > 60
    assert check.centre_of_mass_excursion <= 1e-14
    original = workspace_check(design.mechanism, design.workspace)
    assert original.centre_of_mass_excursion > 1e-3


@pytest.mark.parametrize("objective", [{"shaking_moment": 1.0},
                                       {"shaking_moment": 1.0, "driving_torque": 0.5}])
def test_the_objective_is_the_redesigns_own_loads_along_the_motions(objective):
    design = design_from_dict(spec(objective, counter_rotor=True))
    result = optimize(design)
    assert result.success and str(result.status) == "optimal"
    # The redesigned linkage's loads, by its own inverse dynamics along each motion.
    along = along_motions(result.linkage, design.motions, loads=False)
    moment = np.mean([np.mean(m.reactions.shaking_moment**2) for m in along.motions])
    torque = np.mean([sum(np.mean(t**2) for t in m.reactions.torques) for m in along.motions])
    j = objective["shaking_moment"] * moment + objective.get("driving_torque", 0.0) * torque
    assert result.objective == pytest.approx(j, rel=1e-9)
    assert np.max(np.abs(along.reactions.shaking_force)) <= 1e-12
    # and it is the best: no lower than its certified bound, within the certificate's gap
    assert result.lower_bound <= result.objective * (1 + 1e-12)
    assert result.gap <= GAP_TOLERANCE
    # the original's, the same way
    before = along_motions(design.mechanism, design.motions, loads=False)
    moment0 = np.mean([np.mean(m.reactions.shaking_moment**2) for m in before.motions])
    torque0 = np.mean([sum(np.mean(t**2) for t in m.reactions.torques) for m in before.motions])
    j0 = objective["shaking_moment"] * moment0 + objective.get("driving_torque", 0.0) * torque0
    assert result.original_objective == pytest.approx(j0, rel=1e-9)


def test_a_linkage_with_several_inputs_and_no_motion_is_refused():
    data = spec({"shaking_moment": 1.0})
    del data["motion"]
    with pytest.raises(SpecError, match="no \\[\\[motion\\]\\]") as caught:
        optimize(design_from_dict(data))
    assert caught.value.key == "motion"


@pytest.mark.parametrize("against", ["added-mass", "driving-torque"])
def test_the_front_along_the_motions_is_the_redesigns_own(against):
    design = design_from_dict(spec({"shaking_moment": 1.0}))
    front = pareto_front(design, against, 4)
    data = numeric_problem(design)
    for point in front.points:
        along = along_motions(data.linkage_of(point.x), design.motions, loads=False)
        moment = np.sqrt(np.mean([np.mean(m.reactions.shaking_moment**2)
                                  for m in along.motions]))
        assert point.least == pytest.approx(moment, rel=1e-9)
        if against == "driving-torque":  # the inputs' mean squares summed, motions alike
            torque = np.sqrt(np.mean([sum(np.mean(t**2) for t in m.reactions.torques)
                                      for m in along.motions]))
            assert point.value == pytest.approx(torque, rel=1e-9)
        assert point.lower_bound <= point.least * (1 + 1e-9)
    if against == "added-mass":  # its least end: the least mass that balances it
        assert front.points[0].value == pytest.approx(_least_added_mass(), rel=1e-5)


def test_a_sweep_balances_each_point_along_the_motions(tmp_path):
    """A sweep over the coupler r's mass: each point's least added mass is its closed form's
    (each arm's missing first moment over its radius, r's mass entering along p's)."""
    path = tmp_path / "pick.toml"
    path.write_text(dumps_design(design_from_dict(spec({"added_mass": 1.0,
                                                        "shaking_moment": 0.0}))))
    out = tmp_path / "sweep.parquet"
    sweep(path, [Vary("links.r.mass", 0.05, 0.2, 3)], out, workers=0)
    rows = pq.read_table(out).to_pylist()
    assert [r["status"] for r in rows] == ["optimal"] * 3
    links = parallelogram()["links"]
    for row in rows:
        mass = row["links.r.mass"]
        r = dict(links["r"], mass=mass)
        need_p = -(A * mass + _first_moment(links["s"])) - _first_moment(links["p"])
        need_q = -(B * links["s"]["mass"] + _first_moment(r)) - _first_moment(links["q"])
        closed = (abs(need_p) + abs(need_q)) / RADIUS
        assert row["added_mass"] == pytest.approx(closed, rel=10 * GAP_TOLERANCE)
        assert row["shaking_force_after"] <= 1e-12 < row["shaking_force_before"]


def test_a_motions_weight_weighs_its_mean_squares():
    """``[balance.motions] wave = 3``: J is (3·J_wave + J_swing)/4, from the redesign's own
    inverse dynamics; the weights are read, written back and refused where they name no
    motion."""
    data = spec({"shaking_moment": 1.0})
    data["balance"]["motions"] = {"wave": 3.0}
    design = design_from_dict(data)
    result = optimize(design)
    assert result.success
    along = along_motions(result.linkage, design.motions, loads=False)
    means = [np.mean(m.reactions.shaking_moment**2) for m in along.motions]
    assert result.objective == pytest.approx((3 * means[0] + means[1]) / 4, rel=1e-9)
    again = design_from_dict(tomllib.loads(dumps_design(design)))
    assert again.balance == design.balance
    data["balance"]["motions"] = {"nowhere": 1.0}
    with pytest.raises(SpecError, match="names no motion") as caught:
        design_from_dict(data)
    assert caught.value.key == "balance.motions.nowhere"
    data["balance"]["motions"] = {"wave": 0.0, "swing": 0.0}
    with pytest.raises(SpecError, match="every motion weighs 0"):
        design_from_dict(data)


def test_entries_the_objective_sees_only_together_are_bounded_and_the_optimum_certified():
    """Two counterweights on links that turn alike (p and s of the parallelogram): their
    inertias enter the shaking moment only through their sum, and have no upper bound. The
    certificate bounds each by the sum's bound and the other's lower bound: the optimum and
    every point of the front are certified (each bound at most its value, within the gap)."""
    data = spec({"shaking_moment": 1.0})
    data["balance"]["s"] = copy.deepcopy(data["balance"]["p"])
    design = design_from_dict(data)
    result = optimize(design)
    assert str(result.status) == "optimal", result.message
    assert 0 < result.lower_bound <= result.objective * (1 + 1e-12)
    assert result.gap <= GAP_TOLERANCE
    front = pareto_front(design, "added-mass", 3)
    for point in front.points:
        assert 0 < point.lower_bound <= point.least * (1 + 1e-9)
        assert point.least - point.lower_bound <= 1e-6 * point.least


@pytest.mark.parametrize("seed", range(6))
def test_the_box_of_entries_seen_together_holds_every_point_of_the_sublevel_set(seed):
    """:func:`certificate._bounded_below_box` against CVXPY's largest entry over the set it
    bounds (``‖P_J·u‖ ≤ reach``, ``u ≥ low``), for columns repeated or combined."""


    rng = np.random.default_rng(seed)
    base = rng.normal(size=(5, 2))
    pj = np.column_stack([base[:, 0], base[:, 0], base[:, 1], base[:, 0] + 0.5 * base[:, 1]])
    low = rng.uniform(-1.0, 1.0, 4)
    reach = float(rng.uniform(1.0, 5.0)) + float(np.linalg.norm(pj @ low))
    free = np.ones(4, dtype=bool)
    box = _bounded_below_box(pj, low, reach, np.full(4, np.inf), free)
    assert box is not None
    for j in range(4):
        u = cp.Variable(4)
        problem = cp.Problem(cp.Maximize(u[j]), [cp.norm(pj @ u) <= reach, u >= low])
        problem.solve(solver=cp.CLARABEL)
        assert problem.value <= box[j] * (1 + 1e-7) + 1e-7
    # a direction along which every entry may grow (columns c and −c): no box
    unbounded = np.column_stack([base[:, 0], -base[:, 0]])
    assert _bounded_below_box(unbounded, np.zeros(2), 1.0, np.full(2, np.inf),
                              np.ones(2, dtype=bool)) is None


def test_torque_is_the_inputs_torques_term_by_designs_name():
    # `[balance.objective] torque` (DESIGN.md's name for several inputs) is driving_torque.
    from importlib.resources import files

    base = tomllib.loads((files("balancer") / "examples" / "pick_fivebar.toml").read_text())
    by_name = copy.deepcopy(base)
    by_name["balance"].setdefault("objective", {}).pop("driving_torque", None)
    by_name["balance"]["objective"]["torque"] = 0.5
    by_key = copy.deepcopy(base)
    by_key["balance"].setdefault("objective", {})["driving_torque"] = 0.5
    a, b = (design_from_dict(d).balance for d in (by_name, by_key))
    assert a == b and a is not None and a.objective.driving_torque == 0.5
    both = copy.deepcopy(by_key)
    both["balance"]["objective"]["torque"] = 0.5
    with pytest.raises(SpecError, match="not both") as caught:
        design_from_dict(both)
    assert caught.value.key == "balance.objective.torque"


def _swing_only_p(scope: str) -> dict:
    """pick_fivebar with one motion that swings p alone (q held), force balanced by scope."""
    from importlib.resources import files

    spec = tomllib.loads((files("balancer") / "examples" / "pick_fivebar.toml").read_text())
    spec["motion"] = [{"name": "swing", "times": [0.0, 0.5, 1.0],
                       "path": [[0.0, 0.0], [0.4, 0.0], [0.0, 0.0]], "law": "quintic",
                       "samples": 60}]
    spec["balance"]["force"] = scope
    return spec


def test_force_balance_along_the_motions_only_is_a_relaxation():
    # Along a swing of p alone the total centre of mass must stay still only as p turns: q's
    # counterweight is not needed. The least added mass is then p's closed form alone, at most
    # the every-motion optimum; the shaking force vanishes along the swing, not everywhere.
    everywhere = optimize(design_from_dict(_swing_only_p("every-motion")))
    along = optimize(design_from_dict(_swing_only_p("motion")))
    for result in (everywhere, along):
        assert result.success and result.lower_bound is not None
    assert along.objective <= everywhere.objective + GAP_TOLERANCE * everywhere.objective
    assert along.objective < 0.5 * everywhere.objective  # (q's arm no longer balanced)
    design = design_from_dict(_swing_only_p("motion"))
    balanced = along.balanced_design(design)
    analysis = along_motions(balanced.mechanism, balanced.motions)
    swing = analysis.motions[0]
    assert swing.loads()["shaking_force"].max <= 1e-12 * swing.natural_scales()["N"]
    assert not analysis.force_balanced  # over the workspace it is not
    # p alone carries the first moment its swing needs: the every-motion optimum's own
    # counterweight on p (the parallelogram's p-direction condition), not q's.
    p_weight = everywhere.counterweights["p"].mass
    assert abs(along.added_mass - p_weight) <= 1e-6 * p_weight
    assert everywhere.counterweights["q"].mass > 0.1
    text = dumps_design(balanced)
    assert 'force = "motion"' in text
    again = design_from_dict(tomllib.loads(text))
    assert again.balance is not None and again.balance.force_scope == "motion"


def test_the_motions_conditions_hold_between_their_samples():
    from balancer.force_balance import first_moment_map, force_balance_along
    from balancer.linkage import trajectory
    from balancer.mechanisms import mechanism_of

    design = design_from_dict(_swing_only_p("motion"))
    mech = mechanism_of(design.mechanism)
    motion = design.motions[0]
    conditions = force_balance_along(mech, [trajectory.input_state(mech.structure, motion)])
    assert 0 < conditions.count < 4  # fewer than the whole space's four
    # Any design in the conditions' null space keeps the centre of mass still at fresh times.
    rng = np.random.default_rng(7)
    null = np.linalg.svd(conditions.matrix)[2][conditions.count:].T
    x = null @ rng.normal(size=null.shape[1])
    fresh = trajectory.input_state(mech.structure, motion, rng.uniform(0.0, 1.0, 25))
    g = first_moment_map(mech, fresh) @ x
    assert np.max(np.abs(g - g.mean())) <= 1e-12 * np.max(np.abs(first_moment_map(mech, fresh))
                                                            @ np.abs(x))


def test_force_scope_is_a_several_input_key():
    spec = _swing_only_p("sometimes")
    with pytest.raises(SpecError, match="must be one of every-motion, motion") as caught:
        design_from_dict(spec)
    assert caught.value.key == "balance.force"
    from linkage.several_inputs_specs import crank_rocker

    one = crank_rocker() | {"operation": {"speed": 10.0},
                            "balance": {"force": "motion", "crank": {"mass": [0.5, 2.0]}}}
    with pytest.raises(SpecError, match="several inputs along its motions") as caught:
        design_from_dict(one)
    assert caught.value.key == "balance.force"
