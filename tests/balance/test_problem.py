"""The redesign problem: the [balance] section (errors, defaults, exact round trip) and its numbers.

The objective the optimisers minimise is built from the mechanism's regressors (the general
core's linear maps); here it is checked against the cycle analysis by the paper's Newton–Euler
route in closed form, an independent route.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import CLASS_EXAMPLES, PAPER_LENGTHS, paper_linkage, paper_links, random_linkage

from balancer import spec
from balancer.balance.bounds import resolve_link
from balancer.balance.problem import numeric_problem
from balancer.balance.regressors import cycle_regressors, cycle_regressors_at
from balancer.cli import main
from balancer.cycle import cycle_analysis
from balancer.errors import AssemblyError, SpecError
from balancer.linkage.dynamics import shaking_regressors
from balancer.mechanisms import mechanism_of
from balancer.mechanisms.fourbar.model import FourBar
from balancer.model import Design, Operation
from balancer.model.balance import BalanceProblem, LinkFreedom, Objective

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

BASE = """
[mechanism]
type = "four-bar"
[mechanism.lengths]
crank = 1.0
coupler = 3.0
rocker = 2.0
frame = 3.2
[links.crank]
mass = 2.1
inertia = 1.1
com = { s = 0.6, sigma = 0.3 }
[links.coupler]
mass = 3.0
inertia = 3.1
com = { s = 1.45, sigma = 0.4 }
[links.rocker]
mass = 2.2
inertia = 2.1
com = { s = 1.66, sigma = -0.4 }
[operation]
speed = 10.0
samples = 72
[balance]
[balance.crank]
mass = [2.1, 8.4]
com_radius = 1.0
min_gyration = 0.1
counter_rotor = [0.0, 20.0]
"""


def design_vector(mech):
    """The design vector of a mechanism's own links (its layout's)."""
    return mech.layout.vector(mech.linkage)


def _with(old: str, new: str) -> str:
    assert old in BASE
    return BASE.replace(old, new)


BAD = {
    "mass range reversed": (_with("mass = [2.1, 8.4]", "mass = [8.4, 2.1]"),
                            "balance.crank.mass", "exceeds the upper bound"),
    "zero mass bound": (_with("mass = [2.1, 8.4]", "mass = [0.0, 8.4]"),
                        "balance.crank.mass", "positive"),
    "negative fixed mass": (_with("mass = [2.1, 8.4]", "mass = -2.0"),
                            "balance.crank.mass", "positive"),
    "range of three": (_with("mass = [2.1, 8.4]", "mass = [1.0, 2.0, 3.0]"),
                       "balance.crank.mass", "range [low, high]"),
    "range of strings": (_with("mass = [2.1, 8.4]", 'mass = ["light", "heavy"]'),
                         "balance.crank.mass", "range [low, high]"),
    "negative radius": (_with("com_radius = 1.0", "com_radius = -1.0"),
                        "balance.crank.com_radius", "zero or positive"),
    "negative gyration": (_with("min_gyration = 0.1", "min_gyration = -0.1"),
                          "balance.crank.min_gyration", "zero or positive"),
    "negative counter-rotor": (_with("counter_rotor = [0.0, 20.0]", "counter_rotor = [-1.0, 2.0]"),
                               "balance.crank.counter_rotor", "zero or positive"),
    "counter-rotor on the coupler": (BASE + "[balance.coupler]\ncounter_rotor = [0.0, 1.0]\n",
                                     "balance.coupler.counter_rotor", "ground pivot"),
    "joint not on the link": (_with("com_radius = 1.0", 'com_radius = 1.0\ncom_about = "A3"'),
                              "balance.crank.com_about", "joint of the crank (A0 or A1)"),
    "no such joint": (_with("com_radius = 1.0", 'com_radius = 1.0\ncom_about = "B0"'),
                      "balance.crank.com_about", "must be one of"),
    "com_about without radius": (_with("com_radius = 1.0", 'com_about = "A0"'),
                                 "balance.crank.com_about", "needs com_radius"),
    "typo in a link key": (_with("min_gyration = 0.1", "min_gyraton = 0.1"),
                           "balance.crank.min_gyraton", "did you mean 'min_gyration'"),
    "typo in a link name": (BASE.replace("[balance.crank]", "[balance.crnak]"),
                            "balance.crnak", "did you mean 'crank'"),
    "typo in the objective": (BASE + "[balance.objective]\nshaking_moments = 1.0\n",
                              "balance.objective.shaking_moments", "did you mean 'shaking_moment'"),
    "negative weight": (BASE + "[balance.objective]\ndriving_torque = -1.0\n",
                        "balance.objective.driving_torque", "zero or positive"),
    "all weights zero": (BASE + "[balance.objective]\nshaking_moment = 0.0\n",
                         "balance.objective", "nothing to minimise"),
    "force_balance not a bool": (BASE.replace("[balance]\n", '[balance]\nforce_balance = "yes"\n'),
                                 "balance.force_balance", "true or false"),
    "nothing free": (BASE.split("[balance.crank]")[0] + "[balance.crank]\ncounter_rotor = 0.0\n",
                     "balance", "nothing may change"),
    "nothing listed": (BASE.split("[balance.crank]")[0], "balance", "nothing may change"),
    # From the seed-4242 linkage fuzz campaign: both were internal errors in the convex solver
    # (an OverflowError squaring ρ, a ZeroDivisionError from the objective's scale squared).
    "gyration past double precision": (_with("min_gyration = 0.1", "min_gyration = 1e300"),
                                       "balance.crank.min_gyration", "at most 1e+50 m"),
    "subnormal weight": (BASE + "[balance.objective]\nshaking_moment = 5e-324\n",
                         "balance.objective.shaking_moment", "subnormal"),
    "gyration beyond the inertia bound": (
        _with("min_gyration = 0.1", "min_gyration = 0.5\ninertia = [0.1, 0.4]"),
        "balance.crank.min_gyration", "at least m·ρ² = 0.525"),
}  # fmt: skip


@pytest.mark.parametrize("case", list(BAD))
def test_bad_balance_sections_raise_spec_error_naming_the_key(case):
    text, key, words = BAD[case]
    with pytest.raises(SpecError) as info:
        spec.loads_design(text, source="test.toml")
    message = str(info.value)
    assert key in message and words in message and "test.toml" in message, message
    assert "\n" not in message
    assert info.value.exit_code == 2


@pytest.mark.parametrize("case", ["mass range reversed", "typo in a link key", "nothing free"])
def test_bad_balance_sections_exit_2_with_one_line(case, tmp_path, capsys):
    text, key, _ = BAD[case]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and key in err and "Traceback" not in err


def test_the_value_is_named():
    with pytest.raises(SpecError, match=r"got \[8\.4, 2\.1\]"):
        spec.loads_design(BAD["mass range reversed"][0])


def test_a_balance_section_is_read_with_its_defaults():
    design = spec.loads_design(BASE)
    problem = design.balance
    assert isinstance(problem, BalanceProblem)
    assert problem.force_balance is True
    assert problem.objective == Objective(shaking_moment=1.0)
    assert problem.link("crank") == LinkFreedom(
        mass=(2.1, 8.4), com_radius=1.0, min_gyration=0.1, counter_rotor=(0.0, 20.0)
    )
    assert problem.link("coupler") is None and problem.link("rocker") is None


def test_defaults_resolve_as_documented():
    links = paper_links(loads=False)
    mech = mechanism_of(paper_linkage(loads=False))
    # Not listed: everything fixed at the spec's values.
    b = resolve_link(mech, "coupler", None)
    assert b.mass == (3.0, 3.0) and b.com_fixed == links["coupler"].com
    assert b.inertia == (3.1, 3.1) and b.counter_rotor is None
    # Mass free: inertia free (ρ = 0 by default); the rocker's radius is about A3 = l3.
    b = resolve_link(mech, "rocker", LinkFreedom(mass=(1.0, 3.0), com_radius=0.5))
    assert b.inertia == (0.0, math.inf) and b.com_centre == 2.0 and b.about == "A3"
    assert b.counter_rotor == (0.0, 0.0)  # fixed at the spec's (none)
    # Mass and centre of mass fixed, no min_gyration: the inertia stays.
    b = resolve_link(mech, "crank", LinkFreedom(counter_rotor=(0.0, 1.0)))
    assert b.inertia == (1.1, 1.1) and b.mass == (2.1, 2.1)
    # ... unless min_gyration is given.
    b = resolve_link(mech, "crank", LinkFreedom(min_gyration=0.2))
    assert b.inertia == (0.0, math.inf) and b.gyration == 0.2
    # A zero radius pins the centre of mass to the joint; an inertia bound caps the mass.
    b = resolve_link(
        mech, "crank",
        LinkFreedom(mass=(1.0, 9.0), com_radius=0.0, com_about="A1", min_gyration=0.5,
                    inertia=(0.0, 1.0)),
    )  # fmt: skip
    assert b.com_fixed == 1.0 + 0j and b.com_radius is None
    assert b.mass == (1.0, 4.0)  # I ≤ 1 and I ≥ m·0.25


def _random_problem(rng: np.random.Generator) -> BalanceProblem:
    def pair(lo, hi):
        a, b = sorted(float(v) for v in rng.uniform(lo, hi, 2))
        return (a, a) if rng.random() < 0.2 else (a, b)

    def freedom(name):
        if rng.random() < 0.3:
            return None
        grounded = name != "coupler"
        joints = {"crank": "A0", "coupler": "A2", "rocker": "A2"}
        radius = float(rng.uniform(0, 2)) if rng.random() < 0.7 else None
        return LinkFreedom(
            mass=pair(0.1, 9.0) if rng.random() < 0.7 else None,
            com_radius=radius,
            com_about=joints[name] if radius is not None and rng.random() < 0.5 else None,
            min_gyration=float(rng.uniform(0, 0.1)) if rng.random() < 0.5 else None,
            inertia=pair(1.0, 5.0) if rng.random() < 0.3 else None,
            counter_rotor=pair(0.0, 3.0) if grounded and rng.random() < 0.6 else None,
        )

    links = {name: freedom(name) for name in ("crank", "coupler", "rocker")}
    links["crank"] = links["crank"] or LinkFreedom(counter_rotor=(0.0, 1.0))
    return BalanceProblem(
        force_balance=bool(rng.random() < 0.5),
        objective=Objective(
            shaking_moment=float(rng.uniform(0, 2)),
            driving_torque=float(rng.uniform(0, 1)),
            shaking_force=float(rng.uniform(0, 1)),
            added_mass=float(rng.uniform(0, 100)),
        ),
        links={name: f for name, f in links.items() if f is not None},
    )


@pytest.mark.parametrize("seed", range(15))
def test_the_balance_section_round_trips_exactly(seed):
    rng = np.random.default_rng(seed)
    design = Design(
        mechanism=random_linkage(rng),
        operation=Operation(speed=float(rng.uniform(1, 20))),
        balance=_random_problem(rng),
    )
    text = spec.dumps_design(design)
    again = spec.loads_design(text)
    assert again == design
    assert spec.dumps_design(again) == text


@pytest.mark.parametrize("name", ["pb1.toml", "pb2.toml"])
def test_the_examples_round_trip_exactly(name):
    design = spec.load_design(EXAMPLES / name)
    assert not design.mechanism.has_loads  # inertial balancing: the loads of Eq. 56 left out
    assert design.mechanism.lengths == PAPER_LENGTHS
    text = spec.dumps_design(design)
    assert spec.loads_design(text) == design


def test_the_problem_needs_the_operating_speed_and_a_balance_section():
    design = spec.loads_design(BASE)
    with pytest.raises(SpecError, match="operation.speed"):
        numeric_problem(replace(design, operation=None))
    with pytest.raises(SpecError, match="balance"):
        numeric_problem(replace(design, balance=None))


def test_a_crank_that_cannot_turn_is_bad_input():
    design = spec.loads_design(BASE)
    rocker_crank = replace(design.mechanism, lengths=CLASS_EXAMPLES["rocker-crank"])
    with pytest.raises(AssemblyError):
        numeric_problem(replace(design, mechanism=rocker_crank))


def _objective_by_newton_euler(data, linkage: FourBar) -> float:
    """The objective from the Newton–Euler cycle analysis (no loads), not the regressors.

    A four-bar's route "newton-euler" is the paper's free-body equations in closed form
    (:func:`balancer.mechanisms.fourbar.inverse.newton_euler`), independent of the general
    core's regressors.
    """
    w = data.weights
    s = cycle_analysis(linkage, data.speed, data.samples, route="newton-euler", loads=False)
    summary = s.summary
    return (
        w.shaking_moment * summary.shaking_moment.rms**2
        + w.driving_torque * summary.driving_torque.rms**2
        + w.shaking_force * summary.shaking_force.rms**2
        + w.added_mass * (linkage.total_mass - data.linkage.total_mass)
    )


@pytest.mark.parametrize("seed", range(8))
def test_the_objective_equals_the_newton_euler_route(seed):
    """Regressors (the general core's) against the paper's free-body equations, to 1e-9."""
    rng = np.random.default_rng(100 + seed)
    linkage = random_linkage(rng, loads=True, full_turn=True)  # loads must be left out
    problem = _random_problem(rng)
    design = Design(
        mechanism=linkage,
        operation=Operation(speed=float(rng.uniform(-20, 20)), samples=int(rng.integers(8, 200))),
        balance=problem,
    )
    data = numeric_problem(design)
    # The original, and a design with every parameter perturbed.
    x = data.x0 * rng.uniform(0.8, 1.2, data.size) + rng.uniform(0.0, 0.1, data.size)
    for k in (0, 4, 8):  # a realisable link: inertia about the centre of mass I ≥ 0
        x[k + 3] = (x[k + 1] ** 2 + x[k + 2] ** 2) / x[k] + rng.uniform(0.01, 1.0)
    other = data.linkage_of(x)
    for lk in (linkage, other):
        x = design_vector(mechanism_of(lk))
        expected = _objective_by_newton_euler(data, lk)
        scale = abs(expected) + data.weights.added_mass * lk.total_mass
        assert abs(data.objective(x) - expected) <= 1e-9 * scale
        # The factor R the optimisers use gives the same quadratic part, and the objective
        # through it (what the solvers' inner loops compare) the same figure.
        assert float(np.sum((data.factor @ x) ** 2)) == pytest.approx(data.quadratic(x), rel=1e-12)
        assert abs(data.reduced_objective(x) - expected) <= 1e-9 * scale


@pytest.mark.parametrize("seed", range(8))
def test_a_problem_under_new_bounds_equals_one_built_afresh(seed):
    """``with_problem`` (what it keeps, what it makes anew) against ``numeric_problem``.

    Random problems change bounds, free links, the objective's weights and whether force
    balance is imposed; every field, cached scale and figure of the derived problem must be
    those of the problem built from the spec with the new ``[balance]``.
    """
    rng = np.random.default_rng(300 + seed)
    linkage = random_linkage(rng, loads=False, full_turn=True)
    first, second = _random_problem(rng), _random_problem(rng)
    if seed % 2:  # the same objective: its reduction is kept, not rebuilt
        second = replace(second, objective=first.objective)
    operation = Operation(speed=float(rng.uniform(-20, 20)), samples=int(rng.integers(8, 200)))
    data = numeric_problem(Design(mechanism=linkage, operation=operation, balance=first))
    derived = data.with_problem(second)
    fresh = numeric_problem(Design(mechanism=linkage, operation=operation, balance=second))
    assert derived.problem == second
    assert derived.links == fresh.links
    assert derived.inert == fresh.inert
    np.testing.assert_array_equal(derived.rows, fresh.rows)
    np.testing.assert_array_equal(derived.factor, fresh.factor)
    assert (derived.force_balance is None) == (fresh.force_balance is None)
    if fresh.force_balance is not None:
        for a, b in zip(derived.force_balance, fresh.force_balance, strict=True):
            np.testing.assert_array_equal(a, b)
    for name in ("objective_scale", "objective_reference", "inertial_scale",
                 "original_objective", "original_mass"):
        assert getattr(derived, name) == getattr(fresh, name), name
    np.testing.assert_array_equal(derived.scales, fresh.scales)
    np.testing.assert_array_equal(derived.offset, fresh.offset)
    np.testing.assert_array_equal(derived.acceleration_factor, fresh.acceleration_factor)
    x = data.x0 * rng.uniform(0.8, 1.2, data.size)
    assert derived.objective(x) == fresh.objective(x)
    np.testing.assert_array_equal(derived.force_balance_rows(x), fresh.force_balance_rows(x))
    assert derived.violations(x) == fresh.violations(x)


def test_a_problem_under_new_bounds_is_checked():
    """A contradictory problem is refused as the spec's would be, naming the key."""
    data = numeric_problem(spec.load_design(EXAMPLES / "pb1.toml"))
    with pytest.raises(SpecError, match="balance.objective"):
        data.with_problem(replace(data.problem, objective=Objective(shaking_moment=0.0)))
    with pytest.raises(SpecError, match="balance.bogus"):
        data.with_problem(data.problem.with_link("bogus", LinkFreedom(mass=(1.0, 2.0))))


def test_force_balance_rows_against_their_definition():
    """Each row's residual over the sum of its links' combined terms (the definition, a link
    at a time), on designs whose links' terms cancel within a link and between links."""
    rng = np.random.default_rng(7)
    data = numeric_problem(spec.load_design(EXAMPLES / "pb2.toml"))
    a, b = data.force_balance
    eps = np.finfo(float).eps
    for _ in range(20):
        x = data.x0 * rng.uniform(0.5, 1.5, data.size)
        x[data.links[0].start + 1 : data.links[0].start + 3] = 0.0  # a link with no terms
        expected = []
        for i in range(a.shape[0]):
            combined = abs(b[i]) + sum(abs(math.fsum(a[i, k] * x[k] for k in range(
                l.start, l.start + 4))) for l in data.links)
            raw = math.fsum(abs(a[i, k] * x[k]) for k in range(data.size)) + abs(b[i])
            floor = 1e-6 * math.fsum(abs(a[i, k]) * data.scales[k] for k in range(data.size))
            size = max(combined, 64 * eps / 1e-12 * raw, floor)
            expected.append(abs(math.fsum(a[i] * x) - b[i]) / size)
        # A·x rounds by at most P·ε of the raw terms, which are at most 1e-12/(64·ε) of the
        # size: that is the absolute rounding of a ratio.
        np.testing.assert_allclose(data.force_balance_rows(x), expected, rtol=1e-12,
                                   atol=data.size * eps * 1e-12 / (64 * eps))


@pytest.mark.parametrize("branch", ["+", "-"])
def test_the_objective_of_a_change_point_linkage_matches_the_cycle_analysis(branch):
    """Parallelogram and anti-parallelogram: samples at the change points θ1 = 0, π."""
    links = paper_links(loads=False)
    linkage = FourBar(lengths=CLASS_EXAMPLES["change-point"], branch=branch, **links)
    design = Design(
        mechanism=linkage,
        operation=Operation(speed=7.0, samples=36),  # samples at θ1 = 0 and π: change points
        balance=BalanceProblem(links={"crank": LinkFreedom(counter_rotor=(0.0, 1.0))}),
    )
    data = numeric_problem(design)
    assert np.isfinite(data.regressors.shaking_moment).all()
    expected = _objective_by_newton_euler(data, linkage)
    assert data.objective(data.x0) == pytest.approx(expected, rel=1e-8)


def test_settling_the_inert_entries_changes_nothing_measured():
    design = spec.load_design(EXAMPLES / "pb2.toml")
    data = numeric_problem(design)
    # At constant crank speed (α1 = 0) the crank's inertia and counter-rotor do nothing.
    assert [i for i, flag in enumerate(data.inert) if flag] == [3, 12]
    x = data.x0.copy()
    x[3], x[12] = 50.0, 7.0
    settled = data.settle(x)
    assert data.objective(settled) == pytest.approx(data.objective(x), rel=1e-13)
    # They are chosen for a crank whose speed changes: no setting within the bounds gives a
    # smaller mean-square shaking moment per unit crank acceleration (from the sampled
    # regressors, not the factor that settling uses).
    a = cycle_regressors(data.mechanism, data.states.positions[0], 0.0, 1.0).shaking_moment

    def accel(z):
        return float(np.sum((a @ z) ** 2))

    rng = np.random.default_rng(0)
    m, q = x[0], (x[1] ** 2 + x[2] ** 2) / x[0]
    lo = max(data.links[0].inertia[0], m * data.links[0].gyration ** 2) + q
    for _ in range(200):
        trial = settled.copy()
        trial[3] = lo + rng.uniform(0, 5)
        trial[12] = rng.uniform(*data.links[0].counter_rotor)
        assert accel(settled) <= accel(trial) * (1 + 1e-12)
    # The counter-rotor does it; the crank keeps its inertia about the centre of mass.
    assert settled[3] - q == pytest.approx(design.mechanism.crank.inertia, rel=1e-6)
    assert 0 < settled[12] < 20


def test_violations_name_what_is_broken():
    data = numeric_problem(spec.load_design(EXAMPLES / "pb1.toml"))
    x = data.x0.copy()
    broken = data.violations(x)
    assert any("force balance" in v for v in broken)  # the paper's design is not balanced
    x[0] = 9.0  # crank mass above 8.4
    assert any("balance.crank.mass" in v for v in data.violations(x))
    x[13] = 25.0
    assert any("balance.rocker.counter_rotor" in v for v in data.violations(x))


@pytest.mark.parametrize("name", ["pb1", "watt_sixbar", "quick_return", "stephenson_sixbar"])
def test_regressors_at_two_rates_in_one_pass_are_each_alone(name):
    """The operating speed's regressors and unit crank acceleration's, computed together
    (``numeric_problem``), are each what ``cycle_regressors`` gives alone, bit for bit; the
    four-bar's change points (limits) included where sampled. ``numeric_problem`` leaves out
    the driving torque at rest (NaN: only the shaking moment settles the counter-rotors);
    asked for, it is the one computed alone too."""
    design = spec.load_design(EXAMPLES / f"{name}.toml")
    data = numeric_problem(design)
    alone = [cycle_regressors(data.mechanism, data.states.positions[0], data.speed),
             cycle_regressors(data.mechanism, data.states.positions[0], 0.0, 1.0)]
    full = cycle_regressors_at(data.mechanism, data.states.positions[0],
                               [(data.speed, 0.0), (0.0, 1.0)])
    for together, single in zip([data.regressors, data.unit_acceleration], alone, strict=True):
        for key in ("shaking_force", "shaking_moment", "rocking_couple"):
            np.testing.assert_array_equal(getattr(together, key), getattr(single, key))
    np.testing.assert_array_equal(data.regressors.driving_torque, alone[0].driving_torque)
    assert np.isnan(data.unit_acceleration.driving_torque).all()
    for together, single in zip(full, alone, strict=True):
        for key in ("shaking_force", "shaking_moment", "driving_torque", "rocking_couple"):
            np.testing.assert_array_equal(getattr(together, key), getattr(single, key))


@pytest.mark.parametrize("name", ["pb1", "watt_sixbar", "stephenson_sixbar", "quick_return"])
def test_a_mechanisms_pose_is_its_motions(name):
    mech = mechanism_of(spec.load_design(EXAMPLES / f"{name}.toml").mechanism)
    theta = np.linspace(0.1, 6.0, 37)
    pose, motion = mech.pose(theta), mech.motion(theta, 3.0, 2.0).pose
    for a, b in zip([*pose.cos, *pose.sin], [*motion.cos, *motion.sin], strict=True):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    for a, b in zip(pose.origins, motion.origins, strict=True):
        np.testing.assert_array_equal(a.complex(), b.complex())


#: Two formulations of the same maps: the groups' joint forces solved state by state, and
#: momentum and virtual power over the links' inertial columns. Each rounds at ε times the
#: terms it sums, amplified by the joint solves' conditioning (a few hundred ε seen on the
#: Stephenson six-bar's numeric triad); 1e-10 of each figure's largest entry leaves room.
FORMULATIONS = 1e-10


@pytest.mark.parametrize("name", ["pb1", "watt_sixbar", "stephenson_sixbar", "quick_return",
                                  "jansen_leg", "two_plane_drive", "engine"])
def test_shaking_regressors_from_momentum_are_the_joint_forces(name):
    """``shaking_regressors`` (no joint forces) against ``regressors`` (the groups' solves):
    shaking force and moment, driving torque, rocking couple, at turning and resting cranks
    (virtual power then takes the rates of a unit crank rate), with gravity."""
    mech = mechanism_of(spec.load_design(EXAMPLES / f"{name}.toml").mechanism)
    theta = np.linspace(0.05, 2 * math.pi - 0.05, 60)
    omega = np.where(np.arange(60) % 3 == 0, 0.0, 35.0)  # (a third at rest,
    omega[1] = 1e-320  # one barely turning: a subnormal rate, the rates of a unit one)
    alpha = np.where(np.arange(60) % 2 == 0, 4.0, -120.0)
    mo = mech.motion(theta, omega, alpha)
    joints = mech.regressors(mo, (0.3, -9.81))
    momentum = shaking_regressors(mech.structure, mo, (0.3, -9.81))
    pairs = [(momentum.shaking_force.x, joints.shaking_force.x),
             (momentum.shaking_force.y, joints.shaking_force.y),
             (momentum.shaking_moment, joints.shaking_moment),
             (momentum.driving_torque, joints.driving_torque),
             (momentum.rocking_couple.x, joints.rocking_couple.x),
             (momentum.rocking_couple.y, joints.rocking_couple.y)]
    for got, want in pairs:
        want = np.asarray(want) * np.ones_like(got)
        scale = np.max(np.abs(want))
        assert np.max(np.abs(got - want)) <= FORMULATIONS * max(scale, 1e-300)


def test_shaking_regressors_where_the_linkage_does_not_assemble_are_nan_as_the_joints():
    """A rocking crank (PB1 with a 5 m frame: it turns within ±1.47 rad): outside its range
    every column is NaN by both routes, inside both are finite and agree."""
    import tomllib

    from balancer.sweeps import with_values

    data = tomllib.loads((EXAMPLES / "pb1.toml").read_text())
    design = spec.design_from_dict(with_values(data, {"mechanism.lengths.frame": 5.0}))
    mech = mechanism_of(design.mechanism)
    (lo, hi), = mech.assembly_range().intervals
    theta = np.array([lo + 0.1, 0.0, hi - 0.1, hi + 0.3, math.pi])
    mo = mech.motion(theta, 12.0, -3.0)
    momentum = shaking_regressors(mech.structure, mo, (0.0, -9.81))
    joints = mech.regressors(mo, (0, -9.81))
    for got, want in ((momentum.shaking_force.x, joints.shaking_force.x),
                      (momentum.shaking_moment, joints.shaking_moment),
                      (momentum.driving_torque, joints.driving_torque)):
        want = np.asarray(want) * np.ones_like(got)
        np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
        assert np.isnan(got[3:]).all() and np.isfinite(got[:3]).all()
        assert np.max(np.abs(got[:3] - want[:3])) <= FORMULATIONS * np.max(np.abs(want[:3]))
