"""[balance.<link>] com_on_line: the centre of mass stays on the link's line (f = 0).

The optimum is checked against a CVXPY program written here from the spec's bounds with the
extra equation m·f = 0 (the product instead drops m·f from its variables), by both backends.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers import least_rms_moment_by_cvxpy

from balancer.balance.optimizer import optimize
from balancer.balance.problem import numeric_problem
from balancer.errors import SpecError
from balancer.spec import dumps_design, loads_design

PB1 = (Path(__file__).resolve().parents[2] / "examples" / "pb1.toml").read_text()
#: PB1 with the coupler's centre of mass on its line (σ2 = 0): then Eq. 57's imaginary parts
#: let crank and rocker have theirs on their lines too (with σ2 = 0.4 they cannot).
ON_AXIS = PB1.replace("com = { s = 1.45, sigma = 0.4 }", "com = { s = 1.45, sigma = 0.0 }")
ROCKER = '''[balance.rocker]
mass = [2.2, 8.8]                 # kg: 1x–4x
com_radius = 2.0                  # m: l3 around A3
com_about = "A3"'''


def _on_line(text: str = ON_AXIS) -> str:
    assert ROCKER in text
    return text.replace(ROCKER, ROCKER + "\ncom_on_line = true", 1)


def _least_by_cvxpy(design) -> float:
    """The oracle of :func:`helpers.least_rms_moment_by_cvxpy`, with the rocker's m·f = 0."""
    rocker = next(b for b in numeric_problem(design).links if b.name == "rocker")
    return least_rms_moment_by_cvxpy(design, lambda x, data: [x[rocker.start + 2] == 0])


@pytest.mark.parametrize("backend", ["convex", "nlp"])
def test_a_centre_of_mass_kept_on_the_line_is_optimal_and_on_it(backend):
    design = loads_design(_on_line())
    result = optimize(design, backend)
    assert result.success and result.optimal, result.message
    rocker = result.linkage.link("rocker")
    assert rocker.f == 0.0  # exactly on the line
    assert abs(complex(rocker.e, rocker.f) - 2.0) <= 2.0  # within com_radius of A3 (e = 2)
    assert result.rms == pytest.approx(_least_by_cvxpy(design), rel=1e-6)
    # It costs: the free rocker's optimum is no higher.
    free = optimize(loads_design(ON_AXIS), "convex")
    assert result.rms >= free.rms * (1 - 1e-9)


def test_a_line_that_force_balance_forbids_is_named():
    """PB1's coupler has its centre of mass off its line, so Eq. 57 asks the rocker's to be
    off its line too: infeasible, and the message says that com_on_line is why."""
    from balancer.balance.result import InfeasibleError

    with pytest.raises(InfeasibleError) as info:
        optimize(loads_design(_on_line(PB1)), "convex")
    assert "balance.rocker.com_on_line" in str(info.value)


def test_com_on_line_round_trips_and_refuses_what_contradicts_it():
    design = loads_design(_on_line())
    assert loads_design(dumps_design(design)).balance == design.balance
    with pytest.raises(SpecError) as info:
        loads_design(_on_line().replace("com_on_line = true", "com_on_line = 1"))
    assert info.value.key == "balance.rocker.com_on_line"
    without_radius = _on_line().replace("com_radius = 2.0                  # m: l3 around A3\n"
                                        "com_about = \"A3\"\n", "")
    with pytest.raises(SpecError) as info:
        loads_design(without_radius)
    assert info.value.key == "balance.rocker.com_on_line"


@pytest.mark.parametrize(("line", "wide", "key"), [
    ("mass = [2.1, 8.4]", "mass = [2.1, 1e308]", "balance.crank.mass"),
    ("com_radius = 1.0", "com_radius = 1.79769e308", "balance.crank.com_radius"),
    ("counter_rotor = [0.0, 20.0]", "counter_rotor = [0.0, 1e15]", "balance.crank.counter_rotor"),
])
def test_a_bound_wider_than_the_optimiser_can_hold_is_refused_by_name(line, wide, key):
    # Linkage fuzz campaign, seed 111, case 1768: a com_radius of 1.8e308 m reached CVXPY as
    # infinity (an internal error); on PB1 a bound 1e12 times the link's scale lost the proof
    # of optimality and 1e15 failed the solve. Beyond BOUND_RANGE (1e9) times the link's mass,
    # length or inertia scale a bound is bad input, named; well within it PB1 still solves.
    from balancer.balance.bounds import BOUND_RANGE

    crank = PB1.index("[balance.crank]")
    assert line in PB1[crank:]
    with pytest.raises(SpecError) as info:
        loads_design(PB1[:crank] + PB1[crank:].replace(line, wide, 1))
    assert info.value.key == key and "times the link's" in str(info.value)
    assert BOUND_RANGE == 1e9
    within = PB1[:crank] + PB1[crank:].replace(line, wide.replace("1e308", "1e6").replace(
        "1.79769e308", "1e6").replace("1e15", "1e6"), 1)
    assert optimize(loads_design(within), "convex").success
