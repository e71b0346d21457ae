"""What the designer reads is what is true (issue 40): rounding, engines' reports, messages.

- A figure that is rounding of its quantity's scale is printed 0 in every text table (the
  JSON keeps every digit), and a ratio between rounding figures is no figure
  (:class:`balancer.rounding.Scales`).
- An engine's balancing writes its original (``[original]``), which ``analyze``, ``plot`` and
  ``verify`` read; its report names the counterweights' centrifugal forces as what they are and
  gives each throw's balance factor, checked here by a route of its own from the spec's
  numbers; the mount torque is a CSV column; speeds come with rpm.
"""

from __future__ import annotations

import csv
import io
import json
import math
import tomllib
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import pytest

from balancer.api import analyze, cycle_analyses, verify
from balancer.balance.optimizer import optimize
from balancer.cli import main
from balancer.cycle import CycleSummary, Figure
from balancer.errors import SpecError
from balancer.report import (
    analysis_json,
    analysis_text,
    optimization_json,
    optimization_text,
    simulation_text,
    verification_text,
    worse_figures,
)
from balancer.rounding import ROUNDING, Scales
from balancer.simulation import simulate
from balancer.spec import load_design, loads_design
from balancer.verification import RunCheck, Verification

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def _row(text: str, label: str) -> list[str]:
    """The cells of the table row that begins with ``label`` (split on two spaces or more)."""
    for line in text.splitlines():
        if line.startswith(label + "  "):
            return [c.strip() for c in line[len(label):].split("  ") if c.strip()]
    raise AssertionError(f"no row {label!r} in\n{text}")


# ---------------------------------------------------------------------------------------------
# The rule


def test_the_rule_prints_rounding_as_zero_and_no_ratio_of_rounding():
    sc = Scales([("N", 697.0), ("N", 4.3e-14), ("N·m", 573.0), ("N·m", None),
                 ("N·m", math.nan)])
    assert sc.scale == {"N": 697.0, "N·m": 573.0}
    assert sc.fmt(4.3317e-14, "N").strip() == "0"
    assert sc.fmt(697.254, "N").strip() == "697.254"
    limit = ROUNDING * 697.0
    assert sc.rounding(limit, "N") and not sc.rounding(2 * limit, "N")
    assert sc.number(2 * limit, "N", ".4g") == f"{2 * limit:.4g}"  # above it: the figure
    assert sc.ratio(4.3e-14, 430.0, "N") == "0"        # after rounding, before not
    assert sc.ratio(8e-13, 8e-13, "N") == "—"          # both rounding
    assert sc.ratio(430.0, 8e-13, "N") == "—"          # risen from rounding: no ratio
    assert sc.ratio(1.0, None, "N") == "—" and sc.ratio(1.0, 0.0, "N") == "—"
    assert sc.ratio(330.923, 147.315, "N") == "2.25"
    assert Scales().fmt(1e-30, "N").strip() == "1.0000e-30"  # no scale: nothing is rounding


def test_analyze_prints_the_v8s_shaking_moment_and_free_orders_as_zero_the_json_keeps_them():
    """The issue's case: `analyze examples/v8.toml` listed 'shaking moment 8.0194e-13' and
    orders of 1.4348e-11 N beside 523 N; the JSON keeps every digit."""
    cycle = analyze(load_design(EXAMPLES / "v8.toml"))
    text = analysis_text(cycle)
    assert _row(text, "shaking moment") == ["0", "0", "N·m"]
    assert _row(text, "shaking force")[:2] == ["369.977", "523.574"]
    order1 = _row(text, "1")
    assert order1[:6] == ["0"] * 6 and order1[-2] == "0.793019"  # only the couple's forward
    doc = analysis_json(cycle)
    assert 0 < doc["shaking_moment"]["rms"] < ROUNDING * doc["driving_torque"]["max"]
    assert 0 < abs(doc["orders"][1]["shaking_force"]["x"]) < 1e-9
    assert "e-1" not in text


def test_analyze_of_a_mechanism_without_rounding_prints_every_figure():
    text = analysis_text(analyze(load_design(EXAMPLES / "pb1.toml")))
    assert _row(text, "shaking moment") == ["214.892", "573.986", "N·m"]
    assert _row(text, "8")[:2] == ["1.13153", "0.921561"]


@pytest.fixture(scope="module")
def pb1():
    design = load_design(EXAMPLES / "pb1.toml")
    return design, optimize(design, "convex")


def test_optimize_prints_the_balanced_force_as_zero_and_its_ratio_zero(pb1):
    """PB1's after-figures of the shaking force were 7.6e-14 N beside 697 N, the ratio
    1.76e-16: now 0 and 0; the JSON keeps them."""
    _, result = pb1
    before, after = result.operating
    text = optimization_text(result, before, after)
    assert _row(text, "shaking force") == ["430.272", "0", "0", "697.254", "0", "N"]
    assert _row(text, "shaking moment")[1:3] == ["101.59", "0.473"]
    assert _row(text, "1: force forward") == ["394.105", "0", "N"]
    doc = optimization_json(result, before, after)
    assert 0 < doc["after"]["shaking_force"]["rms"] < 1e-10
    assert "force-balanced: yes" in text


def test_a_ratio_of_two_rounding_figures_is_no_figure():
    """`optimize examples/v8_to_balance.toml` printed the ratio 1 between 8e-13 and 8e-13."""
    design = load_design(EXAMPLES / "v8_to_balance.toml")
    result = optimize(design, "convex")
    text = optimization_text(result, *result.operating)
    assert _row(text, "shaking moment") == ["0", "0", "—", "0", "0", "N·m"]
    assert _row(text, "driving torque")[2] == "1"
    assert _row(text, "1: couple backward") == ["0", "0", "N·m"]


def test_the_verdict_gives_a_rounding_optimum_as_zero():
    """PB2's complete balance: 'RMS shaking moment 6.48695e-10 N·m (3.02e-12 of the
    original's)' is 0 to the problem's scale (214.9 N·m)."""
    result = optimize(load_design(EXAMPLES / "pb2.toml"), "convex")
    assert "RMS shaking moment 0 N·m (0 of the original's)" in result.message
    assert 0 < result.rms < ROUNDING * result.scale


def _summary(force: float, moment: float, torque: float, ground: float) -> CycleSummary:
    def fig(x: float) -> Figure:
        return Figure(rms=x, max=x)

    return CycleSummary(shaking_force=fig(force), shaking_moment=fig(moment),
                        driving_torque=fig(torque), rocking_couple=fig(0.0),
                        ground={"A0": fig(ground)}, slider_normal={}, slider_couple={})


def test_a_rounding_figure_that_doubles_is_no_warning_one_that_rises_from_it_is():
    before = SimpleNamespace(summary=_summary(400.0, 2e-13, 100.0, 900.0), orders=())
    same = SimpleNamespace(summary=_summary(400.0, 5e-13, 100.0, 900.0), orders=())
    assert worse_figures(before, same) == []  # (2.5× of rounding: no warning)
    risen = SimpleNamespace(summary=_summary(400.0, 50.0, 100.0, 900.0), orders=())
    warnings = worse_figures(before, risen)
    assert warnings == [
        "the shaking moment's RMS rises from 0 (to rounding) to 50 N·m",
        "the shaking moment's maximum rises from 0 (to rounding) to 50 N·m"]


def _run(force, original_force, moment, original_moment):
    return RunCheck(trajectory=None, original=None, max_shaking_force=force,
                    max_shaking_moment=moment, original_max_shaking_force=original_force,
                    original_max_shaking_moment=original_moment, max_rocking_couple=0.0,
                    original_max_rocking_couple=0.0)


def test_verify_prints_rounding_as_zero_and_its_ratios_as_zero_or_none():
    check = Verification(method="complex-masses",
                         driven=_run(6.551e-14, 697.3, 1.211e-13, 574.0),
                         free=_run(8.0e-16, 5.38, 3e-14, 2e-14))
    text = verification_text(check)
    assert _row(text, "driven at the operating speed") == [
        "0", "697.3", "0", "—", "0", "574", "0"]
    # The free run's moments are both rounding of the report's scale (574 N·m): no ratio.
    assert _row(text, "free from the initial state") == ["0", "5.38", "0", "—", "0", "0", "—"]


def test_simulate_prints_a_balanced_design_s_shaking_force_as_zero(pb1):
    design, result = pb1
    balanced = result.balanced_design(design)
    settings = replace(balanced.simulation, drive="constant-speed", omega1=10.0,
                       duration=0.2, outputs=11)
    traj = simulate(balanced.mechanism, settings)
    text = simulation_text(traj)
    assert _row(text, "shaking force") == ["0", "0", "N"]
    assert float(_row(text, "driving torque")[1]) > 100
    assert "10 rad/s (95.49 rpm)" in text
    assert 0 < max(abs(traj.shaking_force)) < 1e-10


# ---------------------------------------------------------------------------------------------
# An engine's balancing: its original, its costs, its balance factors


@pytest.fixture(scope="module")
def three(tmp_path_factory):
    """``inline_three_to_balance`` balanced: the written spec, the report and the JSON."""
    folder = tmp_path_factory.mktemp("three")
    out = folder / "balanced.toml"
    spec = str(EXAMPLES / "inline_three_to_balance.toml")
    text, doc = io.StringIO(), io.StringIO()
    from contextlib import redirect_stderr, redirect_stdout

    with redirect_stdout(text), redirect_stderr(io.StringIO()):
        assert main(["optimize", spec, "--no-verify", "--out", str(out)]) == 0
    with redirect_stdout(doc):
        assert main(["optimize", spec, "--no-verify", "--json", "--backend", "convex"]) == 0
    return out, text.getvalue(), json.loads(doc.getvalue())


def test_an_engine_s_written_spec_keeps_its_original(three):
    out, _, _ = three
    written = out.read_text()
    assert "[original.crankshaft]" in written and "[original.piston]" in written
    balanced = load_design(out)
    original = load_design(EXAMPLES / "inline_three_to_balance.toml").mechanism
    assert balanced.original == original  # read back exactly: masses, rod, piston, shafts
    assert balanced.mechanism != original
    assert loads_design(written).original == original


@pytest.mark.slow
def test_an_engine_s_original_is_what_plot_and_verify_show(three):
    out, _, _ = three
    design = load_design(out)
    now, before = cycle_analyses(design, samples=720)
    assert before is not None
    unbalanced = analyze(load_design(EXAMPLES / "inline_three_to_balance.toml"))
    assert before.summary.rocking_couple.rms == pytest.approx(
        unbalanced.summary.rocking_couple.rms, rel=1e-12)
    assert now.summary.rocking_couple.rms < 0.4 * before.summary.rocking_couple.rms
    check = verify(design, duration=0.005)
    for run in (check.driven, check.free):
        assert run.original_max_rocking_couple is not None
        assert run.max_rocking_couple < run.original_max_rocking_couple
    text = verification_text(check)  # (the original's figures, not "—" as before)
    couples = text.split("max |Mrock| (N·m)", 1)[1]
    original = float(_row(couples.split("\n", 2)[2], "driven at the operating speed")[1])
    assert original == pytest.approx(check.driven.original_max_rocking_couple, rel=1e-3)


def test_an_engine_s_original_key_errors_are_named_there(three):
    out, _, _ = three
    text = out.read_text().replace("[original.piston]\nmass = 0.38", "[original.piston]\nmass = -1")
    with pytest.raises(SpecError) as caught:
        loads_design(text)
    assert caught.value.key == "original.piston.mass"
    text = out.read_text().replace("[original.rod]\nmass", "[original.rod]\nmas")
    with pytest.raises(SpecError, match="original.rod.mas: unknown key 'mas'; did you mean "
                                        "'mass'"):
        loads_design(text)


def test_an_engine_report_names_the_centrifugal_forces_and_gives_rpm(three):
    _, text, doc = three
    line = next(x for x in text.splitlines() if x.startswith("their centrifugal forces"))
    assert "root-sum-square" in line and "no bearing's load" in line and "6000 rpm" in line
    assert "the main bearings' net reaction RO" in text
    # The shaft's two opposed eccentrics leave its bearings no net force: rounding, printed 0.
    assert "new shaft 1: largest net force on its bearings 0 N" in text
    assert 0 <= doc["balance_shafts"][0]["max_bearing_load"] < 1e-9


def _factor_by_hand(rod_mass, e, rod, piston, crank, pin_mr, counterweights):
    """A throw's balance factor from the spec's numbers: counterweights' mr opposite the pin
    over pin + the rod's big-end share + half the reciprocating (piston + small-end share)."""
    rotating = pin_mr + rod_mass * (1 - e / rod) * crank
    reciprocating = (piston + rod_mass * e / rod) * crank
    return counterweights / (rotating + reciprocating / 2)


def test_a_single_s_counterweights_balance_its_rotating_and_half_its_reciprocating_mass():
    """The single's comment: counterweights of m_pin·r + m_rod·(1 − e/l)·r + ½·m_rec·r — a
    balance factor of 100 % in the convention engine designers quote for a throw."""
    spec = tomllib.loads((EXAMPLES / "single_cylinder.toml").read_text())
    (throw,) = load_design(EXAMPLES / "single_cylinder.toml").mechanism.throws()
    rod, lengths = spec["links"]["rod"], spec["mechanism"]["lengths"]
    expected = _factor_by_hand(rod["mass"], rod["com"]["e"], lengths["rod"],
                               spec["links"]["piston"]["mass"], lengths["crank"], 0.0113,
                               2 * 0.01539)
    assert throw.cylinders == (1,)
    assert throw.factor == pytest.approx(expected, rel=1e-12)
    assert throw.factor == pytest.approx(1.0, abs=1e-3)


def test_throws_are_the_cylinders_on_one_pin():
    four = load_design(EXAMPLES / "inline_four.toml").mechanism
    assert [t.cylinders for t in four.throws()] == [(1,), (2,), (3,), (4,)]
    spec = tomllib.loads((EXAMPLES / "inline_four.toml").read_text())
    rod, lengths = spec["links"]["rod"], spec["mechanism"]["lengths"]
    expected = _factor_by_hand(rod["mass"], rod["com"]["e"], lengths["rod"],
                               spec["links"]["piston"]["mass"], lengths["crank"], 0.0105,
                               2 * 0.0103)
    assert all(t.factor == pytest.approx(expected, rel=1e-12) for t in four.throws())
    # Without counterweights between them, cylinders 2 and 3 (both at 180°) share a pin.
    bare = replace(four, crankshaft=replace(four.crankshaft, masses=tuple(
        m for m in four.crankshaft.masses if m.label != "counterweight")))
    assert [t.cylinders for t in bare.throws()] == [(1,), (2, 3), (4,)]
    assert all(t.factor == 0 for t in bare.throws())
    v8 = load_design(EXAMPLES / "v8.toml").mechanism
    assert [t.cylinders for t in v8.throws()] == [(1, 2), (3, 4), (5, 6), (7, 8)]


def test_optimize_gives_each_throw_s_balance_factor_before_and_after(three):
    """The balanced in-line three by hand: its end webs' new counterweights (from the JSON's
    crankshaft_counterweights) and the inner webs' kept ones, each throw's nearest."""
    _, text, doc = three
    spec = tomllib.loads((EXAMPLES / "inline_three_to_balance.toml").read_text())
    rod, lengths = spec["links"]["rod"], spec["mechanism"]["lengths"]
    piston = spec["links"]["piston"]["mass"]
    new = {c["z"]: c for c in doc["crankshaft_counterweights"]}
    factors = doc["balance_factors"]
    assert [t["cylinders"] for t in factors["before"]] == [[1], [2], [3]]
    for k, (pin_z, phase) in enumerate(((-0.091, 0.0), (0.0, 120.0), (0.091, 240.0))):
        kept = [m for m in spec["links"]["crankshaft"]["masses"]
                if m.get("label") == "counterweight" and m["z"] not in new
                and min((-0.091, 0.0, 0.091), key=lambda z: abs(z - m["z"])) == pin_z]
        added = [c for z, c in new.items()
                 if min((-0.091, 0.0, 0.091), key=lambda p: abs(p - z)) == pin_z]
        opposite = sum(-m["mr"] * math.cos(math.radians(m["phase_deg"] - phase))
                       for m in (*kept, *added))
        expected = _factor_by_hand(rod["mass"], rod["com"]["e"], lengths["rod"], piston,
                                   lengths["crank"], 0.012, opposite)
        after = factors["after"][k]
        assert after["counterweight_mr"] == pytest.approx(opposite, rel=1e-12)
        assert after["factor"] == pytest.approx(expected, rel=1e-12)
        assert factors["before"][k]["factor"] == pytest.approx(
            _factor_by_hand(rod["mass"], rod["com"]["e"], lengths["rod"], piston,
                            lengths["crank"], 0.012, 2 * 0.01438), rel=1e-12)
    assert list(doc)[-1] == "balance_factors"  # after the keys every document has
    assert "balance factor of each throw" in text
    assert _row(text, "2")[-2:] == ["70.6 %", "70.6 %"]


def test_a_linkage_s_optimize_json_has_no_balance_factors(pb1):
    _, result = pb1
    assert "balance_factors" not in optimization_json(result, *result.operating)


# ---------------------------------------------------------------------------------------------
# The CSV's mount torque, the guide forces' direction, the cycle's words


def test_the_mount_torque_is_the_analyze_csv_s_last_column(tmp_path, capsys):
    out = tmp_path / "v8.csv"
    assert main(["analyze", str(EXAMPLES / "v8.toml"), "--csv", str(out)]) == 0
    rows = list(csv.reader(out.read_text().splitlines()))
    assert rows[0][-2:] == ["driving_torque", "mount_torque"]
    header = rows[0]
    values = [dict(zip(header, map(float, r), strict=True)) for r in rows[1:]]
    assert all(r["mount_torque"] == r["shaking_moment"] + r["driving_torque"] for r in values)
    peak = max(abs(r["mount_torque"]) for r in values)
    assert peak == pytest.approx(analyze(load_design(EXAMPLES / "v8.toml")).summary
                                 .mount_torque.max, rel=1e-15)
    pb1 = tmp_path / "pb1.csv"
    assert main(["analyze", str(EXAMPLES / "pb1.toml"), "--csv", str(pb1)]) == 0
    assert "mount_torque" not in pb1.read_text().splitlines()[0]


def test_a_piston_s_normal_force_points_along_its_axis_turned_a_quarter_turn():
    """docs/outputs.md: N_<link> is the force on the frame across the guide, along the guide's
    direction turned +90°. Summed with the main bearings' reaction it is the shaking force."""
    design = load_design(EXAMPLES / "v8.toml")
    cycle = analyze(design)
    names, columns = cycle.columns()
    col = dict(zip(names, columns, strict=True))
    total = col["ROx"] + 1j * col["ROy"]
    for k, c in enumerate(design.mechanism.cylinders, start=1):
        total = total + col[f"N_piston{k}"] * 1j * complex(math.cos(c.bank), math.sin(c.bank))
    force = col["shaking_force_x"] + 1j * col["shaking_force_y"]
    assert max(abs(total - force)) < 1e-12 * max(abs(col["N_piston1"]))
    assert max(abs(col["N_piston1"])) > 1000  # (not a sum of zeros)


def test_a_four_stroke_cycle_says_its_samples_the_same_way_everywhere():
    cycle = analyze(load_design(EXAMPLES / "inline_four.toml"))  # (with gas: over 720°)
    assert cycle.samples == 1440
    words = "720 angles per revolution over a cycle of 720° (1440 in all) at 628.319 rad/s"
    assert words in repr(cycle) and "(6000 rpm)" in repr(cycle)
    assert ("720 crank angles per revolution over a cycle of 720° (1440 in all) at 628.319 "
            "rad/s (6000 rpm)") in analysis_text(cycle)
    one = analyze(load_design(EXAMPLES / "pb1.toml"))
    assert "360 angles per revolution at 10 rad/s (95.49 rpm)" in repr(one)
