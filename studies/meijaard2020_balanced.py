"""The force-balanced variant of Meijaard & van der Wijk's example, then moment and full balance.

Source: J. P. Meijaard, V. van der Wijk, *Principal vectors and equivalent mass descriptions for
the equations of motion of planar four-bar linkages*, Multibody System Dynamics (2020),
Sect. 5.2: the linkage of Eq. 56 without its loads, with the centres of mass of crank and
rocker moved so that Eq. 57 holds (``s1, σ1, s3, σ3`` adjusted; the paper does not print the
values, they follow from Eq. 57), released at θ1 = 1 rad with θ̇1 = 1 rad/s in free motion.

What it reproduces:

- Fig. 9, the reactions at the supports of the force-balanced linkage; the paper: "the sum of
  the forces in the x-direction as well as the sum of the forces in the y-direction is zero up
  to truncation errors in the numerics" — here the sum relative to the reactions themselves,
  by every formulation;
- then two redesigns of that linkage that the paper only describes: the shaking moment
  minimised under exact force balance (the bounds of benchmark PB1: crank and rocker free,
  coupler unchanged, counter-rotors allowed) and complete balancing (PB2: the coupler free too;
  Berkof's conditions of Sect. 5.2 give zero shaking moment), with the RMS shaking force,
  shaking moment and driving torque at a constant 10 rad/s for the four designs.

Run ``python studies/meijaard2020_balanced.py``; it writes ``studies/out/meijaard2020_balanced/``.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from balancer.balance.optimizer import optimize
from balancer.cycle import cycle_analysis
from balancer.mechanisms.fourbar.conditions import (
    berkof_residuals,
    force_balance_error,
    force_balanced_by_crank_and_rocker,
)
from balancer.mechanisms.fourbar.mechanism import FourBarMechanism
from balancer.model import SimulationSettings
from balancer.plots import COLOURS, SERIES, plot_reactions, save_png
from balancer.report import markdown_table
from balancer.simulation import simulate
from balancer.spec import dumps_design, load_design, loads_design

#: The paper's four formulations of the four-bar.
METHODS = tuple(FourBarMechanism.own_formulations)

NAME = "meijaard2020_balanced"
ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
RTOL, ATOL = 1e-11, 1e-13
#: Operating speed of the comparison (PB1/PB2's), rad/s, and crank angles per revolution.
SPEED, SAMPLES = 10.0, 360
#: The free motion of Sect. 5.2.
FREE = SimulationSettings(duration=5.0, theta1=1.0, omega1=1.0)
DESIGN_COLOURS = {"original": COLOURS["before"], "force-balanced": SERIES[0],
                  "moment-minimised": SERIES[1], "complete": COLOURS["after"]}


def balanced_from(problem_spec: Path, linkage, title: str):
    """A benchmark's ``[balance]`` problem (PB1 or PB2), posed for another starting linkage.

    The spec is written out and read back, so the problem is validated against the new linkage
    exactly as a designer's file would be.
    """
    design = replace(load_design(problem_spec), mechanism=linkage, title=title)
    design = loads_design(dumps_design(design), source=f"{problem_spec.name} from {title}")
    result = optimize(design, backend="nlp")
    return design, result


def reaction_sum_level(traj) -> float:
    """Largest |R̄A0 + R̄A3| relative to the largest individual reaction."""
    scale = traj.largest_reaction
    return float(np.max(np.abs(traj.shaking_force)) / scale)


def figure_fig9(traj) -> Figure:
    """Fig. 9: reaction components of the force-balanced linkage and their sums."""
    fig = Figure(figsize=(7, 4), layout="constrained")
    ax = fig.add_subplot()
    plot_reactions(traj, ax=ax, title="Fig. 9: reactions of the force-balanced linkage, "
                   "free motion (sums: black)")
    ax.legend(fontsize="small", ncol=3, loc="lower left")
    return fig


def figure_comparison(analyses: dict) -> Figure:
    """Shaking force, shaking moment and driving torque over a revolution, per design."""
    fig = Figure(figsize=(8, 8.5), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    for name, cycle in analyses.items():
        deg = np.degrees(cycle.theta1)
        r = cycle.reactions
        style = {"color": DESIGN_COLOURS[name], "lw": 1.8 if name == "complete" else 1.4}
        axes[0].plot(deg, np.abs(r.shaking_force), label=name, **style)
        axes[1].plot(deg, r.shaking_moment, label=name, **style)
        axes[2].plot(deg, r.driving_torque, label=name, **style)
    axes[0].set_ylabel("|shaking force| (N)")
    axes[1].set_ylabel("shaking moment about A0 (N·m)")
    axes[2].set_ylabel("driving torque (N·m)")
    axes[2].set_xlabel("crank angle θ1 (°)")
    axes[2].set_xticks(np.arange(0, 361, 60))
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize="small", ncol=2)
    fig.suptitle(f"Meijaard & van der Wijk (2020) example without loads, crank at "
                 f"{SPEED:g} rad/s: four designs")
    return fig


def run(out_dir: Path, quick: bool = False) -> dict:
    """Run the study and write its figures and ``report.md`` into ``out_dir``.

    ``quick`` simulates 1 s instead of 5 s with fewer output times.
    """
    start = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    original = load_design(EXAMPLES / "meijaard2020.toml").mechanism.without_loads()
    balanced = force_balanced_by_crank_and_rocker(original)
    settings = replace(FREE, duration=1.0) if quick else FREE
    outputs = 101 if quick else 501
    free = {m: simulate(balanced, settings, method=m, rtol=RTOL, atol=ATOL, outputs=outputs)
            for m in METHODS}
    sum_levels = {m: reaction_sum_level(t) for m, t in free.items()}

    pb1, moment_result = balanced_from(EXAMPLES / "pb1.toml", balanced,
                                       "force-balanced Eq. 56, shaking moment minimised")
    pb2, complete_result = balanced_from(EXAMPLES / "pb2.toml", balanced,
                                         "force-balanced Eq. 56, complete balance")
    # PB1 itself (from the paper's design): the same problem apart from the starting design,
    # which only decides the tie-break among optimal designs.
    pb1_rms = math.sqrt(optimize(load_design(EXAMPLES / "pb1.toml"), backend="convex").objective)
    designs = {
        "original": original,
        "force-balanced": balanced,
        "moment-minimised": moment_result.linkage,
        "complete": complete_result.linkage,
    }
    analyses = {name: cycle_analysis(linkage, SPEED, SAMPLES) for name, linkage in
                designs.items()}
    # The complete design in the free motion of Sect. 5.2, against the original's.
    free_complete = simulate(designs["complete"], settings, method="opened-loop", rtol=RTOL,
                             atol=ATOL, outputs=outputs)
    free_original = simulate(original, settings, method="opened-loop", rtol=RTOL, atol=ATOL,
                             outputs=outputs)
    figures = [
        save_png(figure_fig9(free["opened-loop"]), out_dir / "fig9_reactions.png"),
        save_png(figure_comparison(analyses), out_dir / "comparison.png"),
    ]
    summary = {name: {key: getattr(a.summary, key).rms for key in
                      ("shaking_force", "shaking_moment", "driving_torque")}
               for name, a in analyses.items()}
    results = {
        "reaction_sum_level": max(sum_levels.values()),
        "reaction_sum_levels": sum_levels,
        "force_balance_error": force_balance_error(balanced),
        "rms": summary,
        "moment_status": str(moment_result.status),
        "complete_status": str(complete_result.status),
        "complete_berkof": berkof_residuals(designs["complete"]).max(),
        "pb1_rms": pb1_rms,
        "moment_ratio": summary["moment-minimised"]["shaking_moment"]
        / summary["force-balanced"]["shaking_moment"],
        "complete_ratio": summary["complete"]["shaking_moment"]
        / summary["original"]["shaking_moment"],
        "free_complete_moment": float(np.max(np.abs(free_complete.shaking_moment))),
        "free_original_moment": float(np.max(np.abs(free_original.shaking_moment))),
        "figures": figures,
    }
    results["seconds"] = time.perf_counter() - start
    write_report(out_dir / "report.md", designs, free, settings, results,
                 (moment_result, complete_result))
    return results


def _link_rows(designs: dict) -> list[list[str]]:
    rows = []
    for name, linkage in designs.items():
        for link_name in linkage.link_names:
            link = linkage.link(link_name)
            rows.append([name, link_name, f"{link.mass:.4g}", f"{link.s:.5g}",
                         f"{link.sigma:.5g}", f"{link.inertia:.5g}",
                         f"{link.counter_rotor:.5g}"])
    return rows


def write_report(path: Path, designs, free, settings, results, optimised) -> None:
    moment_result, complete_result = optimised
    levels = markdown_table(
        ["formulation", "max abs(RA0 + RA3) / max reaction", "energy error"],
        [[m, f"{results['reaction_sum_levels'][m]:.1e}", f"{free[m].energy_error:.1e}"]
         for m in METHODS],
    )
    rms = results["rms"]
    comparison = markdown_table(
        ["design", "RMS shaking force (N)", "RMS shaking moment (N·m)",
         "RMS driving torque (N·m)"],
        [[name, f"{v['shaking_force']:.4g}", f"{v['shaking_moment']:.4g}",
          f"{v['driving_torque']:.4g}"] for name, v in rms.items()],
    )
    links = markdown_table(
        ["design", "link", "m (kg)", "s (m)", "σ (rad)", "I (kg·m²)", "counter-rotor (kg·m²)"],
        _link_rows(designs),
    )
    fb = designs["force-balanced"]
    text = f"""# Meijaard & van der Wijk (2020), Sect. 5.2: the force-balanced example

Source: J. P. Meijaard, V. van der Wijk, *Principal vectors and equivalent mass descriptions for
the equations of motion of planar four-bar linkages*, Multibody System Dynamics (2020),
Sect. 5.2 and Fig. 9.

## Fig. 9: the force-balanced linkage in free motion

The linkage of Eq. 56 without loads; the centres of mass of crank and rocker are moved so that
Eq. 57 holds
(`balancer.mechanisms.fourbar.conditions.force_balanced_by_crank_and_rocker`; the paper does not
print the values it used, these are the ones Eq. 57 gives with the masses and the coupler kept):
s1 = {fb.crank.s:.6g} m, σ1 = {fb.crank.sigma:.6g} rad, s3 = {fb.rocker.s:.6g} m,
σ3 = {fb.rocker.sigma:.6g} rad (Eq. 57 residual {results['force_balance_error']:.1e} of the
total mass). Free motion from θ1 = {settings.theta1:g} rad, θ̇1 = {settings.omega1:g} rad/s over
{settings.duration:g} s (rtol {RTOL:g}).

The paper: the sums of the reaction components are "zero up to truncation errors in the
numerics". Here, per formulation:

{levels}

## Balancing further: shaking moment, then complete balance

- *moment-minimised*: the `[balance]` problem of `examples/pb1.toml` (crank and rocker mass
  1×–4× the paper's, centre of mass within the link's length of its ground pivot, radius of
  gyration ≥ 0.1·l, counter-rotors 0–20 kg·m²; exact force balance; RMS shaking moment at
  {SPEED:g} rad/s minimised) posed for the force-balanced linkage. Status:
  {moment_result.status}, gap {moment_result.gap:.1e}. The coupler is fixed and its centre of
  mass is off the line A1A2, so the shaking moment cannot vanish.
- *complete*: the problem of `examples/pb2.toml` (the coupler free too). Status:
  {complete_result.status}, gap {complete_result.gap:.1e}; largest residual of Berkof's
  conditions (Sect. 5.2: f2 = 0, I2 = m2·e2·(l2 − e2), counter-rotors) of the result:
  {results['complete_berkof']:.1e}.

RMS over one revolution at a constant {SPEED:g} rad/s ({SAMPLES} crank angles):

{comparison}

The moment-minimised design has {results['moment_ratio']:.3g} of the force-balanced one's RMS
shaking moment, the same optimum ({rms['moment-minimised']['shaking_moment']:.6g} N·m) as
benchmark PB1 posed for the paper's own design ({results['pb1_rms']:.6g} N·m): the starting
design only decides which of the equally good designs is returned. The complete one has
{results['complete_ratio']:.1e} of the original's. In the free motion above (θ̇1 = 1 rad/s) the
complete design's largest shaking moment is {results['free_complete_moment']:.1e} N·m against
{results['free_original_moment']:.3g} N·m for the original (opened-loop formulation).

### The designs

{links}

s, σ: centre of mass from the link's first joint in the link frame; I about the centre of mass.

## Figures

- `fig9_reactions.png`: reaction components at A0 and A3 and their sums (their Fig. 9).
- `comparison.png`: shaking force, shaking moment and driving torque over one revolution at
  {SPEED:g} rad/s for the four designs.

Generated by `python studies/{NAME}.py` in {results['seconds']:.1f} s.
"""
    path.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    res = run(Path(__file__).parent / "out" / NAME)
    print(f"{NAME}: reaction sum {res['reaction_sum_level']:.1e} of the reactions; RMS shaking "
          f"moment original {res['rms']['original']['shaking_moment']:.4g}, force-balanced "
          f"{res['rms']['force-balanced']['shaking_moment']:.4g}, moment-minimised "
          f"{res['rms']['moment-minimised']['shaking_moment']:.4g}, complete "
          f"{res['rms']['complete']['shaking_moment']:.2e} N·m; {res['seconds']:.1f} s")
