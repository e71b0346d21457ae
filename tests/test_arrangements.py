"""Crank arrangements and firing orders searched (balancer/arrangements.py, ``balancer search``).

- The classic answers come out on top by themselves: the flat-plane four (1-3-4-2 among the
  first), the in-line six's 1-5-3-6-2-4, the cross-plane V8 (nothing free that counterweights
  cannot take), the in-line five's 1-2-4-5-3.
- Each arrangement's figures are the cycle analysis's of the engine built with its phases (the
  order table's whirls, from the inverse dynamics), and its firing order fires evenly by the
  engine's own firing angles.
- The driving torque's orders are the built engine's (its cycle analysis with its gas), its
  energy swing the flywheel page's (:class:`balancer.speed_fluctuation.CrankEnergy`: the
  inverse dynamics at four crank states), even and uneven.
- With ``step`` (uneven firing): every crank on the grid and every firing that fits is there
  once (counted by brute force over every order, from any cylinder), by an order the engine
  fires it with, cylinder 1 first wherever one such order is; the even ones among them keep
  their figures and the flat-plane four stays first, the even firing's energy swing below
  every uneven one's of the same crank.
"""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer.arrangements import search
from balancer.cli import main
from balancer.cycle import cycle_analysis
from balancer.errors import SpecError
from balancer.mechanisms import mechanism_of
from balancer.spec import load_design
from balancer.speed_fluctuation import CrankEnergy

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


def torque_figures(built, speed: float, samples: int) -> tuple[dict[float, float], float]:
    """The built engine's driving torque orders up to 12 and its energy swing, by two routes.

    The orders from its cycle analysis (loads included: its gas) over the working cycle; the
    swing ``ΔE`` from the inverse dynamics at four crank states (the flywheel's
    :class:`CrankEnergy`: the applied loads' work integrated, the inertia's exactly), on the
    grid four times finer than the samples as the search evaluates it.
    """
    analysis = cycle_analysis(built, speed, samples)
    cycle = 720 if built.strokes == 4 else 360
    torque = np.tile(np.asarray(analysis.reactions.driving_torque, float),
                     cycle // (360 * analysis.revolutions))
    c = np.fft.rfft(torque) / torque.size
    orders = {h * 360 / cycle: 2 * abs(c[h]) for h in range(1, 12 * cycle // 360 + 1)}
    theta = np.arange(torque.size) * math.radians(cycle) / torque.size
    energy = CrankEnergy.of(mechanism_of(built), theta, math.radians(cycle))
    j = energy.inertia_on(4)
    swing = float(np.ptp(energy.work(4) - 0.5 * speed**2 * (j - j[0])))
    return orders, swing


@pytest.mark.parametrize("which", [  # (the fours' gas over 720 samples: the full suite's)
    pytest.param("four", marks=pytest.mark.slow), pytest.param("four uneven",
                                                               marks=pytest.mark.slow),
    "v8", "three uneven"])
def test_each_arrangements_torque_is_its_engines(which):
    """Each candidate's torque orders and energy swing are those of the engine built with its
    crank and firing order (its gas, where the spec has one), and its firing intervals the
    engine's own firing angles'. Tolerances: the orders to 1e-9 of the torque's scale (the
    same samples, summed another way); the swing to 1e-8 (the inertial torque integrated as a
    trigonometric interpolant here, exactly there: their difference is its aliasing)."""
    name = {"four": "inline_four", "four uneven": "inline_four", "v8": "v8",
            "three uneven": "inline_three"}[which]
    design = load_design(EXAMPLES / f"{name}.toml")
    engine = replace(design.mechanism, crankshaft=replace(design.mechanism.crankshaft,
                                                          masses=()), balance_shafts=())
    speed, samples = design.operation.speed, design.operation.samples
    step = 90.0 if which == "four uneven" else 60.0 if which == "three uneven" else None
    found = search(engine, speed, top=5, step=step, samples=samples)
    for a in found.arrangements:
        built = replace(engine, cylinders=tuple(
            replace(c, phase_deg=p) for c, p in zip(engine.cylinders, a.phases, strict=True)),
            firing_order=a.firing_order)
        firing = [math.degrees(built.firing_angles()[k - 1]) for k in a.firing_order]
        cycle = 720 if engine.strokes == 4 else 360
        np.testing.assert_allclose(a.intervals, np.diff([*firing, firing[0] + cycle]),
                                   atol=1e-9)
        orders, swing = torque_figures(built, speed, samples)
        for order, amplitude in a.torque:
            assert amplitude == pytest.approx(orders[order], abs=1e-9 * found.torque_scale)
        assert a.energy_swing == pytest.approx(swing, rel=1e-8)


def pattern(firing: list[float], cycle: float) -> tuple[float, ...]:
    """Firing angles less cylinder 1's, modulo the working cycle, degrees (to 1e-6°)."""
    return tuple(round((f - firing[0]) % cycle, 6) % cycle for f in firing)


def brute_force_firings(engine, phases) -> dict[tuple[float, ...], set[tuple[int, ...]]]:
    """Every firing the engine built with ``phases`` accepts, by its pattern (cylinder 1 at 0),
    each with the orders, from any cylinder, that fire it (its firing_angles, every
    permutation)."""
    cylinders = tuple(replace(c, phase_deg=p)
                      for c, p in zip(engine.cylinders, phases, strict=True))
    cycle = 720.0 if engine.strokes == 4 else 360.0
    out: dict[tuple[float, ...], set[tuple[int, ...]]] = {}
    for order in itertools.permutations(range(1, len(cylinders) + 1)):
        try:  # (an engine with gas checks its firing order when it is made)
            angles = replace(engine, cylinders=cylinders, firing_order=order).firing_angles()
        except SpecError:
            continue
        out.setdefault(pattern([math.degrees(a) for a in angles], cycle), set()).add(order)
    return out


def test_the_uneven_search_has_every_crank_on_its_step_and_every_order_that_fits():
    """An in-line four on a 90° step: 4³ cranks; for each, the firing orders the search gives
    are exactly those the engine accepts (its firing_angles, over every permutation). The even
    firings are among them with the even search's figures; the flat-plane four is still first,
    and no uneven firing of its crank exists (its top dead centres allow none)."""
    design = load_design(EXAMPLES / "inline_four.toml")
    engine = replace(design.mechanism, crankshaft=replace(design.mechanism.crankshaft,
                                                          masses=()), balance_shafts=())
    speed = design.operation.speed
    uneven = search(engine, speed, step=90.0, samples=360)
    even = search(engine, speed, samples=360)
    by_crank: dict[tuple[float, ...], list[tuple[int, ...]]] = {}
    for a in uneven.arrangements:
        by_crank.setdefault(a.phases, []).append(a.firing_order)
    cranks = {(0.0, *p) for p in itertools.product((0.0, 90.0, 180.0, 270.0), repeat=3)}
    firings = {p: brute_force_firings(engine, p) for p in cranks}
    assert set(by_crank) == {p for p in cranks if firings[p]}
    from_others = 0
    for phases, orders in by_crank.items():
        found = {}
        for order in orders:  # each the engine's own: its pattern, once
            angles = replace(engine, cylinders=tuple(
                replace(c, phase_deg=p) for c, p in zip(engine.cylinders, phases, strict=True)),
                firing_order=order).firing_angles()
            key = pattern([math.degrees(a) for a in angles], 720.0)
            assert key not in found and order in firings[phases][key], (phases, order)
            found[key] = order
        assert set(found) == set(firings[phases]), phases  # every firing that fits, once
        for key, order in found.items():  # cylinder 1 first wherever an order from it fires it
            assert (order[0] == 1) == any(o[0] == 1 for o in firings[phases][key])
            from_others += order[0] != 1
    assert from_others  # (firings that only an order from another cylinder fires: 90° has some)
    same = {(a.phases, a.firing_order): a for a in uneven.arrangements}
    for a in even.arrangements:
        b = same[(a.phases, a.firing_order)]
        assert b.free == a.free and b.energy_swing == pytest.approx(a.energy_swing, rel=1e-12)
    assert {a.phases for a in uneven.arrangements if a.rank == 1} == {(0.0, 180.0, 180.0, 0.0)}
    assert all(set(a.intervals) == {180.0} for a in uneven.arrangements
               if a.phases == (0.0, 180.0, 180.0, 0.0))
    crank = (0.0, 180.0, 90.0, 270.0)  # (a cross-plane crank: even and uneven firings)
    swings = {len(set(a.intervals)) == 1: a.energy_swing for a in uneven.arrangements
              if a.phases == crank}
    assert set(swings) == {False} or swings[True] < swings[False]


def test_a_step_that_does_not_divide_the_turn_is_refused(capsys):
    assert main(["search", str(EXAMPLES / "inline_four.toml"), "--step", "7"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--step" in err[0]
    assert main(["search", str(EXAMPLES / "inline_four.toml"), "--step", "90", "--json",
                 "--top", "2"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["step_deg"] == 90.0
    assert {"firing_intervals_deg", "energy_swing", "torque_orders"} <= set(doc["arrangements"][0])


@pytest.mark.slow  # (the full suite's: the fast lane's minute)
def test_regressions_of_the_audit(capsys, tmp_path):
    """A step of nan or inf is refused by its key; a search too big is refused by its first
    cranks' count, at once (the V8 on 15°: 24³ cranks); at a number of samples the banks do not
    divide (the V6's 60° at 100), the torque's samples are raised to a whole multiple, so that
    mirror images stay tied (1-4-2-6-3-5 and 1-5-3-6-2-4)."""
    for bad in ("nan", "inf", "360"):
        assert main(["search", str(EXAMPLES / "v8.toml"), "--step", bad]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "--step" in err[0]
    assert main(["search", str(EXAMPLES / "v8.toml"), "--step", "15"]) == 2
    assert "from the first 16 of 13824 cranks" in capsys.readouterr().err  # (not all of them)
    design = load_design(EXAMPLES / "v6.toml")
    found = search(design.mechanism, design.operation.speed, step=120.0, samples=100)
    mirror = {a.firing_order: a for a in found.arrangements
              if a.firing_order in ((1, 4, 2, 6, 3, 5), (1, 5, 3, 6, 2, 4))
              and a.phases in ((60.0, 300.0, 300.0, 60.0, 180.0, 180.0),
                               (60.0, 60.0, 180.0, 300.0, 300.0, 180.0))}
    assert len({a.rank for a in mirror.values()}) == 1, mirror
