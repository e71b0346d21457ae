"""``analyze``'s report: the cycle analysis as a table, a JSON document and CSV."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..cycle import CycleAnalysis
from ..mechanisms.base import in_one_plane
from ..orders import order_name
from ..quantities import FRAME_LOADS
from ..rounding import Scales, speed_text
from .text import csv_text, table

if TYPE_CHECKING:
    from ..motion_analysis import AlongMotions
    from ..speed_fluctuation import Flywheel


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


def orders_list(analysis: CycleAnalysis | AlongMotions) -> list[dict[str, Any]]:
    """The ``orders`` table (DESIGN.md's names; :mod:`balancer.orders`)."""
    return [order.as_dict() for order in analysis.orders]


def analysis_figures(analysis: CycleAnalysis | AlongMotions) -> list[tuple[str, float]]:
    """Every figure of a cycle analysis under its unit, for :class:`Scales`.

    The shaking, the driving and mount torques and the rocking couple (RMS and maximum), the
    forces on the frame at each ground point and guide, the guides' couples, every order.
    """
    s = analysis.summary
    out: list[tuple[str, float]] = []
    for q in FRAME_LOADS:
        fig = getattr(s, q.key)
        if fig is not None:
            out += [(q.unit, fig.rms), (q.unit, fig.max)]
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
    planes = not in_one_plane(analysis.mechanism)
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


def analysis_json(analysis: CycleAnalysis, spec: str | None = None,
                  flywheel: Flywheel | None = None) -> dict[str, Any]:
    """The ``analyze --json`` document (with ``flywheel`` where the spec asks for one)."""
    mech = analysis.mechanism
    balanced, residual = analysis.force_balanced, analysis.force_balance_residual
    doc: dict[str, Any] = {}
    if spec is not None:
        doc["spec"] = spec
    doc.update(
        {
            "mechanism": mech.model.type,
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
            "orders": orders_list(analysis),
            **({mech.presentation.supports_key: _supports_list(analysis)}
               if analysis.supports else {}),
            **({"gears": _gears_list(analysis)} if analysis.reactions.teeth else {}),
            **({} if flywheel is None else {"flywheel": flywheel.as_dict()}),
            "units": {
                "force": "N",
                "moment": "N·m",
                "speed": "rad/s",
                "gravity": "m/s²",
                "force_balance_residual": "dimensionless (first moments left over, over those "
                                          "that make them)",
                "centre_of_mass_excursion": "m (largest distance of the total centre of mass "
                                            "from its mean place over the cycle)",
                **({} if flywheel is None else {
                    "flywheel": "inertia, mechanism_inertia, classical_inertia: kg·m² about the "
                                "crank; energy_swing: J; mean_torque: N·m; speed_min, speed_max: "
                                "rad/s; fluctuation, fluctuation_without: (ω_max − ω_min)/ω_mean"}),
            },
        }
    )
    return doc


def _supports_list(analysis: CycleAnalysis) -> list[dict[str, Any]]:
    """Each support's (an engine's main bearing's) plane, extremes, RMS and orders."""
    return [{"name": s.name, "z": s.z, "rms": float(np.sqrt(np.mean(np.abs(s.force) ** 2))),
             **reaction_extremes(s.force),
             "orders": [{"order": q, **w.as_dict()} for q, w in analysis.support_orders(s)]}
            for s in analysis.supports]


def _gears_list(analysis: CycleAnalysis) -> list[dict[str, Any]]:
    """Each gear pair's tooth force on its driven gear: RMS and extremes (N)."""
    return [{"name": name, "rms": float(np.sqrt(np.mean(np.abs(force) ** 2))),
             **reaction_extremes(force)}
            for name, force in analysis.reactions.teeth.items()]


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


def analysis_text(analysis: CycleAnalysis, spec: str | None = None,
                  flywheel: Flywheel | None = None) -> str:
    """The readable ``analyze`` report (with ``flywheel`` where the spec asks for one)."""
    mech = analysis.mechanism
    s = analysis.summary
    sc = Scales(analysis_figures(analysis))
    planar = in_one_plane(mech)
    head = f"balancer analyze — {spec}" if spec else "balancer analyze"
    per_cycle = (f" over a cycle of 720° ({analysis.samples} in all)"
                 if analysis.revolutions == 2 else "")
    lines = [
        head,
        f"{mech.model.type} ({mech.describe()}), {analysis.samples_per_revolution} crank angles "
        f"per revolution{per_cycle} at {speed_text(analysis.speed)}, {analysis.route} route"
        + (f"; gravity ({analysis.gravity[0]:g}, {analysis.gravity[1]:g}) m/s² included"
           if any(analysis.gravity) else "; gravity not included")
        + ("" if analysis.loads else "; loads left out"),
        "",
        table(
            [
                [q.key.replace("_", " "), sc.fmt(fig.rms, q.unit), sc.fmt(fig.max, q.unit),
                 q.unit]
                for q, fig in ((q, getattr(s, q.key)) for q in FRAME_LOADS)
                if fig is not None and not (q.out_of_plane and planar)
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
    if analysis.supports:
        lines += ["", supports_text(analysis, sc)]
    if analysis.reactions.teeth:
        rows = [[name, sc.fmt(float(np.sqrt(np.mean(np.abs(f) ** 2))), "N"),
                 sc.fmt(float(np.max(np.abs(f), initial=0.0)), "N")]
                for name, f in analysis.reactions.teeth.items()]
        lines += ["", table(rows, ["gear pair: tooth load (N)", "|F| RMS", "|F| max"])]
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
    lines.append(force_balance_line(analysis))
    if flywheel is not None:
        lines += ["", flywheel_text(flywheel)]
    return "\n".join(lines)


def flywheel_text(f: Flywheel) -> str:
    """The least flywheel for the spec's speed fluctuation, and the figures it comes from."""
    low, mean, high = f.mechanism_inertia
    if f.inertia > 0:
        alone = ("stops within its cycle at this mean speed" if math.isinf(f.fluctuation_without)
                 else f"{f.fluctuation_without:.4g}")
        verdict = (f"least flywheel on the crank for a speed fluctuation of {f.fluctuation:g}: "
                   f"{f.inertia:.6g} kg·m² (the mechanism alone: {alone})")
    else:
        verdict = (f"no flywheel needed for a speed fluctuation of {f.fluctuation:g}: the "
                   f"mechanism alone keeps {f.fluctuation_without:.4g}")
    return "\n".join([
        verdict,
        f"  from the exact energy balance: the speed between {f.speeds[0]:.6g} and "
        f"{f.speeds[1]:.6g} rad/s, mean {f.speed:.6g}; the mechanism's inertia on the crank "
        f"{low:.4g} to {high:.4g} kg·m² (mean {mean:.4g})",
        f"  turning-moment diagram: energy swing {f.energy_swing:.6g} J about the mean torque "
        f"{f.mean_torque:.6g} N·m; the classical ΔE/(δ·ω²) − J̄ = {f.classical:.6g} kg·m²",
    ])


def supports_text(analysis: CycleAnalysis, sc: Scales) -> str:
    """The supports' (an engine's main bearings') loads: RMS, largest, orders 1 and 2.

    An order's figure is the largest magnitude of its part of the load, its forward and
    backward whirls' sum (N).
    """
    words = analysis.mechanism.presentation.support_words
    rows = []
    for s in analysis.supports:
        orders = dict(analysis.support_orders(s))
        rows.append([s.name, f"{s.z:g}", sc.fmt(float(np.sqrt(np.mean(np.abs(s.force) ** 2))),
                                                "N"),
                     sc.fmt(float(np.max(np.abs(s.force), initial=0.0)), "N"),
                     *(sc.fmt(orders[q].forward + orders[q].backward, "N") if q in orders
                       else "—" for q in (1.0, 2.0))])
    return table(rows, [f"{words} (N)", "z (m)", "|R| RMS", "|R| max", "order 1", "order 2"])


def force_balance_line(analysis: CycleAnalysis) -> str:
    """Whether the design is force-balanced, in words a designer pictures."""
    balanced, residual = analysis.force_balanced, analysis.force_balance_residual
    if balanced:
        source = analysis.mechanism.presentation.force_balance_source
        return ("force-balanced: yes (the total centre of mass stands still; "
                f"{source} hold to {residual:.1e} of the links' first moments)")
    excursion = analysis.centre_of_mass_excursion
    return ("force-balanced: no (the total centre of mass moves up to "
            f"{_length(excursion)} from its mean place over a revolution)")


def _length(metres: float) -> str:
    """A length for a reader: mm below a metre, else m."""
    if abs(metres) < 1.0:
        return f"{1e3 * metres:.4g} mm"
    return f"{metres:.4g} m"


def analysis_csv(analysis: CycleAnalysis) -> str:
    """Per-angle values of a cycle analysis as CSV text (SI units, full precision)."""
    return csv_text(*analysis.columns())
