"""Presentation of results: readable tables, JSON documents and CSV files.

Computation lives elsewhere; this module only turns result objects into text. The JSON field
names that other tools rely on are fixed in DESIGN.md.
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from .balance.counterweights import UNCHANGED, Counterweight, link_scales
from .balance.front import FIGURES, Front
from .cycle import CycleAnalysis, Figure
from .errors import SolverError
from .orders import order_name
from .rounding import Scales, speed_text
from .rounding import figure_text as _fmt

if TYPE_CHECKING:  # annotations only (no cycle): the commands that make these load them
    from .balance.result import BalanceResult, RotorMasses
    from .model import Link
    from .model.mechanisms import ThrowBalance
    from .simulation import Trajectory
    from .verification import Verification

UNITS = {"shaking_force": "N", "shaking_moment": "N·m", "driving_torque": "N·m",
         "rocking_couple": "N·m", "mount_torque": "N·m"}


def table(rows: Sequence[Sequence[str]], header: Sequence[str]) -> str:
    """A plain text table: first column left-aligned, the others right-aligned."""
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    lines = []
    for r in [header, *rows]:
        cells = [
            str(c).ljust(w) if i == 0 else str(c).rjust(w)
            for i, (c, w) in enumerate(zip(r, widths, strict=True))
        ]
        lines.append("  ".join(cells).rstrip())
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A GitHub-flavoured markdown table (first column left-aligned, the others right)."""
    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join([":---"] + ["---:"] * (len(header) - 1)) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def reaction_extremes(values: np.ndarray) -> dict[str, float]:
    """Magnitude maximum and component extremes of a complex force history, N.

    Unbounded values (NaN, at the change points of a change-point linkage) are left out.
    """
    values = values[~np.isnan(values)]
    return {
        "max": float(np.max(np.abs(values))),
        "x_min": float(np.min(values.real)),
        "x_max": float(np.max(values.real)),
        "y_min": float(np.min(values.imag)),
        "y_max": float(np.max(values.imag)),
    }


def figures_dict(analysis: CycleAnalysis) -> dict[str, dict[str, float]]:
    """The three fixed figures ``shaking_force``, ``shaking_moment``, ``driving_torque``."""
    return analysis.summary.as_dict()


def _orders_list(analysis: CycleAnalysis) -> list[dict[str, Any]]:
    """The ``orders`` table (DESIGN.md's names; :mod:`balancer.orders`)."""
    return [order.as_dict() for order in analysis.orders]


def analysis_figures(analysis: CycleAnalysis) -> list[tuple[str, float]]:
    """Every figure of a cycle analysis under its unit, for :class:`Scales`.

    The shaking, the driving and mount torques and the rocking couple (RMS and maximum), the
    forces on the frame at each ground point and guide, the guides' couples, every order.
    """
    s = analysis.summary
    out: list[tuple[str, float]] = []
    for name in ("shaking_force", "shaking_moment", "driving_torque", "rocking_couple",
                 "mount_torque"):
        fig = getattr(s, name)
        if fig is not None:
            out += [(UNITS[name], fig.rms), (UNITS[name], fig.max)]
    out += [("N", f.max) for f in (*s.ground.values(), *s.slider_normal.values())]
    out += [("N·m", f.max) for f in s.slider_couple.values()]
    for o in analysis.orders:
        out += [("N", abs(v)) for v in o.shaking_force.as_dict().values()]
        out += [("N·m", abs(v)) for v in (*o.rocking_couple.as_dict().values(),
                                           o.shaking_moment, o.driving_torque)]
        if o.mount_torque is not None:
            out.append(("N·m", abs(o.mount_torque)))
    return out


def orders_text(analysis: CycleAnalysis, scales: Scales | None = None) -> str:
    """The order table of ``analyze``: amplitudes by multiple of the crank speed.

    ``scales``: the report's (:class:`Scales`; default the analysis' own figures).
    """
    sc = scales if scales is not None else Scales(analysis_figures(analysis))
    planes = not analysis.mechanism.in_one_plane()
    rows = []
    for o in analysis.orders:
        f = o.shaking_force
        row = [order_name(o.order), *(sc.fmt(v, "N") for v in (f.x, f.y, f.forward, f.backward)),
               sc.fmt(o.shaking_moment, "N·m"), sc.fmt(o.driving_torque, "N·m")]
        if o.mount_torque is not None:
            row.append(sc.fmt(o.mount_torque, "N·m"))
        if planes:
            row += [sc.fmt(o.rocking_couple.forward, "N·m"),
                    sc.fmt(o.rocking_couple.backward, "N·m")]
        rows.append(row)
    head = ["order", "force x (N)", "force y (N)", "forward (N)", "backward (N)",
            "moment (N·m)", "torque (N·m)"]
    if analysis.mount_torque is not None:
        head.append("mount (N·m)")
    if planes:
        head += ["couple fwd (N·m)", "couple bwd (N·m)"]
    return ("orders (peak amplitudes; order 0 the mean; forward turns with the crank, backward "
            "against it):\n" + table(rows, head))


def analysis_json(analysis: CycleAnalysis, spec: str | None = None) -> dict[str, Any]:
    """The ``analyze --json`` document."""
    mech = analysis.mechanism
    balanced, residual = analysis.force_balanced, analysis.force_balance_residual
    doc: dict[str, Any] = {}
    if spec is not None:
        doc["spec"] = spec
    doc.update(
        {
            "mechanism": mech.kind,
            "class": mech.describe(),
            **({"branch": mech.branch} if mech.branch is not None else {}),
            "speed": analysis.speed,
            "samples": int(analysis.samples_per_revolution),
            "route": analysis.route,
            # Always [gx, gy] (one type for a reader): [0, 0] when the figures include none.
            "gravity": [float(g) for g in analysis.gravity],
            **figures_dict(analysis),
            "force_balanced": balanced,
            "force_balance_residual": {"relative": residual},
            "centre_of_mass_excursion": analysis.centre_of_mass_excursion,
            "reactions": _reactions_dict(analysis),
            "change_points": _change_points(analysis),
            "orders": _orders_list(analysis),
            "units": {
                "force": "N",
                "moment": "N·m",
                "speed": "rad/s",
                "gravity": "m/s²",
                "force_balance_residual": "dimensionless (first moments left over, over those "
                                          "that make them)",
                "centre_of_mass_excursion": "m (largest distance of the total centre of mass "
                                            "from its mean place over the cycle)",
            },
        }
    )
    return doc


def _reactions_dict(analysis: CycleAnalysis) -> dict[str, dict[str, float]]:
    """Extremes of the force at each ground point; each ground slider's normal force, couple."""
    r, s = analysis.reactions, analysis.summary
    out: dict[str, dict[str, float]] = {p: reaction_extremes(v) for p, v in r.ground.items()}
    for link in r.slider_normal:
        out[link] = {"max": s.slider_normal[link].max, "couple_max": s.slider_couple[link].max}
    return out


def _change_points(analysis: CycleAnalysis) -> list[float]:
    """Sampled crank angles (rad) at which the individual reactions are unbounded."""
    if analysis.singular is None:
        return []
    return [float(t) for t in analysis.theta1[analysis.singular]]


def analysis_text(analysis: CycleAnalysis, spec: str | None = None) -> str:
    """The readable ``analyze`` report."""
    mech = analysis.mechanism
    s = analysis.summary
    sc = Scales(analysis_figures(analysis))
    head = f"balancer analyze — {spec}" if spec else "balancer analyze"
    per_cycle = (f" over a cycle of 720° ({analysis.samples} in all)"
                 if analysis.revolutions == 2 else "")
    lines = [
        head,
        f"{mech.kind} ({mech.describe()}), {analysis.samples_per_revolution} crank angles per "
        f"revolution{per_cycle} at {speed_text(analysis.speed)}, {analysis.route} route"
        + (f"; gravity ({analysis.gravity[0]:g}, {analysis.gravity[1]:g}) m/s² included"
           if any(analysis.gravity) else "; gravity not included")
        + ("" if analysis.loads else "; loads left out"),
        "",
        table(
            [
                [name.replace("_", " "), sc.fmt(fig.rms, UNITS[name]),
                 sc.fmt(fig.max, UNITS[name]), UNITS[name]]
                for name, fig in (
                    ("shaking_force", s.shaking_force),
                    ("shaking_moment", s.shaking_moment),
                    ("driving_torque", s.driving_torque),
                    *((("rocking_couple", s.rocking_couple),)
                      if not analysis.mechanism.in_one_plane() else ()),
                    *((("mount_torque", s.mount_torque),) if s.mount_torque is not None
                      else ()),
                )
            ],
            ["quantity", "RMS", "max", "unit"],
        ),
        "",
    ]
    rows = []
    for point, values in analysis.reactions.ground.items():
        ex = reaction_extremes(values)
        rows.append([f"R{point}",
                     *(sc.fmt(ex[k], "N") for k in ("max", "x_min", "x_max", "y_min", "y_max"))])
    lines.append(
        table(rows, ["reaction (N)", "|R| max", "Rx min", "Rx max", "Ry min", "Ry max"])
    )
    if analysis.reactions.slider_normal:
        rows = [[link, sc.fmt(s.slider_normal[link].max, "N"),
                 sc.fmt(s.slider_couple[link].max, "N·m")]
                for link in analysis.reactions.slider_normal]
        lines += ["", table(rows, ["slider on the frame", "normal force max (N)",
                                   "couple max (N·m)"])]
    lines += ["", orders_text(analysis, sc)]
    lines.append("")
    points = _change_points(analysis)
    if points:
        where = ", ".join(f"{math.degrees(t):g}°" for t in points)
        lines += [
            f"change point at θ1 = {where}: all joints collinear; the individual reactions are "
            "unbounded there and left out of their extremes (shaking force, moment and torque "
            "are the limits of the smooth motion)",
            "",
        ]
    lines.append(_force_balance_line(analysis))
    return "\n".join(lines)


def _force_balance_line(analysis: CycleAnalysis) -> str:
    """Whether the design is force-balanced, in words a designer pictures."""
    balanced, residual = analysis.force_balanced, analysis.force_balance_residual
    if balanced:
        return ("force-balanced: yes (the total centre of mass stands still; "
                f"{analysis.mechanism.force_balance_source} hold to {residual:.1e} of the "
                "links' first moments)")
    excursion = analysis.centre_of_mass_excursion
    return ("force-balanced: no (the total centre of mass moves up to "
            f"{_length(excursion)} from its mean place over a revolution)")


def _length(metres: float) -> str:
    """A length for a reader: mm below a metre, else m."""
    if abs(metres) < 1.0:
        return f"{1e3 * metres:.4g} mm"
    return f"{metres:.4g} m"


def dumps_json(doc: dict[str, Any]) -> str:
    """JSON text with a trailing newline; NaN and infinity are not allowed.

    Raises
    ------
    SolverError
        Naming the first field that holds NaN or infinity (a computation that failed; strict
        JSON has no such numbers, and a reader must not get them).
    """
    where = _nonfinite(doc, "")
    if where is not None:
        raise SolverError(f"the results are not finite numbers (at {where}): the computation "
                          "lost its precision")
    import json  # here: a table needs no JSON

    return json.dumps(doc, indent=2, allow_nan=False) + "\n"


def _nonfinite(value: Any, path: str) -> str | None:
    """The path of the first NaN or infinity in a JSON-like document, or ``None``."""
    if isinstance(value, float):
        return None if math.isfinite(value) else (path or "the top")
    if isinstance(value, dict):
        for key, item in value.items():
            found = _nonfinite(item, f"{path}.{key}" if path else str(key))
            if found is not None:
                return found
    elif isinstance(value, list | tuple):
        for i, item in enumerate(value):
            found = _nonfinite(item, f"{path}[{i}]")
            if found is not None:
                return found
    return None


def analysis_csv(analysis: CycleAnalysis) -> str:
    """Per-angle values of a cycle analysis as CSV text (SI units, full precision)."""
    return csv_text(*analysis.columns())


def csv_text(columns: Sequence[str], values: Sequence[np.ndarray]) -> str:
    """CSV with a header row; numbers written so that they read back exactly.

    A value that does not exist (a reaction at the change point of a change-point linkage,
    unbounded there) is an empty cell, never a literal ``nan``.
    """
    data = np.column_stack([np.broadcast_to(np.asarray(v, dtype=float), np.shape(values[0]))
                            for v in values])
    buf = io.StringIO()
    np.savetxt(buf, data, delimiter=",", fmt="%.17g")
    lines = buf.getvalue().splitlines()
    for i in np.flatnonzero(~np.isfinite(data).all(axis=1)):
        lines[i] = ",".join("" if not np.isfinite(x) else cell
                            for x, cell in zip(data[i], lines[i].split(","), strict=True))
    return "\n".join([",".join(columns), *lines]) + "\n"


# ----------------------------------------------------------------------------------------------
# simulate

def simulation_csv(traj: Trajectory, all_columns: bool = False) -> str:
    """The time histories of a simulation as CSV text (:meth:`Trajectory.columns`)."""
    return csv_text(*traj.columns(all_columns))


def simulation_json(traj: Trajectory, spec: str | None = None) -> dict[str, Any]:
    """The ``simulate --json`` document."""
    doc: dict[str, Any] = {}
    if spec is not None:
        doc["spec"] = spec
    doc.update(
        {
            "method": traj.method,
            "drive": traj.drive,
            **({"speed": traj.speed} if traj.speed is not None else {}),
            "duration": float(traj.t[-1]),
            "outputs": int(traj.t.size),
            "rtol": traj.rtol,
            "atol": traj.atol,
            "initial": traj.state(0),
            "final": traj.state(-1),
            "steps": traj.steps,
            "nfev": traj.nfev,
            "seconds": traj.seconds,
            "energy_error": traj.energy_error,
            "constraint_drift": {"position": traj.drift[0], "velocity": traj.drift[1]},
            "shaking_force": Figure.of(traj.shaking_force).as_dict(),
            "shaking_moment": Figure.of(traj.shaking_moment).as_dict(),
            "driving_torque": Figure.of(traj.driving_torque).as_dict(),
            "reactions": {
                **{p: reaction_extremes(v) for p, v in traj.ground.items()},
                **{link: {"max": Figure.of(traj.slider_normal[link]).max,
                          "couple_max": Figure.of(traj.slider_couple[link]).max}
                   for link in traj.slider_normal}},
            **({"slider": {"initial": [float(v) for v in traj.slider[:, 0]],
                           "final": [float(v) for v in traj.slider[:, -1]]}}
               if traj.slider is not None else {}),
            "units": {"theta": "rad", "omega": "rad/s", "alpha": "rad/s²", "speed": "rad/s",
                      "force": "N",
                      "moment": "N·m", "constraint_drift": "m, m/s"},
        }
    )
    return doc


def simulation_text(traj: Trajectory, spec: str | None = None) -> str:
    """The readable ``simulate`` report: the paper's Table 1 quantities and the checks."""
    head = f"balancer simulate — {spec}" if spec else "balancer simulate"
    lines = [
        head,
        f"{traj.drive} motion"
        + (f" at {speed_text(traj.speed)}" if traj.speed is not None else "")
        + f" for {traj.t[-1]:g} s, formulation {traj.method}, rtol "
        f"{traj.rtol:g}: {traj.steps} steps, {traj.nfev} right-hand sides, {traj.seconds:.3g} s",
        "",
    ]
    # Each column's scale: the largest of its states (an angle's at least π: on the circle).
    states = ("rad", "rad/s", "rad/s²")
    sc = Scales([("rad", math.pi)])
    for unit, values in zip(states, (traj.theta, traj.omega, traj.alpha), strict=True):
        sc.add((unit, float(v)) for v in values[:, [0, -1]].ravel())
    rows = []
    for when, index in (("initial", 0), ("final", -1)):
        for k, name in enumerate(traj.links):
            label = name if traj.named_states else f"link {k + 1}"
            rows.append([f"{when} {label}",
                         *(sc.fmt(values[k, index], unit, 14) for unit, values in
                           zip(states, (traj.theta, traj.omega, traj.alpha), strict=True))])
    lines.append(table(rows, ["state", "θ (rad)", "θ̇ (rad/s)", "θ̈ (rad/s²)"]))
    lines.append("")
    figures = (("shaking_force", Figure.of(traj.shaking_force)),
               ("shaking_moment", Figure.of(traj.shaking_moment)),
               ("driving_torque", Figure.of(traj.driving_torque)))
    sc.add((UNITS[name], x) for name, fig in figures for x in (fig.rms, fig.max))
    sc.add([("N", traj.largest_reaction)])
    sc.add(("N·m", Figure.of(c).max) for c in traj.slider_couple.values())
    rows = [[name.replace("_", " "), sc.fmt(fig.rms, UNITS[name]), sc.fmt(fig.max, UNITS[name]),
             UNITS[name]] for name, fig in figures]
    lines.append(table(rows, ["quantity over time", "RMS", "max", "unit"]))
    lines.append("")
    lines.append(
        f"energy balance: kinetic energy change = work of loads, gravity and motor to "
        f"{traj.energy_error:.1e} (relative); loop-closure drift before projection "
        f"{traj.drift[0]:.1e} m, {traj.drift[1]:.1e} m/s"
    )
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# verify


def _verification_scales(verification: Verification) -> Scales:
    """The scales of ``verify``'s figures: both runs', the design's and the original's.

    Forces with the largest force on the frame of each run (the reactions the shaking force
    sums); moments with the rocking couples and the driving torque.
    """
    sc = Scales()
    for run in (verification.driven, verification.free):
        sc.add(("N", x) for x in (run.max_shaking_force, run.original_max_shaking_force))
        sc.add(("N·m", x) for x in (run.max_shaking_moment, run.original_max_shaking_moment,
                                    run.max_rocking_couple, run.original_max_rocking_couple))
        for traj in (run.trajectory, run.original):
            if traj is not None and traj.t.size:
                sc.add([("N", traj.largest_reaction),
                        ("N·m", float(np.max(np.abs(traj.driving_torque))))])
    return sc


def verification_text(verification: Verification, spec: str | None = None) -> str:
    """The readable ``verify`` report.

    A figure that is rounding of its quantity's scale is printed 0, a ratio of it ``0`` (or
    ``—`` where the original's is rounding too: :class:`Scales`).
    """
    head = f"balancer verify — {spec}" if spec else "balancer verify"
    driven = verification.driven.trajectory
    speed = (f"; driven at {speed_text(driven.speed)}"
             if driven is not None and driven.speed is not None else "")
    lines = [head, f"simulated with the {verification.method} formulation{speed}", ""]
    sc = _verification_scales(verification)

    def shown(x: float | None, unit: str) -> str:
        return "—" if x is None else sc.number(x, unit, ".4g")

    rows = []
    for name, run in (("driven at the operating speed", verification.driven),
                      ("free from the initial state", verification.free)):
        rows.append([name, shown(run.max_shaking_force, "N"),
                     shown(run.original_max_shaking_force, "N"),
                     sc.ratio(run.max_shaking_force, run.original_max_shaking_force, "N",
                              ".2e"),
                     "—" if run.force_level is None else format(run.force_level, ".1e"),
                     shown(run.max_shaking_moment, "N·m"),
                     shown(run.original_max_shaking_moment, "N·m"),
                     sc.ratio(run.max_shaking_moment, run.original_max_shaking_moment, "N·m",
                              ".2e")])
    lines.append(table(rows, ["motion", "max |ΣR| (N)", "original", "ratio", "of |R|",
                              "max |Msh| (N·m)", "original", "ratio"]))
    if any(r.max_rocking_couple for r in (verification.driven, verification.free)):
        rows = [[name, shown(run.max_rocking_couple, "N·m"),
                 shown(run.original_max_rocking_couple, "N·m"),
                 sc.ratio(run.max_rocking_couple, run.original_max_rocking_couple, "N·m",
                          ".2e")]
                for name, run in (("driven at the operating speed", verification.driven),
                                  ("free from the initial state", verification.free))]
        lines += ["", table(rows, ["motion", "max |Mrock| (N·m)", "original", "ratio"])]
    for name, run in (("driven", verification.driven), ("free", verification.free)):
        if run.note:
            lines.append(f"{name}: {run.note}")
        elif run.trajectory is not None:
            lines.append(f"{name}: energy balance to {run.trajectory.energy_error:.1e}, "
                         f"{run.trajectory.steps} steps over {run.trajectory.t[-1]:g} s")
    levels = [r.force_level for r in (verification.driven, verification.free)
              if r.force_level is not None]
    if levels and max(levels) < 1e-8:
        lines.append("the reaction sums vanish to integration-error level: force-balanced")
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# optimize


def link_parameters(link: Link) -> dict[str, float]:
    """A link's physical parameters for a report (SI units)."""
    return {
        "mass": link.mass,
        "inertia": link.inertia,
        "e": link.e,
        "f": link.f,
        "s": link.s,
        "sigma": link.sigma,
        "counter_rotor": link.counter_rotor,
    }


def optimization_json(result: BalanceResult, before: CycleAnalysis, after: CycleAnalysis,
                      verification: Verification | None = None, spec: str | None = None,
                      out: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """The ``optimize --json`` document.

    ``before``, ``after``, ``links``, ``status`` and ``verification`` are fixed names.
    """
    linkage = result.linkage
    doc: dict[str, Any] = {}
    if spec is not None:
        doc["spec"] = spec
    doc.update(
        {
            "backend": result.backend,
            "status": str(result.status),
            "success": result.success,
            "message": result.message,
            "before": _operating_figures(before),
            "after": _operating_figures(after),
            "warnings": worse_figures(before, after),
            # The inertial part alone, which the optimiser balances (loads and gravity left out).
            "inertial": {"before": result.before.summary.as_dict(),
                         "after": result.after.summary.as_dict()},
            "links": {name: link_parameters(linkage.link(name)) for name in linkage.link_names},
            "original_links": {name: link_parameters(result.original.link(name))
                               for name in linkage.link_names},
            "counterweights": {name: w.as_dict() for name, w in result.counterweights.items()},
            "added_mass": result.added_mass,
            **({} if result.rotor_masses is None else result.rotor_masses.as_dict()),
            "objective": result.objective,
            "objective_terms": _objective_terms(result),
            "original_objective": result.original_objective,
            "lower_bound": result.lower_bound,
            "gap": result.gap,
            "scale": result.scale,
            **({"rms": result.rms, "rms_lower_bound": result.rms_lower_bound,
                "rms_gap": result.rms_gap} if result.rms_form else {}),
            "relaxation_tight": result.relaxation_tight,
            "iterations": result.iterations,
            "time": result.time,
            "stages": [
                {"name": s.name, "converged": s.converged, "solver_status": s.solver_status,
                 "iterations": s.iterations, "time": s.time,
                 "objective": s.objective if math.isfinite(s.objective) else None}
                for s in result.stages
            ],
            "force_balanced": after.force_balanced,
            "force_balance_residual": after.force_balance_residual,
            "orders": {"before": _orders_list(before), "after": _orders_list(after)},
            "verification": None if verification is None else verification.as_dict(),
            "out": None if out is None else str(out),
            "units": {"objective, lower_bound": "(N·m)², the weighted mean squares of the "
                      "inertial shaking (J of [balance.objective])",
                      "objective_terms": "each term's RMS in its 'unit' (N for a force, N·m "
                      "for a moment or torque; added_mass: kg added)",
                      "max_ground_reaction": "N",
                      "gap": "relative to scale (of √J when rms is given, else of J)",
                      "scale, rms, rms_lower_bound, rms_gap": "N·m", "time": "s",
                      "mass, added_mass": "kg", "inertia": "kg·m²", "e, f, s": "m",
                      **({} if result.rotor_masses is None else {
                          "mr": "kg·m", "phase_deg": "degrees at θ1 = 0", "z, at": "m",
                          "max_bearing_load": "N"}),
                      "sigma": "rad", "disc radius, thickness": "m",
                      **({} if result.rotor_masses is None else {
                          "rotating_mr, reciprocating_mr, counterweight_mr": "kg·m",
                          "factor": "dimensionless: counterweight_mr / (rotating_mr + "
                                    "reciprocating_mr/2)"})},
        }
    )
    factors = result.original.balance_factors(result.linkage)
    if factors is not None:  # an engine's (after the keys every document has)
        doc["balance_factors"] = {"before": [t.as_dict() for t in factors[0]],
                                  "after": [t.as_dict() for t in factors[1]]}
    return doc


#: A figure that balancing multiplies by more than this is reported as made worse.
WORSE_RATIO = 2.0
#: The figures watched for getting worse, with their names and units.
_WATCHED = (("shaking_force", "shaking force", "N"), ("shaking_moment", "shaking moment", "N·m"),
            ("driving_torque", "driving torque", "N·m"))


def _operating_figures(analysis: CycleAnalysis) -> dict[str, Any]:
    """``optimize``'s ``before``/``after``: the analyze figures and the largest ground load."""
    return {**analysis.summary.as_dict(),
            "max_ground_reaction": analysis.summary.max_ground_reaction}


def worse_figures(before: CycleAnalysis, after: CycleAnalysis) -> list[str]:
    """One sentence for each figure that the balanced design more than doubles.

    The RMS and maximum of the shaking force, shaking moment and driving torque, and the largest
    force at a ground point (:attr:`~balancer.cycle.CycleSummary.max_ground_reaction`), at the
    operating speed with the loads. A figure that was zero or rounding (:class:`Scales`: of its
    quantity's scale before and after) has no ratio: it is reported where it rises beyond
    rounding, not where it stays there.
    """
    out = []
    sc = Scales([*analysis_figures(before), *analysis_figures(after)])
    b, a = before.summary, after.summary
    figures = [(f"the {words}'s {'RMS' if stat == 'rms' else 'maximum'}", unit,
                getattr(getattr(b, name), stat), getattr(getattr(a, name), stat))
               for name, words, unit in _WATCHED for stat in ("rms", "max")]
    figures.append(("the largest force on a ground pivot or guide", "N", b.max_ground_reaction,
                    a.max_ground_reaction))
    for what, unit, old, new in figures:
        if sc.rounding(old, unit):
            if not sc.rounding(new, unit):
                out.append(f"{what} rises from 0 (to rounding) to {_fmt(new).strip()} {unit}")
        elif new > WORSE_RATIO * old:
            out.append(f"{what} rises {new / old:.3g}× "
                       f"({_fmt(old).strip()} → {_fmt(new).strip()} {unit})")
    return out


def _objective_terms(result: BalanceResult) -> dict[str, dict[str, float | str]]:
    """Each term of the objective: its weight and unit, its RMS before and after (inertial)."""
    before, after = result.term_rms(result.before), result.term_rms(result.after)
    return {t.name: {"weight": t.weight, "unit": t.unit, "before": before[t.name],
                     "after": after[t.name]} for t in result.weights.terms}


#: What each kind of counterweight asks of the workshop.
_COUNTERWEIGHT_KINDS = {
    "none": "unchanged",
    "add": "add this body",
    "remove": "remove this material",
    "rebuild": "rebuild the link as",
}


def counterweight_text(weights: Mapping[str, Counterweight]) -> str:
    """The counterweights as a table a workshop can build from (mm, kg, kg·m²).

    A body to add: its mass, centre and inertia about its centre; material to remove: the
    removed body's (its mass and inertia as positive numbers); a link to rebuild: the new
    link's own mass, centre of mass and inertia about it, never a difference that no body has.
    """
    rows = []
    for name, w in weights.items():
        disc = (f"Ø {2e3 * w.disc_radius:.4g} × {1e3 * w.disc_thickness:.4g}"
                if w.disc_radius is not None and w.disc_thickness is not None else "")
        if w.kind == "none":
            values: tuple[str, ...] = ("", "", "", "")
        else:
            if w.kind == "rebuild" and w.rebuilt is not None:
                mass, e, f, inertia = w.rebuilt
            else:
                sign = -1.0 if w.kind == "remove" else 1.0
                mass, e, f, inertia = sign * w.mass, w.e, w.f, sign * w.inertia
            # A component within rounding of the centre's distance is none (a balanced
            # centre of mass on the link's line comes out 1e-12 m off it).
            reach = math.hypot(e, f)
            e, f = (0.0 if abs(v) <= UNCHANGED * reach else v for v in (e, f))
            values = (f"{mass:.6g}", f"{1e3 * e:.6g}", f"{1e3 * f:.6g}", f"{inertia:.6g}")
        rows.append([name, _COUNTERWEIGHT_KINDS[w.kind], *values, disc])
    total = math.fsum(w.mass for w in weights.values())
    notes = [f"added mass {total:.6g} kg (e, f: the centre in the link's frame; inertia about "
             "that centre)"]
    if any(w.kind == "rebuild" for w in weights.values()):
        notes.append("rebuild: no single body added or removed makes the balanced link; the "
                     "row gives the new link's own mass, centre of mass and inertia")
    if any(w.kind == "remove" for w in weights.values()):
        notes.append("remove: the mass and inertia of the material taken away")
    return (table(rows, ["counterweight", "to do", "mass kg", "e mm", "f mm",
                         "inertia kg·m²", "steel disc mm"])
            + "\n" + "\n".join(notes))


def rotor_masses_text(masses: RotorMasses, speed: float, before: CycleAnalysis | None = None,
                      after: CycleAnalysis | None = None) -> str:
    """What an engine's balancing builds: per plane the counterweight, per shaft its eccentrics.

    Each mass·radius (kg·m) at its angle at θ1 = 0 (degrees), its plane (mm), its mass at the
    given radius (kg); then what they cost: their centrifugal forces (N, the objective's
    unbalance), the main bearings' net reaction before and after (N, from ``before`` and
    ``after``, the analyses at the operating speed) and each new shaft's net force on its
    bearings.
    """
    rows = []
    for c in masses.counterweights:
        mass = masses.mass(c)
        rows.append(["crankshaft", f"{1e3 * c.z:.6g}", f"{c.mr:.6g}",
                     f"{c.phase_deg:.6g}" if c.mr > 0 else "—",
                     "" if mass is None else f"{mass:.6g}"])
    for j, s in enumerate(masses.shafts, start=1):
        where = (f"new shaft {j} (×{s.ratio} at {1e3 * s.at[0]:.6g}, "
                 f"{1e3 * s.at[1]:.6g} mm)")
        for e in s.eccentrics:
            rows.append([where, f"{1e3 * e.z:.6g}", f"{e.mr:.6g}",
                         f"{e.phase_deg:.6g}" if e.mr > 0 else "—", ""])
    header = ["to build", "plane z mm", "mr kg·m", "angle °", "mass kg"]
    notes = ["angle: the mass's direction at θ1 = 0 from +x towards +y; mr 0: none in that "
             "plane" + ("" if not masses.replaced else
                        "; the new counterweights replace those labelled \"counterweight\" in "
                        "their planes")]
    if masses.radius is not None:
        notes[0] += f"; mass at radius {1e3 * masses.radius:.6g} mm"
    notes.append(f"their centrifugal forces mr·ω² at ω = {speed_text(speed)}, "
                 f"root-sum-square √Σ(mr·ω²)² (the objective's unbalance; the bearings share "
                 f"these forces, it is no bearing's load): {masses.unbalance_before:.6g} N "
                 f"before, {masses.unbalance_after:.6g} N after")
    if before is not None and after is not None and "O" in before.reactions.ground:
        b, a = before.summary.ground["O"].max, after.summary.ground["O"].max
        notes.append(f"the main bearings' net reaction RO (all of them together: the force "
                     f"they pass to the frame): largest {b:.6g} N before, {a:.6g} N after")
    for j, (s, load) in enumerate(zip(masses.shafts, masses.bearing_loads, strict=True),
                                  start=1):
        # Its eccentrics' centrifugal forces are the scale of the force they leave on its
        # bearings together (opposed eccentrics leave a couple, and no net force).
        sc = Scales(("N", e.mr * (s.ratio * speed) ** 2) for e in s.eccentrics)
        notes.append(f"new shaft {j}: largest net force on its bearings {sc.number(load, 'N')} N")
    return table(rows, header) + "\n" + "\n".join(notes)


def balance_factors_text(before: Sequence[ThrowBalance], after: Sequence[ThrowBalance]) -> str:
    """Each throw's balance factor before and after, as engine designers quote it."""
    rows = []
    for k, (b, a) in enumerate(zip(before, after, strict=True), start=1):
        rows.append([f"{k}", ", ".join(str(c) for c in b.cylinders), f"{b.phase_deg:.6g}",
                     f"{b.rotating_mr:.6g}", f"{b.reciprocating_mr:.6g}",
                     f"{b.counterweight_mr:.6g}", f"{a.counterweight_mr:.6g}",
                     f"{100 * b.factor:.3g} %", f"{100 * a.factor:.3g} %"])
    return ("balance factor of each throw: its counterweights' mr (opposite its pin) over its "
            "rotating mr + ½ its reciprocating mr (rods split at their centres of mass):\n"
            + table(rows, ["throw", "cylinders", "pin °", "rotating kg·m",
                           "reciprocating kg·m", "counterweights kg·m before", "after",
                           "factor before", "after"]))


def _parameters_text(result: BalanceResult) -> str:
    """Each link's parameters before and after, the changed ones marked."""
    rows = []
    for name in result.linkage.link_names:
        old, new = result.original.link(name), result.linkage.link(name)
        scales = _parameter_scales(old, new)
        sc = Scales(scales.items())  # (a parameter within rounding of its kind's scale: 0)
        for key, unit in (("mass", "kg"), ("e", "m"), ("f", "m"), ("inertia", "kg·m²"),
                          ("counter_rotor", "kg·m²")):
            a, b = getattr(old, key), getattr(new, key)
            if key == "counter_rotor" and name not in result.linkage.grounded_links:
                continue
            # A change within MARKED_CHANGE of its kind's scale in the link is the optimiser's
            # resolution (a parameter nothing pulls, or held off its bound by the interior-point
            # solver): not marked.
            changed = "" if abs(a - b) <= MARKED_CHANGE * scales[key] else "changed"
            rows.append([f"{name} {key}", sc.number(a, key), sc.number(b, key), unit, changed])
    return table(rows, ["parameter", "before", "after", "unit", ""])


#: The share of its kind's scale in the link (:func:`_parameter_scales`) by which a parameter
#: must move to be marked ``changed``: the certified tolerance of the optimum
#: (:data:`balancer.balance.result.GAP_TOLERANCE`). An interior-point solver leaves a parameter
#: at its bound, or where nothing pulls it, to ~1e-10 on one machine and ~1e-6 on another
#: ("almost solved"); no workshop builds such a change.
MARKED_CHANGE = 1e-6


def _parameter_scales(old: Link, new: Link) -> dict[str, float]:
    """Each parameter kind's scale in a link before and after (:func:`.link_scales`).

    A counter-rotor's is the larger of the link's inertia and the counter-rotors.
    """
    mass, reach, inertia = link_scales(old, new)
    rotor = max(inertia, abs(old.counter_rotor), abs(new.counter_rotor))
    return {"mass": mass, "e": reach, "f": reach, "inertia": inertia, "counter_rotor": rotor}


def optimization_scales(result: BalanceResult, before: CycleAnalysis, after: CycleAnalysis
                        ) -> Scales:
    """The scales of ``optimize``'s figures (:class:`Scales`): before and after together.

    The operating figures of both designs and their inertial ones (the objective's terms),
    and an engine's counterweights' centrifugal forces.
    """
    sc = Scales()
    for analysis in (before, after, result.before, result.after):
        sc.add(analysis_figures(analysis))
    masses = result.rotor_masses
    if masses is not None:
        sc.add(("N", x) for x in (masses.unbalance_before, masses.unbalance_after))
    return sc


def optimization_text(result: BalanceResult, before: CycleAnalysis, after: CycleAnalysis,
                      verification: Verification | None = None,
                      spec: str | None = None) -> str:
    """The readable ``optimize`` report."""
    head = f"balancer optimize — {spec}" if spec else "balancer optimize"
    lines = [
        head,
        f"backend {result.backend}: {result.message}",
        f"{result.iterations} solver iterations in {1e3 * result.time:.1f} ms "
        f"({', '.join(s.name for s in result.stages)}); the objective is the mean-square "
        "inertial shaking (loads left out)",
        "",
    ]
    sc = optimization_scales(result, before, after)
    rows = []
    planes = () if after.mechanism.in_one_plane() else ("rocking_couple",)
    for name in ("shaking_force", "shaking_moment", "driving_torque", *planes):
        b, a = getattr(before.summary, name), getattr(after.summary, name)
        unit = UNITS[name]
        rows.append([name.replace("_", " "), sc.fmt(b.rms, unit), sc.fmt(a.rms, unit),
                     sc.ratio(a.rms, b.rms, unit), sc.fmt(b.max, unit), sc.fmt(a.max, unit),
                     unit])
    b, a = before.summary.max_ground_reaction, after.summary.max_ground_reaction
    rows.append(["largest ground load", "", "", sc.ratio(a, b, "N"), sc.fmt(b, "N"),
                 sc.fmt(a, "N"), "N"])
    lines.append(table(rows, ["at the operating speed", "RMS before", "RMS after", "ratio",
                              "max before", "max after", "unit"]))
    lines += [f"warning: {w}" for w in worse_figures(before, after)]
    lines.append("")
    if result.single_term is None:
        terms = _objective_terms(result)
        rows = [[name.replace("_", " "), f"{t['weight']:.4g}",
                 sc.fmt(float(t["before"]), str(t["unit"])),
                 sc.fmt(float(t["after"]), str(t["unit"])), str(t["unit"])]
                for name, t in terms.items()]
        lines += ["objective J = Σ weight × mean square (added mass: weight × kg added), "
                  "inertial shaking at the operating speed:",
                  table(rows, ["term", "weight", "RMS before", "RMS after", "unit"]), ""]
    rows = []
    for ob, oa in zip(before.orders, after.orders, strict=True):
        if ob.order not in (1.0, 2.0):
            continue
        for label, b, a, unit in (
                ("force forward", ob.shaking_force.forward, oa.shaking_force.forward, "N"),
                ("force backward", ob.shaking_force.backward, oa.shaking_force.backward, "N"),
                ("shaking moment", ob.shaking_moment, oa.shaking_moment, "N·m")):
            rows.append([f"{order_name(ob.order)}: {label}", sc.fmt(b, unit), sc.fmt(a, unit),
                         unit])
        if planes:
            for label, b, a in (
                    ("couple forward", ob.rocking_couple.forward, oa.rocking_couple.forward),
                    ("couple backward", ob.rocking_couple.backward, oa.rocking_couple.backward)):
                rows.append([f"{order_name(ob.order)}: {label}", sc.fmt(b, "N·m"),
                             sc.fmt(a, "N·m"), "N·m"])
    lines += [table(rows, ["order amplitude", "before", "after", "unit"]), ""]
    if result.rotor_masses is not None:  # an engine: what to build, not changed links
        lines += [rotor_masses_text(result.rotor_masses, before.speed, before, after), ""]
        factors = result.original.balance_factors(result.linkage)
        if factors is not None:
            lines += [balance_factors_text(*factors), ""]
    else:
        lines += [_parameters_text(result), "", counterweight_text(result.counterweights), ""]
    lines.append(_force_balance_line(after))
    if verification is not None:
        lines.append("")
        lines.append(verification_text(verification).split("\n", 1)[1].strip("\n"))
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# Trade-off fronts


def front_json(front: Front, spec: str | None = None) -> dict[str, Any]:
    """The ``pareto --json`` document: ``against`` and ``points`` are fixed names."""
    doc: dict[str, Any] = {} if spec is None else {"spec": spec}
    doc.update(front.as_dict())
    return doc


def front_text(front: Front, spec: str | None = None) -> str:
    """The readable front: one row per point, the knee marked."""
    head = f"balancer pareto — {spec}" if spec else "balancer pareto"
    name = front.name.replace("_", " ")
    others = front.figure_names
    # Each column's scale its largest figure (the bound the minimised figure's).
    sc = Scales([(front.name, p.value) for p in front.points]
                + [(front.minimised, x) for p in front.points for x in (p.least, p.lower_bound)]
                + [(n, p.figures[n]) for p in front.points for n in others])
    rows = [[f"{i + 1}", sc.fmt(p.value, front.name), sc.fmt(p.least, front.minimised),
             *(sc.fmt(p.figures[n], n) for n in others), sc.fmt(p.lower_bound, front.minimised),
             "knee" if p.knee else ""] for i, p in enumerate(front.points)]
    unit = FIGURES[front.minimised][1]
    held = ("each mass·radius within its bound; the unbalance term's place taken by the "
            "bound on the mass" if front.masses
            else "the balancing constraints of [balance] hold at every point")
    lines = [head,
             f"least {front.words} against {name} ({len(front.points)} "
             f"point{'s' if len(front.points) != 1 else ''}, each a "
             f"global optimum with its certified lower bound; {held})", "",
             table(rows, ["point", f"{name} {front.unit}", f"{front.words} {unit}",
                          *(f"{FIGURES[n][0]} {FIGURES[n][1]}" for n in others),
                          f"certified bound {unit}", ""])]
    return "\n".join(lines)


def front_csv(front: Front) -> str:
    """The front as CSV: one row per point (knee: 1 at the knee, else 0)."""
    points = front.points
    others = front.figure_names
    return csv_text(
        [front.minimised, front.name, "epsilon", "lower_bound", "knee", *others],
        [np.array([p.least for p in points]), np.array([p.value for p in points]),
         np.array([p.epsilon for p in points]), np.array([p.lower_bound for p in points]),
         np.array([1.0 if p.knee else 0.0 for p in points]),
         *(np.array([p.figures[n] for p in points]) for n in others)])


class SweepSummary(Protocol):
    """What the summary reads of a sweep (:class:`balancer.sweeps.SweepResult`, a layer above)."""

    @property
    def statuses(self) -> Mapping[str, int]:
        """Points by status."""
    @property
    def points(self) -> int:
        """Points in all."""
    @property
    def computed(self) -> int:
        """Points this run computed."""
    @property
    def resumed(self) -> int:
        """Batches kept from an interrupted run."""
    @property
    def workers(self) -> int:
        """Dask workers (0: this process)."""
    @property
    def seconds(self) -> float:
        """Wall-clock time, s."""
    @property
    def rate(self) -> float | None:
        """Points per second of this run, or ``None``."""
    @property
    def residual_force(self) -> Mapping[str, float | str] | None:
        """The perturbed designs' residual RMS shaking force (``mean``, ``p95``, ``max``), N."""


def sweep_text(result: SweepSummary, spec: str | None = None) -> str:
    """The readable summary of a sweep."""
    head = f"balancer sweep — {spec}" if spec else "balancer sweep"
    rows = [[status, str(count)] for status, count in sorted(result.statuses.items())]
    where = (f"{result.workers} Dask workers" if result.workers else "this process")
    # The rate counts this run's own points, not those kept from an interrupted run.
    rate = f"{result.rate:.3g} points/s" if result.rate is not None else "no time to measure"
    timing = f"{result.seconds:.1f} s ({rate}, {where})"
    if not result.resumed:
        summary = f"{result.points} points in {timing}"
    else:
        now = (f"{result.computed} computed in {timing}" if result.computed
               else "none left to compute")
        summary = (f"{result.points} points: {result.points - result.computed} from the "
                   f"interrupted run before ({result.resumed} batches), {now}")
    lines = [head, summary, "", table(rows, ["status", "points"]), ""]
    if result.residual_force is not None:
        r = result.residual_force
        lines += [f"residual RMS shaking force of the perturbed designs: mean {r['mean']:.4g} "
                  f"N, 95th percentile {r['p95']:.4g} N, largest {r['max']:.4g} N", ""]
    return "\n".join(lines).rstrip("\n")
