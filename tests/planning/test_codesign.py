"""The masses and the time law chosen together (``plan --with-masses``).

Block coordinate descent on the plan's objective, each step its lever's certified convex
problem: the objective never rises, the result beats each lever alone, and at it neither lever
alone does better — re-planned at its masses and re-balanced along its motion, the objective
stays. The force balance holds along the chosen motion.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer.api.planning import codesign, planned_design
from balancer.cli import main
from balancer.mechanisms import mechanism_of
from balancer.model.plan import PlanSpec
from balancer.planning import objective_of, plan_motion, weights_of
from balancer.planning.codesign import _balanced, _mass_objective
from balancer.spec import dumps_design, load_design, loads_design

#: A few seconds of optimisation: the full suite's, not the fast lane's.
pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def forbal():
    design = load_design(EXAMPLES / "forbal2.toml")
    settings = replace(design.plan, intervals=80)
    return design, settings, codesign(design, settings=settings)


def test_the_objective_never_rises_and_both_levers_beat_each_alone(forbal):
    _, _, result = forbal
    rounds = np.array(result.rounds)
    assert np.all(np.diff(rounds) <= 1e-9 * rounds[:-1]) and not result.projected
    j = result.objectives
    assert j["both"] <= min(j["masses"], j["motion"]) * (1 + 1e-12)
    assert j["masses"] <= j["spec"] and j["motion"] < j["spec"]
    force = np.abs(result.analyses["both"].reactions.shaking_force)
    assert np.max(force) <= 1e-9 * np.max(np.abs(result.analyses["spec"].reactions.shaking_force))


def test_at_the_result_neither_lever_alone_does_better(forbal):
    design, settings, result = forbal
    chosen = result.design
    again = plan_motion(mechanism_of(chosen.mechanism), result.plan.path, settings)
    assert again.objective_after == pytest.approx(result.objectives["both"], rel=1e-5)
    problem = replace(design.balance, objective=_mass_objective(settings.objective,
                                                                design.balance.objective))
    masses = _balanced(chosen, problem, result.plan.planned)
    weights = weights_of(result.plan.problem.loads.names, settings.objective)
    rebalanced = objective_of(mechanism_of(masses.linkage), result.plan.planned, weights, "rms")
    assert rebalanced >= result.objectives["both"] * (1 - 1e-5)


def test_the_written_spec_holds_the_chosen_masses_and_the_motion(forbal):
    design, _, result = forbal
    text = dumps_design(planned_design(result.design, result.plan))
    again = loads_design(text)
    assert again.original is not None
    assert again.mechanism != design.mechanism
    assert again.motion(result.plan.planned.name) == result.plan.planned


def test_the_verb_reports_each_lever(capsys):
    assert main(["plan", str(EXAMPLES / "forbal2.toml"), "--with-masses", "--intervals", "40",
                 "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert set(doc["levers"]) == {"spec", "masses", "motion", "both"}
    assert doc["levers"]["both"]["objective"] <= doc["levers"]["motion"]["objective"]
    assert main(["plan", str(EXAMPLES / "forbal2.toml"), "--with-masses", "--intervals",
                 "40"]) == 0
    out = capsys.readouterr().out
    for words in ("the masses alone", "the time law alone", "both", "neither lever alone"):
        assert words in out


def test_the_verb_refuses_a_spec_without_balance(capsys, tmp_path):
    spec = tmp_path / "bare.toml"
    spec.write_text((EXAMPLES / "three_rrr.toml").read_text().split("\n[balance]")[0])
    assert main(["plan", str(spec), "--with-masses"]) == 2
    err = capsys.readouterr().err
    assert "balance" in err and len(err.strip().splitlines()) == 1


def test_a_one_input_press_s_masses_are_chosen_along_its_varying_speed():
    # the crank's counterweight along the planned revolution (its speed varies): balanced
    # along the motion, not at constant speed — at constant speed the counterweight leaves the
    # torque as it was; along a varying speed it does not
    design = load_design(EXAMPLES / "servo_press.toml")
    result = codesign(design, settings=replace(design.plan, intervals=60))
    rounds = np.array(result.rounds)
    assert np.all(np.diff(rounds) <= 1e-9 * rounds[:-1])
    j = result.objectives
    assert j["both"] <= min(j["masses"], j["motion"]) * (1 + 1e-12)
    spec_torque = result.analyses["spec"].loads()["torque_crank"].rms
    masses_torque = result.analyses["masses"].loads()["torque_crank"].rms
    assert masses_torque == pytest.approx(spec_torque, rel=1e-9)  # (constant speed)
    assert result.design.mechanism != design.mechanism


def test_the_masses_are_chosen_for_a_mean_square_only(capsys):
    assert main(["plan", str(EXAMPLES / "forbal2.toml"), "--with-masses", "--measure",
                 "peak"]) == 2
    err = capsys.readouterr().err
    assert "--measure" in err and len(err.strip().splitlines()) == 1


def test_where_the_spec_s_masses_are_not_balanced_the_first_step_projects(capsys):
    # the 3-RRR's masses are not force-balanced; its [balance] balances them: the first
    # masses step raises J (the balance costs shaking moment), and from there J never rises
    design = load_design(EXAMPLES / "three_rrr.toml")
    result = codesign(design, settings=PlanSpec(intervals=40))
    rounds = np.array(result.rounds)
    assert result.projected
    assert np.all(np.diff(rounds[1:]) <= 1e-9 * rounds[1:-1])
    assert main(["plan", str(EXAMPLES / "three_rrr.toml"), "--with-masses", "--intervals",
                 "40"]) == 0
    assert "projects onto them" in capsys.readouterr().out
