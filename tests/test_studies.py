"""The studies in ``studies/`` run (quick settings) and still reproduce what they claim.

Each study is a script; it is loaded from its file here, run into a temporary directory, and its
key numbers are checked against the published results or the cross-formulation agreement it
reports.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
import test_forbal2 as forbal
from conftest import PAPER_LENGTHS
from helpers import drift_bound, growth, integration_bound

from balancer.balance.result import GAP_TOLERANCE
from balancer.mechanisms.fourbar import kinematics as kin
from balancer.model import SimulationSettings
from balancer.simulation import simulate

#: The whole module is of the full suite, not of the fast lane (`pytest -m "not slow"`).
pytestmark = pytest.mark.slow

STUDIES = Path(__file__).resolve().parent.parent / "studies"
PNG = b"\x89PNG\r\n\x1a\n"


def load(name: str) -> ModuleType:
    """Import ``studies/<name>.py`` (a script, not part of a package)."""
    spec = importlib.util.spec_from_file_location(f"study_{name}", STUDIES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while it is executed
    spec.loader.exec_module(module)
    return module


def run_quick(name: str, out: Path) -> dict:
    """Run a study (quick settings), keeping what it simulated and analysed.

    Its simulations (``results["simulated"]``) and cycle analyses (``results["analysed"]``) are
    recorded on the way: the tolerances below are derived from their step counts, tolerances
    and reactions.
    """
    module = load(name)
    simulated, analysed = [], []

    def recording(function, into):
        def call(*args, **kwargs):
            value = function(*args, **kwargs)
            into.append(value)
            return value
        return call

    if hasattr(module, "simulate"):
        module.simulate = recording(module.simulate, simulated)
    if hasattr(module, "cycle_analysis"):
        module.cycle_analysis = recording(module.cycle_analysis, analysed)
    results = module.run(out, quick=True)
    results["simulated"], results["analysed"] = simulated, analysed
    report = (out / getattr(module, "REPORT", "report.md")).read_text(encoding="utf-8")
    assert report.startswith("# ") and "Source" in report
    assert results["figures"]
    for figure in results["figures"]:
        assert figure.parent == out and figure.read_bytes()[:8] == PNG
    return results


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """Run a study once per test session (quick settings) and keep its results."""
    cache: dict[str, dict] = {}

    def get(name: str) -> dict:
        if name not in cache:
            cache[name] = run_quick(name, tmp_path_factory.mktemp(name))
        return cache[name]

    return get


def test_meijaard2020_example(quick):
    r = quick("meijaard2020_example")
    runs = r["simulated"]  # the paper's free motion by the four formulations
    assert r["table1"]["initial θ1"] == [1.0] * 4
    # Four integrations of one free motion: the spread of any two is within the sum of their
    # bounds, amplified by the motion (helpers.growth).
    design = load("meijaard2020_example").load_design(STUDIES.parent / "examples"
                                                      / "meijaard2020.toml")
    ref = next(run for run in runs if run.method == "complex-masses")
    amplified = growth(simulate, design.mechanism, design.simulation, method=ref.method,
                       rtol=ref.rtol, atol=ref.atol, reference=ref)
    spread = max(amplified.bound(lambda run, key=key: getattr(run, key), *runs)
                 for key in ("theta", "omega", "alpha"))
    assert r["spread"] < spread  # Table 1 by four formulations
    reactions = max(run.largest_reaction for run in runs)
    spread = max(amplified.bound(lambda run, key=key: run.ground[key], *runs)
                 for key in ("A0", "A3"))
    assert r["reaction_spread"] < spread / reactions
    # The paper's check at the simulated states: no integration, so rounding only (the
    # formulations at a well-conditioned state: ~ROUNDING·1.4 ≈ 2e-14; within 1e-12).
    assert r["statewise_alpha"] < 1e-12 and r["statewise_reactions"] < 1e-12
    # A first integral, quadratic in the rates; one step's error through the loop closure.
    assert r["energy_error"] < 2 * max(integration_bound(run) for run in runs)
    assert r["drift"] < max(max(drift_bound(run, design.mechanism.lengths)) for run in runs)
    assert {p.name for p in r["figures"]} >= {"fig7_angles.png", "fig8_reactions.png"}


def test_meijaard2020_balanced(quick):
    r = quick("meijaard2020_balanced")
    # Eq. 57 in closed form (force_balanced_by_crank_and_rocker): rounding of a few ratios of
    # masses and lengths, ≲ ROUNDING ≈ 1.4e-14; within 1e-12.
    assert r["force_balance_error"] < 1e-12
    # Fig. 9: the sum of the reactions vanishes at every state of a force-balanced linkage,
    # not to integration error but to the formulations' accuracy, 1e-9 of the reactions.
    assert r["reaction_sum_level"] < 1e-9
    rms = r["rms"]
    assert rms["original"]["shaking_force"] > 100.0
    # The same in the cycle analyses: 1e-9 of the largest reaction among the designs.
    reactions = max(np.nanmax(np.abs(np.concatenate(list(a.reactions.ground.values()))))
                    for a in r["analysed"])
    for name in ("force-balanced", "moment-minimised", "complete"):
        assert rms[name]["shaking_force"] < 1e-9 * reactions
    assert rms["moment-minimised"]["shaking_moment"] < rms["original"]["shaking_moment"]
    assert r["moment_ratio"] < 1.0
    # Both "optimal" for the same problem: each RMS within GAP_TOLERANCE of its problem's
    # scale (the RMS shaking moment of the design it started from) of the one optimum; the
    # analysis's route agrees with the objective's to 1e-9.
    starts = rms["force-balanced"]["shaking_moment"] + rms["original"]["shaking_moment"]
    tol = GAP_TOLERANCE * starts + 1e-9 * r["pb1_rms"]
    assert math.isclose(rms["moment-minimised"]["shaking_moment"], r["pb1_rms"], rel_tol=0,
                        abs_tol=tol)
    assert r["moment_status"] == r["complete_status"] == "optimal"
    # The complete balance's optimum is zero: "optimal" within GAP_TOLERANCE of its scale
    # (the force-balanced design's RMS), relative here to the original's.
    fb = rms["force-balanced"]["shaking_moment"]
    assert r["complete_ratio"] < (GAP_TOLERANCE * fb + 1e-9 * fb) / rms["original"][
        "shaking_moment"]
    # Not derived: no tolerance of the optimiser maps onto Berkof's residuals (~1e-13 here).
    assert r["complete_berkof"] < 1e-7
    # In free motion the complete design's shaking moment vanishes at every state but for its
    # Berkof residuals (relative to m·l², so to the moments' terms) and the formulation's
    # accuracy (1e-9) of those terms: its reactions times a lever arm (free: no torque).
    complete = r["simulated"][-2]  # the runs: four formulations, the complete design, original
    assert np.max(np.abs(complete.shaking_moment)) == r["free_complete_moment"]  # that one
    terms = complete.largest_reaction * max(PAPER_LENGTHS)
    ratio = (1e-9 + r["complete_berkof"]) * terms / r["free_original_moment"]
    assert r["free_complete_moment"] < ratio * r["free_original_moment"]


def test_wunderlich1964(quick):
    r = quick("wunderlich1964")
    # To rounding (DESIGN.md): sums of a few vectors with mass-ratio coefficients, relative to
    # the longest link, ~ROUNDING ≈ 1.4e-14; within 1e-12.
    assert r["similarity"] < 1e-12  # Theorem 1: S = B0 + γ·(u1 + β·u2)
    assert r["formula"] < 1e-12 and r["closure"] < 1e-12
    assert r["stationary"] < 1e-12 and r["is_stationary"]  # Theorem 2
    assert r["stationary_force_balance"] < 1e-12
    # Released at rest with a stationary centre of mass: gravity's moments cancel to rounding,
    # so the rates stay within the integration's absolute error from rest, steps·atol (a few
    # dozen steps at atol 1e-13), plus what that rounding (~ROUNDING·g/l ≈ 1e-13 rad/s²)
    # accelerates in 0.5 s: ≲ 1e-11 rad/s, within 1e-9.
    assert r["neutral_equilibrium"] < 1e-9
    # m3·σ3·a with σ3 = e3/l3: a real number, its imaginary part exactly 0.
    assert abs(r["stationary_point"].imag) < 1e-15
    sc = r["slider_crank"]  # Fig. 3 / Theorem 3 and Eq. 20a–b
    assert sc["similarity_error"] < 1e-12
    assert sc["stationary_spread"] < 1e-12 and sc["stationary_at_B0"] < 1e-12
    assert any(f.name == "fig3_slider_crank.png" for f in r["figures"])


def test_bai2024_lie_group(quick):
    r = quick("bai2024_lie_group")
    study = load("bai2024_lie_group")
    crank_rocker, parallelogram = r["crank_rocker"], r["parallelogram"]
    # Initial attitudes as printed in the paper, four digits. Its q_B of the crank-rocker has
    # length 1.0008: the paper's state closes the loop with a coupler 0.25·|q_B| long (its
    # printed vectors lie within √2·5e-5, half a unit of the fourth digit in each component,
    # of that solution). Ours differ from it by what that length changes in the position
    # analysis, plus that rounding.
    case = study.CASES[0]
    q_b = complex(*case.paper_q0[2:4])
    lengths = list(case.lengths)
    ours = kin.position(case.lengths, case.theta1)
    lengths[1] *= abs(q_b)
    theirs = kin.position(tuple(lengths), case.theta1)
    shift = max(abs(theirs.l2[0] - ours.l2[0]) / case.lengths[1],
                abs(theirs.l3[0] - ours.l3[0]) / case.lengths[2])
    assert crank_rocker["q0_difference"] < shift + math.sqrt(2) * 5e-5
    # The parallelogram's are exact (0.6, 0.8 = cos, sin of atan2(0.8, 0.6)): rounding.
    assert parallelogram["q0_difference"] < 1e-12
    assert crank_rocker["pi1_initial"] == parallelogram["pi1_initial"] == 0.0
    # The projection onto the loop closure holds the parallelogram (rounding, not
    # integration error; the run's own rtol is 1e-9): within 1e-10.
    assert r["parallel"] < 1e-10  # the coupler stays parallel to the frame
    assert parallelogram["change_point_passes"] >= 2
    cases = (crank_rocker, parallelogram)
    drift = max(max(drift_bound(run, res["linkage"].lengths)) for res in cases
                for run in res["runs"].values())
    energy = max(integration_bound(run) for res in cases for run in res["runs"].values())
    assert r["drift"] < drift and r["energy_error"] < 2 * energy
    # Four integrations of one free motion (final angles and rates): within the sum of their
    # bounds, amplified by the motion.
    runs = list(crank_rocker["runs"].values())
    ref = crank_rocker["runs"]["complex-masses"]
    settings = SimulationSettings(duration=r["duration"], theta1=case.theta1, omega1=0.0,
                                  gravity=study.GRAVITY)
    amplified = growth(simulate, crank_rocker["linkage"], settings, method=ref.method,
                       rtol=ref.rtol, atol=ref.atol, reference=ref)
    spread = max(amplified.bound(lambda run, key=key: getattr(run, key), *runs)
                 for key in ("theta", "omega"))
    assert crank_rocker["final_spread"] < spread


def test_benchmarks_pb(quick):
    r = quick("benchmarks_pb")
    # Both backends "optimal": √J of each within GAP_TOLERANCE·scale of the same certified
    # bound, so their J within GAP_TOLERANCE·scale·2√J of each other, relative to J_low.
    pb1 = r["problems"]["PB1"]["results"].values()
    best = max(res.objective for res in pb1)
    agreement = max(GAP_TOLERANCE * res.scale * 2 * math.sqrt(best) / res.lower_bound
                    for res in pb1)
    assert r["pb1_backend_agreement"] < agreement
    assert 0.0 < r["pb1_moment_ratio"] < 1.0
    # PB2's optimum is zero: within GAP_TOLERANCE of its scale (the original's RMS), plus the
    # analysis route's 1e-9.
    assert r["pb2_moment_ratio"] < GAP_TOLERANCE + 1e-9
    for problem in r["problems"].values():
        assert all(res.optimal for res in problem["results"].values())
        # IPOPT on its own reaches the convex lower bound: "optimal" by the library's measure.
        assert problem["ipopt_converged"] and abs(problem["ipopt_gap"]) < GAP_TOLERANCE
        # The verification's shaking force vanishes at every state: 1e-9 of the reactions.
        assert problem["verified_force_level"] < 1e-9
    # Not derived: no tolerance of the optimiser maps onto Berkof's residuals (~1e-13 here).
    assert r["problems"]["PB2"]["berkof"] < 1e-7
    # PB2 verified: the shaking moment vanishes at every state but for the Berkof residuals
    # and the formulation's 1e-9, of the moments' terms (reactions times a lever arm, torque),
    # relative to the original's in the same motion.
    pb2 = r["problems"]["PB2"]
    ratio = 0.0
    for run in (pb2["verification"].driven, pb2["verification"].free):
        tr = run.trajectory
        terms = max(tr.largest_reaction * max(PAPER_LENGTHS),
                    np.max(np.abs(tr.driving_torque)))
        ratio = max(ratio, (1e-9 + pb2["berkof"]) * terms / run.original_max_shaking_moment)
    assert pb2["verified_moment_ratio"] < ratio


def test_linkages(quick):
    r = quick("linkages")
    assert set(r["cases"]) == {"Watt six-bar", "Stephenson six-bar", "quick-return",
                               "Jansen's leg"}
    for name, case in r["cases"].items():
        convex, nlp = case["convex"], case["nlp"]
        assert convex.optimal and nlp.optimal, name
        # Force balance is exact: the balance rows hold to rounding (1e-16) times their
        # conditioning (≤ 1e4), so the total centre of mass stands still to 1e-12 of the size.
        assert case["com_excursion_before"] > 1e-3
        assert case["com_excursion_after"] < 1e-12, name
        assert case["force_after"] < 1e-9 * case["force_before"], name
        # The NLP from the convex optimum and from random starts reaches no lower objective
        # than the certified lower bound (beyond the solvers' GAP_TOLERANCE of the scale).
        floor = convex.lower_bound - GAP_TOLERANCE * convex.scale * 2 * math.sqrt(
            convex.objective)
        assert nlp.objective >= floor, name
        starts = case["multistart"]
        assert starts["converged"] >= 1, name
        assert all(j >= floor for j in starts["objectives"]), name
        # Simulated by the multibody formulation: the shaking force vanishes to 1e-9 of the
        # reactions (DESIGN.md's agreement between formulations).
        assert case["verification"].driven.force_level < 1e-9, name


def test_atlas_and_fronts(quick):
    r = quick("atlas_and_fronts")
    rows = r["rows"]
    assert [row["point"] for row in rows] == list(range(len(rows)))
    # The sweep's "bad-geometry" rows are exactly the geometries Grashof's condition says
    # are no crank-rockers (computed from the lengths alone, in the study).
    assert r["grashof_mismatch"] == 0
    assert {row["status"] for row in rows} == {"optimal", "bad-geometry"}
    for row in rows:
        if row["status"] == "optimal":
            # Certified: the bound below the design's RMS by at most the gap tolerance.
            assert row["lower_bound"] <= row["shaking_moment_after"] * (1 + 1e-12)
            assert row["shaking_moment_after"] - row["lower_bound"] <= (
                GAP_TOLERANCE * row["shaking_moment_before"] + 1e-9)
    for front in r["fronts"].values():
        moments = [p.shaking_moment for p in front.points]
        values = [p.value for p in front.points]
        assert values == sorted(values)
        assert all(b <= a * (1 + GAP_TOLERANCE) for a, b in zip(moments, moments[1:],
                                                                  strict=False))
        assert all(p.lower_bound <= p.shaking_moment * (1 + 1e-12) for p in front.points)
    # Both fronts end at PB1's optimum (the counterweights reach what free links reach).
    ends = [front.points[-1].shaking_moment for front in r["fronts"].values()]
    assert ends[0] == pytest.approx(ends[1], rel=GAP_TOLERANCE)


def _authors_bare_link(name: str) -> tuple[float, complex, float]:
    """A Forbal-2 link without its ring, from the authors' URDF (tests/mechanisms/test_forbal2):
    its mass (kg), centre ``e + i·f`` in the link's frame (m) and inertia about it (kg·m²);
    link 22 with the end effector 0.2 m along it."""
    parts = [forbal.URDF[name]]
    if name == "link22":
        m, (x, z), iyy = forbal.EE
        parts.append((m, (forbal.LENGTH + x, z), iyy))
    mass = math.fsum(m for m, _, _ in parts)
    centre = complex(math.fsum(m * c[0] for m, c, _ in parts),
                     math.fsum(m * c[1] for m, c, _ in parts)) / mass
    inertia = math.fsum(i + m * abs(complex(*c) - centre) ** 2 for m, c, i in parts)
    return mass, centre, inertia


def _parallelogram_first_moments(links: dict) -> tuple[complex, complex]:
    """K11, K21 (kg·m) of links ``{name: (mass, centre)}``: link 11's direction carries links
    11, 22 and link 12's mass at link 11's end; link 21's links 21, 12 and link 22's mass."""
    def first(name):
        return links[name][0] * links[name][1]

    l = forbal.LENGTH
    return (first("link11") + first("link22") + links["link12"][0] * l,
            first("link21") + first("link12") + links["link22"][0] * l)


def test_forbal2(quick):
    """The Forbal-2 study's numbers, each against a route of its own.

    The bare robot against the authors' URDF inertials; the least added mass against the
    parallelogram's closed form from those numbers; the published design's excursion against
    the closed form of tests/mechanisms/test_forbal2.py over the workspace's grid; the loads
    with gravity against the weight's closed forms; the front's points against their designs
    analysed as linkages.
    """
    r = quick("forbal2")
    study = load("forbal2")
    assert {f.name for f in r["figures"]} == {"front.png", "diamond.png",
                                              "least_mass_diamond.png"}
    assert study.RINGS == forbal.RINGS and study.RING_RADII == forbal.RING_RADII
    # The rings taken off the example's links give back the URDF's inertials (to the rounding
    # of the example's combined numbers, given to 15 digits).
    bare = r["designs"]["bare"].mechanism
    authors = {name: _authors_bare_link(name) for name in forbal.URDF}
    for name, (mass, centre, inertia) in authors.items():
        link = bare.link(name)
        assert link.mass == pytest.approx(mass, rel=1e-12), name
        assert abs(complex(link.e, link.f) - centre) <= 1e-12 * abs(centre), name
        assert link.inertia == pytest.approx(inertia, rel=1e-12), name
    # The least added mass: each direction's missing first moment over the counterweights'
    # radius (one on link 22 would spare its mass on link 11 and cost it again on link 21: it is
    # not used). Certified: the design within GAP_TOLERANCE·scale² of the bound (an objective
    # in kg, weight 1 (N·m)²/kg).
    k11, k21 = _parallelogram_first_moments(authors)
    radius = study.COUNTERWEIGHT.radius
    closed = (abs(k11) + abs(k21)) / radius
    result = r["result"]
    assert result.status == "optimal"
    assert abs(r["least_added_mass"] - closed) <= GAP_TOLERANCE * result.scale**2
    assert result.lower_bound <= closed * (1 + 1e-12)
    assert r["closed_form"] == pytest.approx(closed, rel=1e-12)
    # ... each counterweight carrying its direction's first moment, at the radius (off the
    # link's line where K is), none on link 22; the centre of mass then stands still.
    cws = r["counterweights"]
    assert set(cws) == {"link11", "link21"}
    for cw, k in ((cws["link11"], k11), (cws["link21"], k21)):
        assert abs(cw.first_moment + k) <= 1e-12
        # (|c| = |K|/m: a mass within the certified gap δ of the least has |c| within δ/m)
        assert abs(complex(cw.e, cw.f)) == pytest.approx(
            radius, rel=GAP_TOLERANCE * result.scale**2 / cw.mass)
        assert cw.f * k.imag < 0   # off the line, across from the links' own centres
    assert r["least_excursion"] < 1e-12
    assert r["analyses"]["least mass"]["inertial"].force_balanced
    assert not r["analyses"]["published"]["inertial"].force_balanced
    # The published design over the workspace's grid: the closed form of test_forbal2
    # (O + (e^{iθ11}·K11 + e^{iθ21}·K21)/M, the authors' numbers with the rings), on the
    # states whose joint 22 (θ11 − θ21 in a parallelogram) is within its limits.
    design = r["designs"]["published"]
    w = design.workspace
    r11, r21 = w.range_of("link11"), w.range_of("link21")
    g11, g21 = np.meshgrid(np.linspace(r11.low, r11.high, w.samples),
                           np.linspace(r21.low, r21.high, w.samples), indexing="ij")
    theta11, theta21 = -forbal.Q11 + g11.ravel(), forbal.Q21 + g21.ravel()
    (joint,) = w.joints
    change = np.remainder(g11.ravel() - g21.ravel() + np.pi, 2 * np.pi) - np.pi
    kept = (joint.low <= change) & (change <= joint.high)
    p11, p21, mass = forbal._first_moments()
    centre = (np.exp(1j * theta11[kept]) * complex(*p11)
              + np.exp(1j * theta21[kept]) * complex(*p21)) / mass
    assert r["workspace"]["published"].states == kept.sum() == 630
    assert r["published_excursion"] == pytest.approx(
        np.max(np.abs(centre - centre.mean())), rel=1e-9)
    # With gravity, every load differs from the inertial one by the weight's: the frame
    # carries −i·g·M; each motor holds g·Re(e^{iθ}·K) of its direction; the moment about the
    # origin gains −g·M·x_c (x_c from the closed form). Bare robot and published design, from
    # the authors' numbers.
    g = -study.GRAVITY[1]
    first = {"bare": (k11, k21, sum(m for m, _, _ in authors.values())),
             "published": (complex(*p11), complex(*p21), mass)}
    for name, (c11, c21, total) in first.items():
        inertial, weighed = (r["analyses"][name][w_] for w_ in ("inertial", "gravity"))
        for a, b in zip(inertial.motions, weighed.motions, strict=True):
            t11, t21 = a.state.positions
            x_c = (study.AXIS + (np.exp(1j * t11) * c11 + np.exp(1j * t21) * c21) / total).real
            scale = g * total * 0.5   # the weight times the robot's reach, N·m
            ra, rb = a.reactions, b.reactions
            assert np.max(np.abs(rb.shaking_force - ra.shaking_force + 1j * g * total)) \
                <= 1e-12 * g * total
            assert np.max(np.abs(rb.shaking_moment - ra.shaking_moment + g * total * x_c)) \
                <= 1e-12 * scale
            for i, (t, k) in enumerate(((t11, c11), (t21, c21))):
                held = g * np.real(np.exp(1j * t) * k)
                assert np.max(np.abs(rb.torques[i] - ra.torques[i] - held)) <= 1e-12 * scale
    # The rings' reductions with gravity are the RMS the study reports.
    for motion, row in r["reductions"]["gravity"].items():
        for key, cut in row.items():
            assert cut == pytest.approx(1 - r["rms"]["published"]["gravity"][motion][key]
                                        / r["rms"]["bare"]["gravity"][motion][key])
    # The front: from the least mass up, non-increasing; each point's design, rebuilt from
    # its design vector and analysed as a linkage (not through the optimiser's regressors),
    # has the point's added mass and RMS shaking moment, and a still centre of mass over the
    # workspace's grid.
    front = r["front"]
    values = [p.value for p in front.points]
    moments = [p.least for p in front.points]
    scale = max(moments)
    assert values == sorted(values) and front.force_balance
    assert values[0] == pytest.approx(r["least_added_mass"], abs=1e-6)
    assert all(b <= a + GAP_TOLERANCE * scale for a, b in zip(moments, moments[1:],
                                                              strict=False))
    for p, check in zip(front.points, r["front_checks"], strict=True):
        assert check["added_mass"] == pytest.approx(p.value, abs=1e-12)
        assert check["shaking_moment"] == pytest.approx(p.least, rel=1e-9)
        assert check["excursion"] < 1e-12
    # (the least-mass design is one of the designs the front's first point minimises over)
    assert moments[0] <= r["least_point"][1] * (1 + 1e-12)
    # With counterweights on links 11 and 21 only the points are certified, and the front is
    # the same: the counterweight on link 22 buys nothing.
    for p, q in zip(front.points, r["pair_front"].points, strict=True):
        assert q.lower_bound <= q.least * (1 + 1e-12)
        assert q.least - q.lower_bound <= GAP_TOLERANCE * scale
        assert abs(p.least - q.least) <= GAP_TOLERANCE * scale
    # The published design lies above the front (a convex front is below its chords).
    published_mass, published_moment = r["published_point"]
    assert published_mass == pytest.approx(sum(forbal.RINGS.values()), rel=1e-12)
    assert published_moment > r["front_at_published"]


@pytest.mark.parametrize("name", ["meijaard2020_example", "meijaard2020_balanced",
                                  "wunderlich1964", "bai2024_lie_group", "benchmarks_pb",
                                  "linkages", "atlas_and_fronts", "forbal2"])
def test_study_is_a_script_with_run(name):
    module = load(name)
    assert module.NAME == name and callable(module.run)
    assert module.__doc__ and "Source" in module.__doc__
    source = (STUDIES / f"{name}.py").read_text(encoding="utf-8")
    assert 'if __name__ == "__main__":' in source and ".show(" not in source


def test_gallery_shows_figures_the_studies_make(quick):
    gallery = load("make_gallery")
    for study, figure, target in gallery.CHOSEN:
        assert figure in {p.name for p in quick(study)["figures"]}
        committed = gallery.GALLERY / target
        assert committed.stat().st_size <= gallery.MAX_BYTES[committed.suffix]
    for name, _, _ in gallery.ANIMATIONS:
        animation = gallery.GALLERY / name
        assert animation.stat().st_size <= gallery.MAX_BYTES[".gif"]


def test_gallery_report_pictures_come_from_the_gallery_pages_commands():
    # docs/gallery's pictures of `plot --cycle` and `verify --plot` are made by make_gallery
    # running these commands; docs/gallery.md shows each picture and its commands (and
    # tests/test_docs.py runs them), every picture of the gallery and every study that makes one.
    from balancer.cli import build_parser

    gallery = load("make_gallery")
    page = (STUDIES.parent / "docs" / "gallery.md").read_text(encoding="utf-8")
    parser = build_parser()
    for target, commands in gallery.COMMANDS:
        picture = gallery.GALLERY / target
        assert picture.stat().st_size <= gallery.MAX_BYTES[picture.suffix]
        assert f"](gallery/{target})" in page
        for command in commands:
            parser.parse_args(gallery.command_argv(command))  # a valid command line
            shown = command.replace("OUT/", "").replace("docs/gallery/", "")
            assert shown in page, shown
    for study, _, target in gallery.CHOSEN:
        assert f"](gallery/{target})" in page and f"python studies/{study}.py" in page
    for name, spec, frames in gallery.ANIMATIONS:
        assert f"](gallery/{name})" in page
        assert f"balancer plot examples/{spec}.toml --animate {name} --frames {frames}" in page


def test_engine_orders_gives_the_classic_verdicts_and_the_series_shortfall(tmp_path):
    """The engine-layout table (studies/engine_orders.py) against what is known in closed form.

    The orders that cancel are the classic ones (an in-line six, a boxer four and a
    cross-plane V8 free of second-order forces; an in-line three's and a cross-plane V8's
    primary couples √3 and √10 in units of m_rec·r·ω²·a); and where the series and the exact
    motion both leave a second-order force, exact/series = A2/λ with A2 by a quadrature of the
    piston's acceleration written here (the trapezoid rule, exact to rounding for this
    periodic analytic function at 4096 points).
    """
    study = load("engine_orders")
    rows = study.run(tmp_path)["rows"]
    lam = study.CRANK / study.ROD
    psi = 2 * np.pi * np.arange(4096) / 4096
    # x = r·cos ψ + l·√(1 − λ² sin² ψ): −ẍ/(r·ω²) at constant speed, its cos 2ψ coefficient.
    s = np.sin(psi) ** 2
    root = np.sqrt(1 - lam**2 * s)
    accel = np.cos(psi) + lam * (np.cos(2 * psi) / root + lam**2 * np.sin(2 * psi) ** 2
                                 / (4 * root**3))
    a2 = 2 * np.mean(accel * np.cos(2 * psi))
    nothing = study.NOTHING
    for name in ("in-line 6", "boxer 4", "V8 cross-plane"):
        assert rows[name]["exact"]["force"][2] < nothing, name
    assert rows["in-line 6"]["exact"]["couple"][1] < nothing
    assert math.isclose(rows["in-line 3"]["exact"]["couple"][1], math.sqrt(3), rel_tol=1e-9)
    assert math.isclose(rows["V8 cross-plane"]["exact"]["couple"][1], math.sqrt(10),
                        rel_tol=1e-9)
    for name, row in rows.items():
        for kind in ("force", "couple"):
            exact, series = row["exact"][kind], row["two_term"][kind]
            assert (exact[1] < nothing) == (series[1] < nothing), (name, kind)
            assert math.isclose(exact[1], series[1], rel_tol=1e-9, abs_tol=nothing)
            if series[2] > nothing:
                assert math.isclose(exact[2] / series[2], a2 / lam, rel_tol=1e-9), (name, kind)


def test_motion_planning_reaches_the_closed_forms_at_the_schemes_orders(quick):
    r = quick("motion_planning")
    closed = r["closed"]
    # the last meshes' observed orders (the first ones still pre-asymptotic): second for the
    # mean square, first for the peak
    assert abs(closed["rms"]["orders"][-1] - 2.0) < 0.2
    assert abs(closed["peak"]["orders"][-1] - 1.0) < 0.15
    assert closed["rms"]["bound"] == pytest.approx(closed["exact"]["rms"], rel=1e-13)
    for case in (r["forbal"]["levers"], r["press"]["levers"]):
        assert case["both"] <= min(case["masses"], case["motion"]) * (1 + 1e-12)
        assert max(case["masses"], case["motion"]) <= case["spec"]
    rows = r["forbal"]["rows"]
    assert all(x["certified"] for x in rows)
    # refining the mesh, the transcription's optimum falls toward the planned motions' own
    assert rows[-1]["transcription"] < rows[0]["transcription"]
