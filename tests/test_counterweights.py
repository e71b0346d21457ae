"""Counterweights: the original link plus the reported body is the balanced link.

The check composes the two bodies by another route than the one that found the counterweight:
the composite's centre of mass as the mass-weighted mean of the two centres and its inertia by
the parallel-axis theorem about that centre (the module subtracts first moments and inertias
about the link frame's origin instead).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from balancer.balance.counterweights import STEEL_DENSITY, counterweight
from balancer.balance.optimizer import optimize
from balancer.report import optimization_json
from balancer.spec import load_design

EPS = 2.0**-52


@dataclass(frozen=True)
class Body:
    mass: float
    e: float
    f: float
    inertia: float


def compose(a: Body, b: Body) -> tuple[Body, dict[str, float]]:
    """``a`` and ``b`` as one body, and the magnitude of the terms each result sums."""
    m = a.mass + b.mass
    sa, sb = complex(a.e, a.f), complex(b.e, b.f)
    s = (a.mass * sa + b.mass * sb) / m
    parts = [a.inertia, a.mass * abs(sa - s) ** 2, b.inertia, b.mass * abs(sb - s) ** 2]
    sizes = {"mass": abs(a.mass) + abs(b.mass),
             "moment": abs(a.mass * sa) + abs(b.mass * sb),
             "inertia": sum(abs(p) for p in parts)
             + (abs(a.mass) * abs(sa) ** 2 + abs(b.mass) * abs(sb) ** 2)}
    return Body(m, s.real, s.imag, math.fsum(parts)), sizes


def assert_reproduces(original, balanced, weight) -> None:
    """Original + counterweight = balanced: mass, first moment and inertia about the centre.

    Each compared quantity is a short sum whose rounding is a few ε of its terms' magnitudes
    (both routes): 16·ε of those, and a floor of subnormals (a product of two lengths can
    underflow).
    """
    added = Body(weight.mass, weight.e, weight.f, weight.inertia)
    whole, size = compose(Body(original.mass, original.e, original.f, original.inertia), added)
    tol = 16 * EPS
    floor = 1e-300
    assert abs(whole.mass - balanced.mass) <= tol * size["mass"] + floor
    s_whole = whole.mass * complex(whole.e, whole.f)
    s_bal = balanced.mass * complex(balanced.e, balanced.f)
    assert abs(s_whole - s_bal) <= tol * size["moment"] + floor
    assert abs(whole.inertia - balanced.inertia) <= tol * size["inertia"] * (
        1 + size["moment"] ** 2 / max(size["mass"], 1e-300) / max(size["inertia"], 1e-300)
    ) + floor


_MASS = st.floats(0.05, 50.0)
_LEN = st.floats(-3.0, 3.0)
_INERTIA = st.floats(0.0, 20.0)


@settings(max_examples=300, deadline=None)
@given(m0=_MASS, e0=_LEN, f0=_LEN, i0=_INERTIA, m1=_MASS, e1=_LEN, f1=_LEN, i1=_INERTIA)
def test_any_change_of_a_link_is_the_reported_body(m0, e0, f0, i0, m1, e1, f1, i1):
    original, balanced = Body(m0, e0, f0, i0), Body(m1, e1, f1, i1)
    w = counterweight("link", original, balanced)
    if w.exact:
        assert_reproduces(original, balanced, w)
    assert w.kind in ("none", "add", "remove", "rebuild")
    if w.kind == "add":
        assert w.mass > 0 and w.inertia >= 0
    if w.kind == "remove":
        assert w.mass < 0 and w.inertia <= 1e-9 * (i0 + i1 + m0 * (e0**2 + f0**2) + 1)
    if w.disc_radius is not None:
        # A solid steel disc: I = m·R²/2 about its axis, m = ρ·π·R²·t.
        assert w.inertia == pytest.approx(w.mass * w.disc_radius**2 / 2, rel=8 * EPS)
        volume = math.pi * w.disc_radius**2 * w.disc_thickness
        assert w.mass == pytest.approx(STEEL_DENSITY * volume, rel=8 * EPS)


def test_an_added_body_is_found_as_it_was_added():
    original = Body(2.0, 0.4, 0.0, 0.5)
    body = Body(0.7, -0.25, 0.1, 0.003)
    balanced, _ = compose(original, body)
    w = counterweight("crank", original, balanced)
    assert w.kind == "add" and w.exact
    assert (w.mass, w.e, w.f, w.inertia) == pytest.approx(
        (body.mass, body.e, body.f, body.inertia), rel=1e-13, abs=1e-15)
    same = counterweight("crank", original, original)
    assert same.kind == "none" and same.mass == 0


def test_a_moment_moved_with_the_mass_kept_is_a_rebuild():
    w = counterweight("rocker", Body(2.0, 0.4, 0.0, 0.5), Body(2.0, 0.6, 0.0, 0.5))
    assert w.kind == "rebuild" and not w.exact


@pytest.mark.parametrize("example", ["pb1", "pb2", "engine", "watt_sixbar"])
def test_optimized_examples_report_counterweights_that_rebuild_the_balanced_links(example):
    design = load_design(f"examples/{example}.toml")
    result = optimize(design, "convex")
    assert result.success
    weights = result.counterweights
    assert set(weights) == set(result.linkage.link_names)
    for name, w in weights.items():
        # A free link whose mass the optimum keeps but whose centre of mass moves (PB1's crank
        # and rocker) is no body added: it is to be rebuilt.
        assert w.exact or w.kind == "rebuild", name
        if w.exact:
            assert_reproduces(result.original.link(name), result.linkage.link(name), w)
    assert result.added_mass == pytest.approx(
        result.linkage.total_mass - result.original.total_mass, rel=1e-12, abs=1e-12)
    doc = optimization_json(result, result.before, result.after)
    assert set(doc["counterweights"]) == set(weights)
    assert {"mass", "e", "f", "inertia"} <= set(doc["counterweights"][name])
    assert doc["added_mass"] == result.added_mass
