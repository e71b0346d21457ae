"""Links in several planes along the crank's axis: the rocking couple.

DESIGN.md defines it from momentum, ``Mx = Σ_b z_b·(m_b·a_b,y − F_b,y)``,
``My = Σ_b z_b·(F_b,x − m_b·a_b,x)``. The independent route here differentiates the centres of
mass' positions over the cycle (spectrally, twice: ``a = ω²·d²r/dθ²`` at constant speed), the
positions from the seed's closed form for the four-bar (Eq. 1–11, not the general core) and from
the general core's positions alone for a six-bar; the weights and applied forces are added by
hand. A mechanism in two planes is also compared with the same in one: everything in the plane
is unchanged.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer.cycle import cycle_analysis
from balancer.mechanisms import geometry, mechanism_of
from balancer.mechanisms.fourbar.kinematics import position
from balancer.mechanisms.fourbar.massmodels import link_centres_of_mass
from balancer.spec import dumps_design, load_design, loads_design

EXAMPLES = Path(__file__).resolve().parents[2] / "balancer" / "examples"
EPS = float(np.finfo(float).eps)
GRAVITY = (0.0, -9.81)


def _in_planes(model, planes: dict[str, float]):
    return model.with_links({name: replace(model.link(name), z=z) for name, z in planes.items()})


def _second_derivative(values: np.ndarray) -> tuple[np.ndarray, float]:
    """``d²x/dθ²`` of periodic samples over one revolution, spectrally; and its error bound.

    The bound: what the spectrum's upper half (where a smooth cycle's harmonics have decayed)
    would add, times the largest order squared, plus the transform's rounding.
    """
    n = values.size
    spectrum = np.fft.fft(values)
    order = np.fft.fftfreq(n, 1.0 / n)
    spectrum[np.abs(order) == n // 2] = 0.0
    second = np.fft.ifft(-(order**2) * spectrum)
    tail = float(np.max(np.abs(spectrum[np.abs(order) > n // 4]))) / n
    bound = tail * (n / 2) ** 2 * n + 8 * n * EPS * float(np.max(np.abs(second)))
    return second, bound


def _momentum_couple(zs, masses, forces, centres, speed) -> tuple[np.ndarray, float]:
    """``Mx + i·My`` from the centres of mass (complex, over the cycle) by DESIGN's sums."""
    total = np.zeros(centres[0].size, complex)
    bound = 0.0
    for z, m, f, r in zip(zs, masses, forces, centres, strict=True):
        d2, err = _second_derivative(r)
        a = speed**2 * d2
        load = f + m * complex(*GRAVITY)
        total += z * (m * a.imag - load.imag) + 1j * z * (load.real - m * a.real)
        bound += abs(z) * m * speed**2 * err
    return total, bound


def test_the_four_bars_rocking_couple_is_minus_the_rate_of_its_angular_momentum():
    design = load_design(EXAMPLES / "meijaard2020.toml")
    planes = {"crank": 0.0, "coupler": 0.12, "rocker": -0.07}
    model = _in_planes(design.mechanism, planes)
    speed, samples = design.operation.speed, 1024
    for route in ("newton-euler", "mass-matrix"):
        analysis = cycle_analysis(model, speed, samples, gravity=GRAVITY, route=route)
        pos = position(model.lengths, analysis.theta1, model.branch)
        centres = link_centres_of_mass(model, pos)
        want, bound = _momentum_couple(
            [link.z for link in model.links], [link.mass for link in model.links],
            [link.force_complex for link in model.links], centres, speed)
        got = analysis.reactions.rocking_couple
        scale = float(np.max(np.abs(want)))
        assert scale > 1.0  # a couple worth checking
        assert np.max(np.abs(got - want)) <= bound + 1e-12 * scale, route


def test_a_six_bar_in_two_planes_rocks_as_its_momentum_says():
    design = load_design(EXAMPLES / "watt_sixbar.toml")
    model = design.mechanism
    names = model.link_names
    planes = {name: (0.1 if i >= len(names) // 2 else 0.0) for i, name in enumerate(names)}
    model = _in_planes(model, planes)
    speed, samples = design.operation.speed, 1024
    analysis = cycle_analysis(model, speed, samples, gravity=GRAVITY)
    mech = mechanism_of(model)
    # Positions only: the core's pose at each angle, no rates or accelerations.
    mo = mech.motion(analysis.theta1, 0.0, 0.0)
    centres = [c.complex()[:, 0] if np.ndim(c.complex()) == 2 else c.complex()
               for c in geometry.centres_of_mass(mech, mo)]
    want, bound = _momentum_couple([link.z for link in model.links],
                                   [link.mass for link in model.links],
                                   [link.force_complex for link in model.links], centres, speed)
    got = analysis.reactions.rocking_couple
    scale = float(np.max(np.abs(want)))
    assert scale > 1.0
    assert np.max(np.abs(got - want)) <= bound + 1e-12 * scale


@pytest.mark.parametrize("name", ["meijaard2020", "watt_sixbar", "engine"])
def test_planes_leave_everything_in_the_plane_as_it_was(name):
    design = load_design(EXAMPLES / f"{name}.toml")
    flat = design.mechanism
    planes = {n: 0.05 * (k + 1) for k, n in enumerate(flat.link_names)}
    stacked = _in_planes(flat, planes)
    speed, samples = design.operation.speed, 360
    a = cycle_analysis(flat, speed, samples, gravity=GRAVITY)
    b = cycle_analysis(stacked, speed, samples, gravity=GRAVITY)
    for key in ("shaking_force", "shaking_moment", "driving_torque"):
        x, y = getattr(a.reactions, key), getattr(b.reactions, key)
        assert np.array_equal(x, y), key
    for point in a.reactions.ground:
        assert np.array_equal(a.reactions.ground[point], b.reactions.ground[point])
    assert not np.any(a.reactions.rocking_couple)
    assert a.summary.rocking_couple.max == 0.0
    # In planes: the rocking couple is the moment of each link's share of the shaking force
    # applied in its plane; with every link in one plane z0 it is z0 × the shaking force's.
    level = _in_planes(flat, {n: 0.3 for n in flat.link_names})
    c = cycle_analysis(level, speed, samples, gravity=GRAVITY, loads=False)
    d = cycle_analysis(flat, speed, samples, gravity=GRAVITY, loads=False)
    force = d.reactions.shaking_force
    want = 0.3 * (-force.imag + 1j * force.real)
    scale = float(np.max(np.abs(want)))
    # Without loads and springs the shaking force is the links' shares summed.
    assert not flat.springs
    assert np.max(np.abs(c.reactions.rocking_couple - want)) <= 1e-12 * scale


def test_a_links_plane_is_written_and_read_back():
    design = load_design(EXAMPLES / "meijaard2020.toml")
    moved = replace(design, mechanism=_in_planes(design.mechanism, {"coupler": 0.125}))
    text = dumps_design(moved)
    assert "z = 0.125" in text
    assert loads_design(text).mechanism.link("coupler").z == 0.125
    assert math.isclose(loads_design(dumps_design(design)).mechanism.link("coupler").z, 0.0)


def test_the_rocking_couples_regressors_are_the_cycle_analysis():
    """``R·x`` of the regressors is the rocking couple the cycle analysis finds for design x."""
    from balancer.balance.problem import numeric_problem

    design = load_design(EXAMPLES / "two_plane_drive.toml")
    data = numeric_problem(design)
    rng = np.random.default_rng(20261127)
    for x in (data.x0, data.x0 * (1 + 0.2 * rng.standard_normal(data.size))):
        x = np.abs(x)  # (masses positive: any such vector is a design)
        model = data.linkage_of(x)
        analysis = cycle_analysis(model, design.operation.speed, design.operation.samples,
                                  loads=False)
        got = data.regressors.rocking_couple @ data.vector_of(data.physical(x))
        want = analysis.reactions.rocking_couple
        assert np.max(np.abs(got - want)) <= 1e-12 * np.max(np.abs(want))


def test_balancing_with_the_rocking_couple_reaches_the_independent_optimum():
    """The two-plane drive with J = mean(Msh²) + mean(|Mrock|²): the optimiser's J against a
    CVXPY program written apart (helpers), and against the cycle analysis of its design."""
    from helpers import least_rms_moment_by_cvxpy

    from balancer import optimize

    design = load_design(EXAMPLES / "two_plane_drive.toml")
    result = optimize(design)
    assert result.status == "optimal"

    def rows(data):
        reg = data.regressors
        return np.vstack([reg.shaking_moment, reg.rocking_couple.real, reg.rocking_couple.imag])

    oracle = least_rms_moment_by_cvxpy(design, rows=rows)
    # The certified gap is 1e-6 of the problem's scale (squared); the oracle solves to 1e-9.
    assert math.sqrt(result.objective) == pytest.approx(oracle, rel=2e-6)
    after = result.after  # the inertial cycle analysis of the balanced design
    j = (float(np.mean(after.reactions.shaking_moment**2))
         + float(np.mean(np.abs(after.reactions.rocking_couple) ** 2)))
    assert result.objective == pytest.approx(j, rel=1e-9)
    assert after.summary.rocking_couple.rms < 0.2 * result.before.summary.rocking_couple.rms


def test_a_driven_simulation_rocks_as_the_cycle_analysis(tmp_path):
    """`simulate --all-columns` of the two-plane drive: the rocking couple's columns (after
    shaking_moment) at each output are the cycle analysis' at the same crank angle (the crank
    driven at constant speed: the same states, reached by integration)."""
    import csv

    from balancer.cli import main

    spec = EXAMPLES / "two_plane_drive.toml"
    out = tmp_path / "sim.csv"
    assert main(["simulate", str(spec), "--outputs", "25", "--all-columns", "--out",
                 str(out)]) == 0
    rows = list(csv.reader(out.read_text().splitlines()))
    head = rows[0]
    at = head.index("shaking_moment")
    assert head[at + 1 : at + 3] == ["rocking_couple_x", "rocking_couple_y"]
    data = np.array(rows[1:], dtype=float)
    theta = data[:, head.index("theta1")]
    design = load_design(spec)
    analysis = cycle_analysis(design.mechanism, design.operation.speed,
                              theta1=np.mod(theta, 2 * np.pi))
    want = analysis.reactions.rocking_couple
    got = data[:, at + 1] + 1j * data[:, at + 2]
    # The simulated states are the prescribed motion's to the integrator's tolerance (rtol):
    # the couple, quadratic in the rates, to a few times that.
    assert np.max(np.abs(got - want)) <= 1e-6 * np.max(np.abs(want))


@pytest.mark.slow
def test_the_balanced_two_plane_drive_is_verified_by_simulation():
    """The balanced design (with its [original]) simulated in a formulation the optimiser did
    not use: force balanced to integration level, and the largest rocking couple of the driven
    run that of the balanced design's cycle analysis at the same states, below the original's."""
    from balancer import optimize, verify

    design = load_design(EXAMPLES / "two_plane_drive.toml")
    balanced = optimize(design).balanced_design(design)
    check = verify(balanced)
    driven = check.driven
    assert driven.force_level is not None and driven.force_level < 1e-8
    assert driven.max_rocking_couple < 0.1 * driven.original_max_rocking_couple
    # At the driven run's own crank angles the cycle analysis gives the same couple, to the
    # integrator's tolerance (the states are the prescribed motion's).
    traj = driven.trajectory
    crank = traj.theta[list(traj.links).index("crank")]
    analysis = cycle_analysis(balanced.mechanism, design.operation.speed,
                              theta1=np.mod(crank, 2 * np.pi))
    top = analysis.summary.rocking_couple.max
    assert driven.max_rocking_couple == pytest.approx(top, rel=1e-6)
