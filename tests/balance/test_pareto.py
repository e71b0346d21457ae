"""Exact trade-off fronts (balance/pareto.py, ``balancer pareto``).

Each point is checked against a second-order cone program written here from the spec's own
bounds in the links' inertial parameters, with CVXPY canonicalising it (the product assembles
its programs in the solver's scaled variables from :mod:`balancer.balance.convex`'s constraint
builder): the least RMS shaking moment with the RMS driving torque at most the point's ε.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from helpers import least_rms_moment_by_cvxpy, rank_rows

from balancer.balance.optimizer import optimize
from balancer.balance.pareto import pareto_front
from balancer.cli import main
from balancer.spec import load_design

#: Clarabel's tolerances (1e-10) on programs scaled to the original's RMS, with the repairs'
#: moves of the same size: the product claims optimality to 1e-6 of that scale.
GAP = 1e-6


def _least_moment_by_cvxpy(design, epsilon: float) -> float:
    """min RMS shaking moment s.t. RMS driving torque ≤ ε, force balance and PB1's bounds."""
    import cvxpy as cp

    def torque_cap(x, data):
        torque = rank_rows(data.regressors.driving_torque)
        scale = float(np.linalg.norm(torque @ data.x0))
        return [cp.norm(torque @ x) / scale <= epsilon * math.sqrt(data.samples) / scale]

    return least_rms_moment_by_cvxpy(design, torque_cap)


@pytest.fixture(scope="module")
def pb1_front():
    design = load_design("examples/pb1.toml")
    return design, pareto_front(design, "driving-torque", 6)


def test_front_is_ordered_monotone_certified_and_marks_one_knee(pb1_front):
    _, front = pb1_front
    values = [p.value for p in front.points]
    moments = [p.shaking_moment for p in front.points]
    assert values == sorted(values)
    scale = moments[0]
    # Non-increasing: a larger bound on the torque allows every design a smaller one did.
    assert all(b <= a + GAP * scale for a, b in zip(moments, moments[1:], strict=False))
    for p in front.points:
        assert p.lower_bound <= p.shaking_moment * (1 + 1e-12)
        assert p.shaking_moment - p.lower_bound <= GAP * scale
        # The design meets its bound on the torque (to the repairs' rounding-size moves).
        assert p.value <= p.epsilon * (1 + 1e-7)
    assert sum(p.knee for p in front.points) == 1


def test_front_points_are_the_optima_of_an_independent_program(pb1_front):
    design, front = pb1_front
    # (Not the first point: its bound is the least torque itself, plus 1e-8 of room, a set
    # too thin for a generic program's solver to call "optimal".)
    for p in (front.points[1], front.points[3], front.points[-1]):
        best = _least_moment_by_cvxpy(design, p.epsilon)
        assert p.shaking_moment == pytest.approx(best, rel=GAP, abs=GAP * front.points[0]
                                                 .shaking_moment)


def test_front_ends_at_the_balancing_optimum(pb1_front):
    design, front = pb1_front
    result = optimize(design, "convex")
    assert front.points[-1].shaking_moment == pytest.approx(result.rms, rel=GAP)


def test_an_objective_the_design_cannot_change_gives_one_point():
    """The engine's crank (the only free link) changes its shaking force but not its shaking
    moment about A0 (its inertial force passes through A0 at constant speed): one point."""
    design = load_design("examples/engine.toml")
    front = pareto_front(design, "shaking-force", 5)
    assert len(front.points) == 1
    analysis_moment = front.original[1]
    assert front.points[0].shaking_moment == pytest.approx(analysis_moment, rel=1e-9)


def test_pareto_command_writes_json_csv_and_plot(tmp_path, capsys):
    csv, png = tmp_path / "front.csv", tmp_path / "front.png"
    code = main(["pareto", "examples/pb1_counterweights.toml", "--against", "added-mass",
                 "--points", "4", "--json", "--csv", str(csv), "--plot", str(png)])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["against"] == "added-mass" and len(doc["points"]) == 4
    assert all({"shaking_moment", "added_mass"} <= set(p) for p in doc["points"])
    masses = [p["added_mass"] for p in doc["points"]]
    assert masses == sorted(masses)
    header = csv.read_text().splitlines()[0]
    assert header == "shaking_moment,added_mass,epsilon,lower_bound,knee"
    assert png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("args, key", [
    (["--against", "speed"], "--against"),
    (["--against", "driving-torque", "--plot", "front.txt"], "--plot"),
    (["--against", "driving-torque", "--points", "1"], "--points"),
    (["--against", "driving-torque", "--points", "100000"], "--points"),
])
def test_pareto_command_refuses_bad_arguments(args, key, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    spec = tmp_path / "pb1.toml"
    spec.write_text((Path(__file__).resolve().parents[2] / "examples" / "pb1.toml")
                    .read_text())
    assert main(["pareto", str(spec), *args]) == 2
    err = capsys.readouterr().err
    assert key in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "front.txt").exists()


def test_a_loose_bound_of_a_front_point_is_tightened_by_another_solve(monkeypatch):
    """As the convex program's certificate: a point whose first bound is loose (a dual off by
    more than its tolerance, as another machine's arithmetic can leave it) is solved again with
    other settings and keeps the highest bound, tight again and still below the point."""
    from balancer.balance import convex, pareto

    exact = pareto._certified
    calls: list[int] = []

    def first_loose(programs, cap, solution, x):
        calls.append(1)
        bound = exact(programs, cap, solution, x)
        return bound * (1 - 1e-3) if len(calls) == 1 else bound

    monkeypatch.setattr(pareto, "_certified", first_loose)
    front = pareto_front(load_design("examples/pb1.toml"), "driving-torque", points=3)
    assert len(calls) >= 3 + 1  # (at least) the loose point solved again
    scale = max(p.least for p in front.points)
    for p in front.points:
        assert p.lower_bound <= p.least + 1e-9 * scale  # (the certificate's rounding)
        assert p.least - p.lower_bound <= 10 * convex.CERTIFY_AGAIN * scale


def test_a_point_whose_bound_was_not_made_is_not_called_certified(pb1_front):
    # A lower bound of 0 under a positive optimum is no certificate (the certificate could not
    # bound the program's box): the table shows it as such and the heading stops claiming one.
    import dataclasses

    from balancer.report.fronts import front_text

    _, front = pb1_front
    text = front_text(front)
    assert "each a global optimum with its certified lower bound" in text and "—" not in text
    first = dataclasses.replace(front.points[0], lower_bound=0.0)
    bare = dataclasses.replace(front, points=(first, *front.points[1:]))
    text = front_text(bare)
    assert "certified where shown" in text
    row = next(line for line in text.splitlines() if line.startswith("1 "))
    assert "—" in row
