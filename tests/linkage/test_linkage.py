"""General linkage specs: the four-bar and slider-crank written as ``type = "linkage"``."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer.cli import main
from balancer.linkage.kinematics import numeric_table
from balancer.mechanisms import mechanism_of
from balancer.model import Design
from balancer.spec import dumps_design, load_design, loads_design

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _as_linkage(design: Design) -> Design:
    """The same design with its mechanism written as a general linkage."""
    general = mechanism_of(design.mechanism).linkage
    return replace(design, mechanism=general, original=None, balance=None,
                   simulation=replace(design.simulation, method=None))


def _analyze(tmp_path, design: Design, name: str, capsys) -> dict:
    path = tmp_path / name
    path.write_text(dumps_design(design))
    capsys.readouterr()
    assert main(["analyze", str(path), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("example", ["meijaard2020.toml", "pb2.toml"])
def test_a_four_bar_written_as_a_linkage_has_the_same_figures(tmp_path, capsys, example):
    # Two routes to the same numbers: the four-bar's closed forms (Eq. 1–11) and the general
    # core's loop equations, each rounding-exact: 1e-9 relative (DESIGN.md).
    design = replace(load_design(EXAMPLES / example), original=None, balance=None)
    four_bar = _analyze(tmp_path, design, "four.toml", capsys)
    linkage = _analyze(tmp_path, _as_linkage(design), "linkage.toml", capsys)
    for key in ("shaking_force", "shaking_moment", "driving_torque"):
        for stat in ("rms", "max"):
            assert linkage[key][stat] == pytest.approx(four_bar[key][stat], rel=1e-9), key
    for point in ("A0", "A3"):
        assert linkage["reactions"][point]["max"] == pytest.approx(
            four_bar["reactions"][point]["max"], rel=1e-9)


def test_a_slider_crank_written_as_a_linkage_has_the_same_figures(tmp_path, capsys):
    design = load_design(EXAMPLES / "engine.toml")
    model = design.mechanism.without_gas_force() if hasattr(
        design.mechanism, "without_gas_force") else replace(
        design.mechanism, gas_force=type(design.mechanism.gas_force)())
    design = replace(design, mechanism=model, original=None, balance=None)
    slider = _analyze(tmp_path, design, "slider.toml", capsys)
    linkage = _analyze(tmp_path, _as_linkage(design), "linkage.toml", capsys)
    for key in ("shaking_force", "shaking_moment", "driving_torque"):
        assert linkage[key]["rms"] == pytest.approx(slider[key]["rms"], rel=1e-9), key
    assert linkage["reactions"]["slider"]["max"] == pytest.approx(
        slider["reactions"]["slider"]["max"], rel=1e-9)


def test_a_linkage_design_round_trips_with_its_original(tmp_path):
    from test_multibody import WATT

    design = loads_design(WATT, "watt.toml")
    mech = design.mechanism
    original = mech.with_links({"crank": replace(mech.link("crank"), mass=3.5)})
    design = replace(design, original=original)
    again = loads_design(dumps_design(design), "again.toml")
    assert again == design
    assert again.original == original


@pytest.mark.parametrize("method", ["multibody", "crank-angle"])
def test_a_simulated_linkage_agrees_with_its_four_bar(method):
    # The same free motion by the paper's opened loop and by a general formulation (the
    # multibody's absolute coordinates, or Lagrange's equation in the crank angle): two
    # integrations, each within its tolerance, carried by the motion (helpers.growth: the
    # motion's amplification of a step's error).
    from helpers import growth

    from balancer.simulation import simulate

    design = load_design(EXAMPLES / "meijaard2020.toml")
    settings = replace(design.simulation, duration=1.0)
    tight = {"rtol": 1e-11, "atol": 1e-13}
    ref = simulate(design.mechanism, settings, method="opened-loop", **tight)
    run = simulate(_as_linkage(design).mechanism, settings, method=method, **tight)
    assert run.method == method
    amplified = growth(simulate, design.mechanism, settings, reference=ref,
                       method="opened-loop", **tight)
    for key in ("theta", "omega", "alpha"):
        bound = amplified.bound(lambda r, key=key: getattr(r, key), ref, run)
        assert np.max(np.abs(getattr(run, key) - getattr(ref, key))) < bound, key


@pytest.mark.parametrize("example", ["pb1.toml", "pb2.toml"])
def test_a_four_bar_balanced_as_a_linkage_reaches_the_same_optimum(example):
    # The four-bar's force balance is Eq. 57–58 in closed form; the linkage's is found from
    # the variation of its centre of mass (balancer.force_balance): the same row space, so the
    # same certified optimum. Each RMS is within GAP_TOLERANCE of the problem's scale of its
    # certified lower bound, so the two agree within twice that.
    from balancer.balance.optimizer import optimize
    from balancer.balance.result import GAP_TOLERANCE

    design = load_design(EXAMPLES / example)
    general = loads_design(dumps_design(replace(_as_linkage(design), balance=design.balance)),
                           "general.toml")
    four_bar = optimize(design, backend="convex")
    linkage = optimize(general, backend="convex")
    assert four_bar.optimal and linkage.optimal
    assert abs(linkage.rms - four_bar.rms) <= 2 * GAP_TOLERANCE * four_bar.scale
    assert abs(linkage.before.summary.shaking_moment.rms
               - four_bar.before.summary.shaking_moment.rms) <= 1e-9 * four_bar.scale


@pytest.mark.parametrize(("change", "key"), [
    # a link may not take a name that [balance] reserves for itself
    (lambda t: t.replace("[links.link5]", "[links.objective]"), "links.objective"),
    # a centre of mass given `at` a point on a link whose frame is undefined: the linkage names
    # the cause (its first two points coincide), not the `at`
    (lambda t: t.replace("C  = [3.6, 3.4]", "C  = [1.4, 2.6]").replace(
        'com = { e = 1.0, f = -0.1 }', 'com = { at = [1.0, 2.0] }'), "links.link5.points"),
])
def test_linkage_spec_errors_name_their_cause(tmp_path, capsys, change, key):
    from test_multibody import WATT

    path = tmp_path / "bad.toml"
    path.write_text(change(WATT))
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{key}:" in err and err.count("\n") == 1


def test_a_radius_of_gyration_that_squares_to_zero_is_no_crash(tmp_path, capsys):
    # min_gyration = 1e-300 (fuzz): ρ² underflows to 0, and the mass bound m ≤ I_max/ρ² that
    # it implies was a division by zero; it implies no bound.
    from test_multibody import WATT

    path = tmp_path / "tiny.toml"
    path.write_text(WATT + "\n[balance]\n[balance.crank]\nmass = [1.0, 3.0]\n"
                    "inertia = [0.1, 0.6]\nmin_gyration = 1e-300\n")
    assert main(["analyze", str(path)]) == 0


def test_a_spec_saved_with_a_byte_order_mark_loads(tmp_path):
    # Some Windows editors start a UTF-8 file with a byte-order mark (fuzz: "not valid TOML at
    # line 1, column 1"); it is not content.
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + (EXAMPLES / "meijaard2020.toml").read_bytes())
    assert load_design(path) == load_design(EXAMPLES / "meijaard2020.toml")


def test_an_initial_crank_angle_too_large_to_integrate_is_refused(tmp_path, capsys):
    # 1e12 rad (fuzz): its rounding (1e-4 rad) swamps the integration's steps; refused, named.
    from test_multibody import WATT

    path = tmp_path / "far.toml"
    path.write_text(WATT.replace("omega1 = 5.0", "omega1 = 5.0\ntheta1 = 1e12"))
    assert main(["simulate", str(path)]) == 2
    assert "simulation.theta1:" in capsys.readouterr().err


@pytest.mark.parametrize("example", ["watt_sixbar.toml", "stephenson_sixbar.toml",
                                     "jansen_leg.toml", "quick_return.toml"])
def test_the_least_assembly_gap_is_brents_minimum(example):
    # The sampled minima of the groups' gap are refined by zooming all at once (5 rounds of
    # 33 points, to ~1e-8 rad); SciPy's bounded Brent from the same brackets (xatol 1e-10 rad)
    # is the independent route. Near its minimum the gap is quadratic, so both are within
    # ~1e-15 of it: 1e-12 absolute (the gaps are ≤ 1).
    from scipy.optimize import minimize_scalar

    from balancer.linkage.assembly import RANGE_SAMPLES, assembly_gaps

    mech = mechanism_of(load_design(EXAMPLES / example).mechanism)
    s = mech.structure
    step = 2 * np.pi / RANGE_SAMPLES
    theta = s.ref_angle[s.input] + step * np.arange(RANGE_SAMPLES + 1)
    gap = assembly_gaps(s, theta)
    dips = np.flatnonzero((gap[1:-1] < gap[:-2]) & (gap[1:-1] <= gap[2:])) + 1
    assert dips.size
    brent = min(minimize_scalar(lambda t: float(assembly_gaps(s, np.array([t]))[0]),
                                bounds=(theta[i - 1], theta[i + 1]), method="bounded",
                                options={"xatol": 1e-10}).fun for i in dips)
    mech.assembly_range()  # (the least gap, found with it)
    assert abs(s.kinematic["least gap"] - min(brent, float(np.min(gap)))) < 1e-12


def _fine_table(monkeypatch, structure, group):
    """The numeric group's table continued one row at a time both ways (no strides, no
    periodicity): the continuation in its plainest form."""
    from balancer.linkage import numeric

    with monkeypatch.context() as patch:
        patch.setattr(numeric, "STRIDE", 1)
        patch.setattr(numeric, "_turn", lambda *args: None)
        structure.cache.clear()
        out = numeric_table(structure, group)
    structure.cache.clear()
    return out


_STEPHENSON = (Path(__file__).resolve().parents[2] / "balancer" / "examples"
               / "stephenson_sixbar.toml")


def _stephenson_with_crank_pin(pin: str | None) -> Design:
    """The shipped Stephenson six-bar, its crank pin D moved (a longer crank: the head then
    cannot follow a whole turn)."""
    text = _STEPHENSON.read_text()
    if pin is not None:
        text = text.replace("D  = [0.02, 0.0346410161514]", f"D  = {pin}")
    return loads_design(text)


def _scotch_yoke(seed: int) -> Design:
    from fuzz.linkages import _random_transform, build_topology, spec_from_topology

    from balancer.spec import design_from_dict

    rng = np.random.default_rng(seed)
    topo, kind, _, _ = build_topology(rng, want="valid", family="scotch-yoke")
    assert kind == "valid"
    doc, _ = spec_from_topology(rng, topo, _random_transform(rng))
    return design_from_dict(doc)


@pytest.mark.parametrize("make", [
    lambda: _stephenson_with_crank_pin(None),
    lambda: _stephenson_with_crank_pin("[0.06, 0.103923048454]"),
    lambda: _stephenson_with_crank_pin("[0.08, 0.138564064606]"),
    lambda: _scotch_yoke(0), lambda: _scotch_yoke(5)],
    ids=["stephenson", "stephenson-swinging", "stephenson-swinging-less", "yoke-0", "yoke-5"])
@pytest.mark.slow
def test_the_strided_continuation_finds_the_plain_ones_table(monkeypatch, make):
    """The table by strides (filled between by one Newton solve, the turn downwards by
    periodicity where the turn upwards closes) is the one-row-at-a-time continuation's: the
    same rows found, each solved to the Newton tolerance (1e-13 of the length scale; the
    group's condition, below 1e3 away from its toggles, makes the coordinates agree to
    1e-10 of it). Full turns and cranks that swing; a four-link group and a yoke's two
    prismatic pairs."""

    structure = mechanism_of(make().mechanism).structure
    groups = [g for g in structure.groups if g.kind == "numeric"]
    assert groups, "a group solved numerically"
    for g in groups:
        structure.cache.clear()
        _, strided = numeric_table(structure, g)
        _, plain = _fine_table(monkeypatch, structure, g)
        np.testing.assert_array_equal(np.isfinite(strided), np.isfinite(plain))
        both = np.isfinite(plain)
        assert both.any(axis=1).sum() > 50
        scale = structure.length_scale()
        tol = np.broadcast_to(np.tile([1e-10 * scale, 1e-10 * scale, 1e-10],
                                      plain.shape[1] // 3), plain.shape)
        assert np.all(np.abs(strided - plain)[both] <= tol[both])


def test_a_slider_direction_of_any_length_is_its_direction():
    # Linkage fuzz campaign (directed): a guide direction [1.7e308, 1.7e308] overflowed its
    # length (an internal error) and [5e-324, 5e-324] lost its digits (a guide at another
    # angle); both are 45°. Scaled by its larger component first, each is the unit vector of
    # [1, 1], exactly as that is (the same rounding: (1 + i)/√2 from the same operations).
    from balancer.linkage.constraints import unit

    reference = unit(1.0, 1.0)
    for x, y in ((1.7e308, 1.7e308), (5e-324, 5e-324), (3.0, 3.0)):
        assert unit(x, y) == reference
    assert unit(-2.0, 0.0) == -1 and unit(0.0, 1e-310) == 1j
    text = (Path(__file__).resolve().parents[2] / "balancer" / "examples"
            / "quick_return.toml").read_text()
    structures = [mechanism_of(loads_design(text.replace("direction = [1.0, 0.0]",
                                                         f"direction = {d}", 1)).mechanism)
                  .structure for d in ("[1.0, 1.0]", "[1.7e308, 1.7e308]", "[5e-324, 5e-324]")]
    for s in structures[1:]:
        assert s.prisms == structures[0].prisms
