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

import pytest

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
    results = load(name).run(out, quick=True)
    report = (out / "report.md").read_text(encoding="utf-8")
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
    assert r["table1"]["initial θ1"] == [1.0] * 4
    assert r["spread"] < 1e-8  # Table 1 by four formulations
    assert r["reaction_spread"] < 1e-8
    # The paper's check at the simulated states: no integration, so rounding only.
    assert r["statewise_alpha"] < 1e-12 and r["statewise_reactions"] < 1e-12
    assert r["energy_error"] < 1e-9 and r["drift"] < 1e-10
    assert {p.name for p in r["figures"]} >= {"fig7_angles.png", "fig8_reactions.png"}


def test_meijaard2020_balanced(quick):
    r = quick("meijaard2020_balanced")
    assert r["force_balance_error"] < 1e-12
    assert r["reaction_sum_level"] < 1e-9  # Fig. 9: the sum of the reactions vanishes
    rms = r["rms"]
    assert rms["original"]["shaking_force"] > 100.0
    for name in ("force-balanced", "moment-minimised", "complete"):
        assert rms[name]["shaking_force"] < 1e-9 * rms["original"]["shaking_force"]
    assert rms["moment-minimised"]["shaking_moment"] < rms["original"]["shaking_moment"]
    assert r["moment_ratio"] < 1.0
    assert math.isclose(rms["moment-minimised"]["shaking_moment"], r["pb1_rms"], rel_tol=1e-6)
    assert r["moment_status"] == r["complete_status"] == "optimal"
    assert r["complete_ratio"] < 1e-6 and r["complete_berkof"] < 1e-7
    assert r["free_complete_moment"] < 1e-9 * r["free_original_moment"]


def test_wunderlich1964(quick):
    r = quick("wunderlich1964")
    assert r["similarity"] < 1e-12  # Theorem 1: S = B0 + γ·(u1 + β·u2)
    assert r["formula"] < 1e-12 and r["closure"] < 1e-12
    assert r["stationary"] < 1e-12 and r["is_stationary"]  # Theorem 2
    assert r["stationary_force_balance"] < 1e-12
    assert r["neutral_equilibrium"] < 1e-9
    assert abs(r["stationary_point"].imag) < 1e-15
    sc = r["slider_crank"]  # Fig. 3 / Theorem 3 and Eq. 20a–b
    assert sc["similarity_error"] < 1e-12
    assert sc["stationary_spread"] < 1e-12 and sc["stationary_at_B0"] < 1e-12
    assert any(f.name == "fig3_slider_crank.png" for f in r["figures"])


def test_bai2024_lie_group(quick):
    r = quick("bai2024_lie_group")
    crank_rocker, parallelogram = r["crank_rocker"], r["parallelogram"]
    # Initial attitudes as printed in the paper (its q_B of the crank-rocker is not converged).
    assert crank_rocker["q0_difference"] < 2e-3
    assert parallelogram["q0_difference"] < 1e-12
    assert crank_rocker["pi1_initial"] == parallelogram["pi1_initial"] == 0.0
    assert r["parallel"] < 1e-10  # the coupler stays parallel to the frame
    assert parallelogram["change_point_passes"] >= 2
    assert r["drift"] < 1e-8 and r["energy_error"] < 1e-6
    assert crank_rocker["final_spread"] < 1e-5


def test_benchmarks_pb(quick):
    r = quick("benchmarks_pb")
    assert r["pb1_backend_agreement"] < 1e-6
    assert 0.0 < r["pb1_moment_ratio"] < 1.0
    assert r["pb2_moment_ratio"] < 1e-6
    for problem in r["problems"].values():
        assert all(res.optimal for res in problem["results"].values())
        # IPOPT on its own reaches the convex lower bound.
        assert problem["ipopt_converged"] and abs(problem["ipopt_gap"]) < 1e-6
        assert problem["verified_force_level"] < 1e-9
    assert r["problems"]["PB2"]["berkof"] < 1e-7
    assert r["problems"]["PB2"]["verified_moment_ratio"] < 1e-6


@pytest.mark.parametrize("name", ["meijaard2020_example", "meijaard2020_balanced",
                                  "wunderlich1964", "bai2024_lie_group", "benchmarks_pb"])
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
    animation = gallery.GALLERY / gallery.ANIMATION
    assert animation.stat().st_size <= gallery.MAX_BYTES[".gif"]
