"""The one quantity table (balancer/quantities.py): complete, and its units right by physics."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from balancer.api import analyze
from balancer.cycle import panel_keys
from balancer.model.balance import Objective
from balancer.quantities import PANELS, QUANTITIES, squared_parts, unit_of
from balancer.spec import load_design

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _metre_power(unit: str) -> int:
    """The power of the metre in an SI unit as the table writes them (``N``, ``N·m``, ``kg``)."""
    powers = {"N": 1, "m": 1, "kg": 0}  # N = kg·m/s²
    return sum(powers[factor] for factor in unit.split("·"))


@pytest.mark.parametrize("example", ["meijaard2020.toml", "engine.toml"])
def test_every_figure_a_report_gives_and_every_panel_it_draws_is_in_the_table(example):
    analysis = analyze(load_design(EXAMPLES / example))
    assert set(analysis.summary.as_dict()) <= set(QUANTITIES)
    assert set(panel_keys(analysis)) <= set(PANELS)
    for panel in panel_keys(analysis):
        assert QUANTITIES[PANELS[panel].key].panel == panel


def test_every_objective_term_is_in_the_table():
    assert {f.name for f in dataclasses.fields(Objective)} <= set(QUANTITIES)
    weights = {f.name: 1.0 for f in dataclasses.fields(Objective)}
    for term in Objective(**weights).terms:
        assert term.unit == unit_of(term.name)


def test_each_figures_unit_by_dimensional_analysis():
    """Lengths scaled by λ (the links' centres too, their inertias by λ²), masses and speed
    kept: a force scales by λ, a moment by λ² (N = kg·m/s²), the links' applied loads too.
    The table's unit of each figure the analysis gives must say the same power of the metre."""
    design = load_design(EXAMPLES / "meijaard2020.toml")
    lam = 3.0
    four = design.mechanism

    def scaled_link(name: str):
        link = getattr(four, name)
        return dataclasses.replace(link, e=lam * link.e, f=lam * link.f,
                                   inertia=lam**2 * link.inertia,
                                   force=(lam * link.force[0], lam * link.force[1]),
                                   moment=lam**2 * link.moment)

    scaled = dataclasses.replace(four, lengths=tuple(lam * x for x in four.lengths),
                                 **{name: scaled_link(name)
                                    for name in ("crank", "coupler", "rocker")})
    before = analyze(design).summary.as_dict()
    after = analyze(dataclasses.replace(design, mechanism=scaled)).summary.as_dict()
    for key, figures in before.items():
        power = _metre_power(unit_of(key))
        for stat, value in figures.items():
            assert math.isclose(after[key][stat], lam**power * value, rel_tol=1e-9,
                                abs_tol=1e-9 * lam**power * abs(value) + 1e-300), (key, stat)


def test_each_mean_square_term_squares_the_parts_of_its_load():
    """The table's squares against the loads themselves: a complex load's two parts add to its
    squared magnitude, its x and y terms to the whole, a real load is itself."""
    analysis = analyze(load_design(EXAMPLES / "engine.toml"))
    r = analysis.reactions

    def mean_square(key):
        return sum(float(np.mean(p**2)) for p in squared_parts(key, lambda k: getattr(r, k)))

    for key in ("shaking_force", "rocking_couple"):
        assert math.isclose(mean_square(key), float(np.mean(np.abs(getattr(r, key)) ** 2)),
                            rel_tol=1e-12)
    assert math.isclose(mean_square("shaking_force_x") + mean_square("shaking_force_y"),
                        mean_square("shaking_force"), rel_tol=1e-12)
    for key in ("shaking_moment", "driving_torque"):
        assert math.isclose(mean_square(key), float(np.mean(getattr(r, key) ** 2)),
                            rel_tol=1e-12)
    weights = {f.name: 1.0 for f in dataclasses.fields(Objective)}
    squared = {t.name for t in Objective(**weights).terms if QUANTITIES[t.name].squares}
    assert squared == {"shaking_moment", "driving_torque", "shaking_force", "rocking_couple",
                       "main_bearing_load"}
    # an engine's main bearings: their loads one after another, each part squared
    four = analyze(load_design(EXAMPLES / "inline_four.toml"))
    loads = np.concatenate([s.force for s in four.supports])
    parts = squared_parts("main_bearing_load", four.load)
    assert math.isclose(sum(float(np.mean(p**2)) for p in parts),
                        float(np.mean(np.abs(loads) ** 2)), rel_tol=1e-12)
