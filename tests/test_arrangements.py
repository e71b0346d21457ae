"""Crank arrangements and firing orders searched (balancer/arrangements.py, ``balancer search``).

- The classic answers come out on top by themselves: the flat-plane four (1-3-4-2 among the
  first), the in-line six's 1-5-3-6-2-4, the cross-plane V8 (nothing free that counterweights
  cannot take), the in-line five's 1-2-4-5-3.
- Each arrangement's figures are the cycle analysis's of the engine built with its phases (the
  order table's whirls, from the inverse dynamics), and its firing order fires evenly by the
  engine's own firing angles.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer.arrangements import search
from balancer.cli import main
from balancer.cycle import cycle_analysis
from balancer.spec import load_design

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def inline(n: int):
    """An in-line ``n`` of the shipped three's cylinders, centred on the crank, no crank masses."""
    design = load_design(EXAMPLES / "inline_three.toml")
    engine = design.mechanism
    first = engine.cylinders[0]
    pitch = engine.cylinders[1].z - first.z
    cylinders = tuple(replace(first, z=(k - (n - 1) / 2) * pitch, phase_deg=0.0)
                      for k in range(n))
    return replace(engine, cylinders=cylinders, firing_order=None, gas=None, balance_shafts=(),
                   crankshaft=replace(engine.crankshaft, masses=())), design.operation.speed


def best(found):
    return [a for a in found.arrangements if a.rank == 1]


def test_the_flat_plane_four_is_first():
    design = load_design(EXAMPLES / "inline_four.toml")
    found = search(design.mechanism, design.operation.speed)
    top = best(found)
    assert {a.phases for a in top} == {(0.0, 180.0, 180.0, 0.0)}
    assert (1, 3, 4, 2) in {a.firing_order for a in top}
    assert all(a.free["couple_1_backward"] == pytest.approx(0.0, abs=1e-9 * found.scale)
               for a in top)


def test_the_inline_sixs_1_5_3_6_2_4_is_first():
    engine, speed = inline(6)
    top = best(search(engine, speed))
    assert ((0.0, 240.0, 120.0, 120.0, 240.0, 0.0), (1, 5, 3, 6, 2, 4)) in {
        (a.phases, a.firing_order) for a in top}
    assert all(a.same_half == 0 for a in top)  # it alternates between the crank's halves


def test_the_cross_plane_v8_is_first_and_the_flat_plane_behind():
    design = load_design(EXAMPLES / "v8.toml")
    found = search(design.mechanism, design.operation.speed)
    zero = 1e-9 * found.scale  # N, and N·m over an arm of a metre (the crank's 0.36 m)

    def nothing_free(a) -> bool:
        return max(a.free.values()) <= zero

    top = best(found)
    assert top and all(nothing_free(a) for a in top)
    cross = {tuple(sorted(set(a.phases))) for a in top}
    assert cross == {(45.0, 135.0, 225.0, 315.0)}  # four pins 90° apart
    assert (1, 8, 4, 3, 6, 5, 7, 2) in {a.firing_order for a in found.arrangements
                                        if nothing_free(a)}
    flat = [a for a in found.arrangements if len(set(a.phases)) == 2]
    assert flat and all(a.free["force_2"] > 0.1 * found.scale for a in flat)


def test_the_inline_fives_known_compromise_is_first():
    engine, speed = inline(5)
    top = best(search(engine, speed))
    assert (1, 2, 4, 5, 3) in {a.firing_order for a in top}


@pytest.mark.parametrize("which", ["four", "v8", "five"])
def test_each_arrangements_figures_are_its_engines_cycle_analysis(which):
    if which == "five":
        engine, speed = inline(5)
    else:  # a shipped engine's cylinders alone
        design = load_design(EXAMPLES / {"four": "inline_four.toml", "v8": "v8.toml"}[which])
        engine = replace(design.mechanism, crankshaft=replace(design.mechanism.crankshaft,
                                                              masses=()), balance_shafts=(),
                         gas=None)
        speed = design.operation.speed
    found = search(engine, speed, top=6)
    n = len(engine.cylinders)
    for a in found.arrangements:
        built = replace(engine, cylinders=tuple(
            replace(c, phase_deg=p) for c, p in zip(engine.cylinders, a.phases, strict=True)),
            firing_order=a.firing_order)
        firing = sorted((f - built.firing_angles()[0]) % (4 * math.pi)
                        for f in built.firing_angles())
        np.testing.assert_allclose(np.diff(firing), 4 * math.pi / n, atol=1e-9)
        analysis = cycle_analysis(built, speed, 360, loads=False)
        orders = {o.order: o for o in analysis.orders}
        scale = found.scale
        arm = max(abs(c.z) for c in engine.cylinders) * 2 or 1.0
        assert orders[1].shaking_force.backward == pytest.approx(
            a.free["force_1_backward"], abs=1e-9 * scale)
        assert orders[1].shaking_force.forward == pytest.approx(
            a.counterweights["force_1_forward"], abs=1e-9 * scale)
        assert orders[1].rocking_couple.backward == pytest.approx(
            a.free["couple_1_backward"], abs=1e-9 * scale * arm)
        assert orders[1].rocking_couple.forward == pytest.approx(
            a.counterweights["couple_1_forward"], abs=1e-9 * scale * arm)
        force_2 = orders[2].shaking_force.forward + orders[2].shaking_force.backward
        couple_2 = orders[2].rocking_couple.forward + orders[2].rocking_couple.backward
        assert force_2 == pytest.approx(a.free["force_2"], abs=1e-9 * scale)
        assert couple_2 == pytest.approx(a.free["couple_2"], abs=1e-9 * scale * arm)


def test_the_command_prints_and_refuses(capsys):
    assert main(["search", str(EXAMPLES / "inline_four.toml"), "--top", "3", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert len(doc["arrangements"]) == 3 and doc["arrangements"][0]["rank"] == 1
    assert main(["search", str(EXAMPLES / "inline_four.toml")]) == 0
    assert "1-3-4-2" in capsys.readouterr().out
    assert main(["search", str(EXAMPLES / "pb1.toml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "mechanism.type" in err[0]


@pytest.mark.slow
def test_search_balance_sizes_each_cranks_counterweights_as_the_spec_asks(capsys):
    """--balance: the spec's own crank balances as optimize balances it; its mirror image (the
    pins and webs turned with their cylinders) to the solvers' accuracy; no [balance]: refused."""
    from balancer.api.arrangements import search as search_design
    from balancer.balance.optimizer import optimize

    design = load_design(EXAMPLES / "inline_three_to_balance.toml")
    found = search_design(design, top=2, balance=True)
    own = optimize(design, "convex").objective
    for a in found.arrangements:
        assert a.balanced is not None and a.balanced.optimal
        assert a.balanced.objective == pytest.approx(own, rel=1e-7)
    spec_crank = [a for a in found.arrangements
                  if a.phases == tuple(c.phase_deg for c in design.mechanism.cylinders)]
    assert spec_crank and spec_crank[0].balanced.objective == pytest.approx(own, rel=1e-9)
    assert main(["search", str(EXAMPLES / "v8.toml"), "--balance"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--balance" in err[0]


def test_an_engine_of_geared_crankshafts_is_not_searched() -> None:
    """The search arranges one crankshaft's pins: a twin-crank spec is refused by its key."""
    assert main(["search", str(EXAMPLES / "square_four.toml")]) == 2
