"""The balancing benchmarks PB1 and PB2, solved by both optimiser backends and verified.

Source: the example of Meijaard & van der Wijk (2020), Eq. 56 (without its loads), and the
balancing conditions of their Sect. 5.2 (force balance, Eq. 57–58; Berkof's complete balance);
the problems are this project's benchmarks (``examples/pb1.toml``, ``examples/pb2.toml``;
``/work/shared/DESIGN.md``, "Benchmark problems"):

- PB1, partial balancing: crank and rocker free (mass 1×–4×, centre of mass within the link's
  length of its ground pivot, inertia ≥ m·(0.1·l)², counter-rotors 0–20 kg·m²), the coupler
  unchanged; exact force balance; RMS shaking moment at 10 rad/s minimised. No published
  optimum exists: the convex backend's optimum is a certified lower bound, and the study shows
  that the nonlinear backend (IPOPT on the designer's parameters) reaches it.
- PB2, complete balancing: PB1 with the coupler free too. The known optimum is zero (Berkof):
  the study shows the shaking moment driven to rounding level and Berkof's conditions met.

For each: the optimum by each backend, the lower bound, the gap, the solve time, the balanced
parameters per link, and the before/after figure of ``balancer verify`` (an independent
simulation with a formulation the optimiser did not use).

Run ``python studies/benchmarks_pb.py``; it writes ``studies/out/benchmarks_pb/``.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from balancer.balance.optimizer import BACKENDS, optimize
from balancer.mechanisms.fourbar.conditions import berkof_residuals, force_balance_error
from balancer.plots import COLOURS, save_png, verification_figure
from balancer.report import markdown_table
from balancer.spec import load_design
from balancer.verification import verify

NAME = "benchmarks_pb"
ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = {"PB1": ROOT / "examples" / "pb1.toml", "PB2": ROOT / "examples" / "pb2.toml"}


def figure_cycle(name: str, result) -> Figure:
    """Shaking moment and driving torque over one revolution, before and after."""
    fig = Figure(figsize=(8, 5.5), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    for label, cycle, colour in (("before", result.before, COLOURS["before"]),
                                 ("after", result.after, COLOURS["after"])):
        deg = np.degrees(cycle.theta1)
        axes[0].plot(deg, cycle.reactions.shaking_moment, color=colour, lw=1.6, label=label)
        axes[1].plot(deg, cycle.reactions.driving_torque, color=colour, lw=1.6, label=label)
    axes[0].set_ylabel("shaking moment about A0 (N·m)")
    axes[1].set_ylabel("driving torque (N·m)")
    axes[1].set_xlabel("crank angle θ1 (°)")
    axes[1].set_xticks(np.arange(0, 361, 60))
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small")
    ratio = result.after.summary.shaking_moment.rms / result.before.summary.shaking_moment.rms
    fig.suptitle(f"{name}: one revolution at {result.before.speed:g} rad/s, before and after "
                 f"balancing\n({result.status}; RMS shaking moment ×{ratio:.3g})", fontsize=11)
    return fig


def solve(name: str, path: Path, duration: float | None, out_dir: Path) -> dict:
    """Both backends on one benchmark; the NLP's design verified and drawn."""
    design = load_design(path)
    results = {backend: optimize(design, backend=backend) for backend in BACKENDS}
    best = results["nlp"]
    balanced = best.balanced_design(design)
    check = verify(balanced, duration=duration)
    figures = [
        save_png(verification_figure(balanced, check), out_dir / f"{name.lower()}_verify.png",
                 dpi=80),
        save_png(figure_cycle(name, best), out_dir / f"{name.lower()}_cycle.png"),
    ]
    before = best.before.summary.shaking_moment.rms
    after = best.after.summary.shaking_moment.rms
    objectives = [r.objective for r in results.values()]
    # Relative to the lower bound, with the library's floor for a zero optimum (1e-10 of the
    # original design's objective).
    floor = max(abs(best.lower_bound), 1e-10 * best.original_objective)
    ipopt = next(stage for stage in best.stages if stage.name == "nlp")
    return {
        "results": results,
        "balanced": best.linkage,
        "verification": check,
        "moment_ratio": after / before,
        "backend_agreement": (max(objectives) - min(objectives)) / floor,
        "ipopt_gap": ipopt.gap,
        "ipopt_converged": ipopt.converged,
        "force_balance_error": force_balance_error(best.linkage),
        "berkof": berkof_residuals(best.linkage).max(),
        "verified_force_level": max(run.force_level for run in (check.driven, check.free)),
        "verified_moment_ratio": max(run.moment_ratio for run in (check.driven, check.free)),
        "figures": figures,
    }


def run(out_dir: Path, quick: bool = False) -> dict:
    """Run the study and write its figures and ``report.md`` into ``out_dir``.

    ``quick`` verifies over 0.5 s of simulated time instead of the specs' 5 s.
    """
    start = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    duration = 0.5 if quick else None
    problems = {name: solve(name, path, duration, out_dir) for name, path in PROBLEMS.items()}
    results = {
        "problems": problems,
        "pb1_backend_agreement": problems["PB1"]["backend_agreement"],
        "pb1_moment_ratio": problems["PB1"]["moment_ratio"],
        "pb2_moment_ratio": problems["PB2"]["moment_ratio"],
        "figures": [f for p in problems.values() for f in p["figures"]],
    }
    results["seconds"] = time.perf_counter() - start
    write_report(out_dir / "report.md", results)
    return results


def write_report(path: Path, results: dict) -> None:
    rows = []
    for name, p in results["problems"].items():
        for backend, r in p["results"].items():
            rows.append([name, backend, str(r.status), f"{r.objective:.6g}",
                         f"{math.sqrt(max(r.objective, 0.0)):.6g}", f"{r.lower_bound:.6g}",
                         f"{r.gap:.1e}", str(r.iterations), f"{1e3 * r.time:.0f}"])
    solves = markdown_table(
        ["problem", "backend", "status", "J = mean M² ((N·m)²)", "RMS moment (N·m)",
         "lower bound ((N·m)²)", "gap", "iterations", "time (ms)"], rows)
    stage_rows = [[name, stage.name, "yes" if stage.converged else "no", stage.solver_status,
                   f"{stage.objective:.6g}", f"{stage.gap:.1e}", str(stage.iterations),
                   f"{1e3 * stage.time:.0f}"]
                  for name, p in results["problems"].items()
                  for stage in p["results"]["nlp"].stages]
    stages = markdown_table(
        ["problem", "stage", "converged", "solver says", "J ((N·m)²)", "gap", "iterations",
         "time (ms)"], stage_rows)
    figures_rows = []
    link_rows = []
    for name, p in results["problems"].items():
        r = p["results"]["nlp"]
        for label, cycle in (("before", r.before), ("after", r.after)):
            s = cycle.summary
            figures_rows.append([name, label, f"{s.shaking_force.rms:.4g}",
                                 f"{s.shaking_moment.rms:.4g}", f"{s.driving_torque.rms:.4g}"])
        for link_name in p["balanced"].link_names:
            link = p["balanced"].link(link_name)
            link_rows.append([name, link_name, f"{link.mass:.6g}", f"{link.e:.6g}",
                              f"{link.f:.6g}", f"{link.inertia:.6g}",
                              f"{link.counter_rotor:.6g}"])
    figures = markdown_table(
        ["problem", "design", "RMS shaking force (N)", "RMS shaking moment (N·m)",
         "RMS driving torque (N·m)"], figures_rows)
    links = markdown_table(
        ["problem", "link", "m (kg)", "e (m)", "f (m)", "I (kg·m²)", "counter-rotor (kg·m²)"],
        link_rows)
    pb1, pb2 = results["problems"]["PB1"], results["problems"]["PB2"]
    checks = markdown_table(
        ["check", "PB1", "PB2"],
        [["objectives of the two backends, difference / lower bound",
          f"{pb1['backend_agreement']:.1e}", f"{pb2['backend_agreement']:.1e}"],
         ["IPOPT stage on its own: gap to the lower bound", f"{pb1['ipopt_gap']:.1e}",
          f"{pb2['ipopt_gap']:.1e}"],
         ["RMS shaking moment after / before", f"{pb1['moment_ratio']:.4g}",
          f"{pb2['moment_ratio']:.1e}"],
         ["Eq. 57 residual of the balanced design", f"{pb1['force_balance_error']:.1e}",
          f"{pb2['force_balance_error']:.1e}"],
         ["largest Berkof residual (complete balance: 0)", f"{pb1['berkof']:.2g}",
          f"{pb2['berkof']:.1e}"],
         ["verify: max shaking force / max reaction", f"{pb1['verified_force_level']:.1e}",
          f"{pb2['verified_force_level']:.1e}"],
         ["verify: max shaking moment / original's", f"{pb1['verified_moment_ratio']:.3g}",
          f"{pb2['verified_moment_ratio']:.1e}"]])
    duration = pb1["verification"].driven.trajectory.t[-1]
    text = f"""# Benchmarks PB1 and PB2: balancing the example of Meijaard & van der Wijk (2020)

Source: the linkage of J. P. Meijaard, V. van der Wijk, *Principal vectors and equivalent mass
descriptions for the equations of motion of planar four-bar linkages*, Multibody System Dynamics
(2020), Eq. 56, and the balance conditions of its Sect. 5.2; the problems are this project's
benchmarks.

Problems: `examples/pb1.toml` (partial balancing: crank, rocker and counter-rotors free, the
coupler unchanged) and `examples/pb2.toml` (complete balancing: the coupler free too), both on
the linkage of Meijaard & van der Wijk (2020), Eq. 56, without its loads; exact shaking-force
balance (Eq. 57–58); J = mean square of the shaking moment over 360 crank angles at 10 rad/s.

What to expect: PB1 has no published optimum — the convex backend's optimum is a certified
global lower bound, and the nonlinear backend must reach it (gap ≈ 0). PB2's optimum is zero
(Berkof's conditions, Meijaard & van der Wijk Sect. 5.2): the shaking moment must vanish to
rounding.

## The solves

{solves}

`nlp` solves the convex problem first (its lower bound and starting point), then IPOPT on the
designer's parameters; the times include both. On a tie the result keeps the convex design (the
least change from the original among the optimal ones), so the two rows can be identical; each
stage on its own:

{stages}

The stages' J are those before the result's final polish, which sets parameters to preferred
values where that changes J by no more than 1e-12 of its floor; at PB2's zero optimum the first
table's J can therefore be slightly larger. Both are at rounding level.

## Before and after (constant 10 rad/s, Newton–Euler route)

{figures}

## Checks

{checks}

The verification simulates the balanced design with the opened-loop formulation (the optimiser
used the mass-matrix one) for {duration:g} s, once with the crank driven at 10 rad/s and once in
free motion from the spec's initial state.

## The balanced designs (nlp backend)

{links}

e, f: centre of mass from the link's first joint along and across the link; I about the centre
of mass.

## Figures

- `pb1_cycle.png`, `pb2_cycle.png`: shaking moment and driving torque over one revolution,
  before and after.
- `pb1_verify.png`, `pb2_verify.png`: the figure of `balancer verify` — reactions and their
  sum, shaking moment before and after, path of the total centre of mass; driven and free.

Generated by `python studies/{NAME}.py` in {results['seconds']:.1f} s.
"""
    path.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    res = run(Path(__file__).parent / "out" / NAME)
    print(f"{NAME}: PB1 backends agree to {res['pb1_backend_agreement']:.1e}, RMS moment "
          f"×{res['pb1_moment_ratio']:.3g}; PB2 RMS moment ×{res['pb2_moment_ratio']:.1e}; "
          f"{res['seconds']:.1f} s")
