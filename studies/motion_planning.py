"""Motion as a balancing lever: the planner's closed forms, its convergence, and what it buys.

Source: the rest-to-rest closed forms of a mass moved ``D`` in ``T`` (the least RMS
acceleration is the cubic's ``√12·D/T²``, the least peak the bang-bang's ``4·D/T²``: the
calculus of variations, and Pontryagin's principle for the double integrator); the convex
transcription of a path's time law of Verscheure, Demeulenaere, Swevers, De Schutter & Diehl,
"Time-optimal path tracking for robots: a convex optimization approach", IEEE Trans. Autom.
Control 54(10), 2009; the Forbal-2 robot of Vyas & Bottin (2025) and the servo press of
``examples/``.

What it reproduces and asks:

1. **The closed forms, at the transcription's order.** A carriage of mass ``M`` moved ``D`` in
   ``T`` along a straight guide (its shaking force ``M·a``), planned for the least RMS and the
   least peak shaking force on meshes of 8 to 256 intervals: the optimum's error against the
   closed form and its observed order — second for the mean square, first for the peak (the
   bang-bang acceleration is discontinuous).
2. **Forbal-2's diamond** in its 4 s, planned for the least RMS shaking moment: the
   transcription's optimum as its mesh is refined, against the planned motion's own objective
   (the core along it, by quadrature); and what the masses (the spec's ``[balance]``), the time
   law and both together buy (``plan --with-masses``).
3. **The servo press** (one input): what its crank counterweight, the crank's varying speed
   and both buy.

Run ``python studies/motion_planning.py [--out DIR] [--quick]``; it writes its figures and
``report.md`` into ``studies/out/motion_planning/`` (or ``DIR``).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from balancer import PlanSpec, PlanWeights, codesign, load_design, loads_design, plan
from balancer.plots import COLOURS, SERIES, save_png
from balancer.report import markdown_table

NAME = "motion_planning"
REPORT = "report.md"
ROOT = Path(__file__).resolve().parent.parent
#: The carriage: its mass (kg), stroke (m) and the stroke's duration (s).
MASS, STROKE, DURATION = 2.0, 0.3, 1.0
CARRIAGE = f"""
title = "A carriage on a straight guide, moved from rest to rest"
[mechanism]
type = "linkage"
inputs = ["carriage", "spindle"]
[mechanism.points]
A = [0.0, 0.0]
S = [0.5, 0.2]
T = [0.6, 0.2]
[[mechanism.sliders]]
link = "carriage"
guide = "ground"
point = "A"
direction = [1.0, 0.0]
[links.ground]
points = ["S"]
[links.carriage]
points = ["A"]
mass = {MASS}
inertia = 0.01
com = {{ e = 0.0, f = 0.0 }}
[links.spindle]   # a second input held still: a disc turning about its centre of mass
points = ["S", "T"]
mass = 0.5
inertia = 0.002
com = {{ e = 0.0, f = 0.0 }}
[[motion]]
name = "stroke"
times = [0.0, {DURATION}]
path = [[0.0, 0.0], [{STROKE}, 0.0]]
law = "cubic"
"""


def closed_forms(meshes: list[int]) -> dict:
    """Section 1: each measure's optimum against its closed form on each mesh."""
    design = loads_design(CARRIAGE)
    exact = {"rms": math.sqrt(12.0) * MASS * STROKE / DURATION**2,
             "peak": 4.0 * MASS * STROKE / DURATION**2}
    out: dict = {"meshes": meshes, "exact": exact}
    for measure in ("rms", "peak"):
        errors, bounds = [], []
        for n in meshes:
            result = plan(design, settings=PlanSpec(objective=PlanWeights(
                shaking_moment=0.0, shaking_force=1.0), measure=measure, intervals=n))
            errors.append(abs(math.sqrt(result.solution.objective) / exact[measure] - 1.0))
            assert result.bound is not None
            bounds.append(math.sqrt(result.bound))
        e = np.asarray(errors)
        out[measure] = {"errors": errors, "orders": list(np.log2(e[:-1] / e[1:])),
                        "bound": bounds[0]}
    return out


def forbal(meshes: list[int]) -> dict:
    """Section 2: Forbal-2's diamond on refined meshes, and the two levers."""
    design = load_design(ROOT / "examples" / "forbal2.toml")
    assert design.plan is not None
    rows = []
    for n in meshes:
        result = plan(design, settings=replace(design.plan, intervals=n))
        rows.append({"intervals": n, "transcription": math.sqrt(result.solution.objective),
                     "planned": math.sqrt(result.objective_after),
                     "certified": result.certified})
    together = codesign(design, settings=replace(design.plan, intervals=meshes[-1]))
    return {"rows": rows, "before": math.sqrt(result.objective_before), "last": result,
            "levers": {k: math.sqrt(v) for k, v in together.objectives.items()},
            "rounds": (len(together.rounds) - 1) // 2}


def press(intervals: int) -> dict:
    """Section 3: the servo press's levers."""
    design = load_design(ROOT / "examples" / "servo_press.toml")
    assert design.plan is not None
    together = codesign(design, settings=replace(design.plan, intervals=intervals))
    loads = {k: a.loads() for k, a in together.analyses.items()}
    return {"levers": {k: math.sqrt(v) for k, v in together.objectives.items()},
            "force": {k: v["shaking_force"].rms for k, v in loads.items()},
            "torque": {k: v["torque_crank"].rms for k, v in loads.items()}}


def convergence_figure(r: dict, out: Path) -> Path:
    """Each measure's error against the intervals, beside the slopes of orders 1 and 2."""
    fig = Figure(figsize=(6.5, 4.5), layout="constrained")
    ax = fig.subplots()
    n = np.asarray(r["meshes"], dtype=float)
    for i, (measure, words) in enumerate((("rms", "least RMS: the cubic's √12·D/T²"),
                                          ("peak", "least peak: the bang-bang's 4·D/T²"))):
        errors = np.asarray(r[measure]["errors"])
        ax.loglog(n, errors, "o-", color=SERIES[i], label=words)
        order = 2 if measure == "rms" else 1
        ax.loglog(n, errors[0] * (n[0] / n) ** order, "--", color=COLOURS["before"],
                  lw=0.8, label=f"order {order}")
    ax.set_xlabel("intervals of the transcription")
    ax.set_ylabel("relative error of the optimum")
    ax.set_title("A carriage moved from rest to rest: the planner against the closed forms")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return save_png(fig, out / "convergence.png")


def run(out_dir: Path, quick: bool = False) -> dict:
    """Run the study into ``out_dir``; its numbers (``quick``: coarser meshes)."""
    start = time.perf_counter()
    out_dir.mkdir(parents=True, exist_ok=True)
    meshes = [8, 16, 32, 64] if quick else [8, 16, 32, 64, 128, 256]
    r: dict = {"closed": closed_forms(meshes), "quick": quick}
    r["forbal"] = forbal([50, 100] if quick else [50, 100, 200, 400])
    r["press"] = press(60 if quick else 240)
    r["figures"] = [convergence_figure(r["closed"], out_dir)]
    r["seconds"] = time.perf_counter() - start
    write_report(r, out_dir / REPORT)
    return r


def write_report(r: dict, path: Path) -> None:
    """The study's ``report.md``."""
    closed = r["closed"]
    rows = [[str(n), f"{e_rms:.2e}", f"{o_rms:.2f}" if o_rms is not None else "",
             f"{e_peak:.2e}", f"{o_peak:.2f}" if o_peak is not None else ""]
            for n, e_rms, o_rms, e_peak, o_peak in zip(
                closed["meshes"], closed["rms"]["errors"], [None, *closed["rms"]["orders"]],
                closed["peak"]["errors"], [None, *closed["peak"]["orders"]], strict=True)]
    forbal_rows = [[str(x["intervals"]), f"{x['transcription']:.6g}", f"{x['planned']:.6g}",
                    "yes" if x["certified"] else "no"] for x in r["forbal"]["rows"]]
    words = {"spec": "as specified", "masses": "the masses alone",
             "motion": "the time law alone", "both": "both"}

    def levers(d: dict) -> str:
        base = d["spec"]
        return markdown_table(["lever", "√J", "change"],
                              [[words[k], f"{v:.6g}", "—" if k == "spec" else
                                f"{100 * (v / base - 1):+.1f} %"] for k, v in d.items()])

    quick = " (quick settings: coarser meshes)" if r["quick"] else ""
    text = f"""# Motion as a balancing lever

Source: the rest-to-rest closed forms of a mass moved D in T (least RMS acceleration the
cubic's √12·D/T², least peak the bang-bang's 4·D/T²); the convex transcription of Verscheure et
al. (IEEE TAC 54(10), 2009); the Forbal-2 robot (Vyas & Bottin 2025) and the servo press of
`examples/`{quick}.

## 1. The closed forms at the transcription's order

A carriage of {MASS} kg moved {STROKE} m in {DURATION} s from rest to rest: least RMS shaking force
{closed['exact']['rms']:.6g} N (the planner's closed-form bound: {closed['rms']['bound']:.6g} N),
least peak {closed['exact']['peak']:.6g} N. The optimum's relative error and the observed order
between successive meshes:

{markdown_table(["intervals", "RMS error", "order", "peak error", "order"], rows)}

The mean square converges at second order (the trapezoid rule on a smooth optimum), the peak at
first (the bang-bang acceleration jumps; the pace holds it constant between rows).

![convergence](convergence.png)

## 2. Forbal-2's diamond, planned for the least RMS shaking moment

√J (N·m) of the spec's trapezoid law: {r['forbal']['before']:.6g}. The transcription's optimum
and the planned motion's own √J (the core along it, by quadrature) as the mesh is refined:

{markdown_table(["intervals", "transcription", "planned motion", "certified global"],
                forbal_rows)}

The path's curvature jumps at the diamond's corners, where the optimum's pace changes fastest:
the transcription converges there more slowly than on a smooth path. With the masses of the
spec's `[balance]` ({r['forbal']['rounds']} rounds):

{levers(r['forbal']['levers'])}

## 3. The servo press

Its crank counterweight (`[balance]`), the crank's speed over the stroke (`[plan]`, within 1.6
times the mean) and both, for the RMS shaking force with the servo's torque weighed a little:

{levers(r['press']['levers'])}

RMS shaking force (N): {', '.join(f"{words[k]} {v:.4g}" for k, v in r['press']['force'].items())};
RMS servo torque (N·m): {', '.join(f"{words[k]} {v:.4g}" for k, v in r['press']['torque'].items())}.

Study run in {r['seconds']:.1f} s.
"""
    path.write_text(text, encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    """``python studies/motion_planning.py [--out DIR] [--quick]``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "out" / NAME,
                        help="output folder (default studies/out/motion_planning)")
    parser.add_argument("--quick", action="store_true", help="coarser meshes")
    args = parser.parse_args(argv)
    r = run(args.out, quick=args.quick)
    orders = r["closed"]
    print(f"{NAME}: RMS order {orders['rms']['orders'][-1]:.2f}, peak order "
          f"{orders['peak']['orders'][-1]:.2f}; Forbal-2 both levers "
          f"{r['forbal']['levers']['both']:.6g} N·m; {r['seconds']:.1f} s; "
          f"wrote {args.out / REPORT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
