"""``analyze``'s report along a motion: a table per motion, a JSON document and CSV."""

from __future__ import annotations

from typing import Any

from ..linkage.loads import Reactions
from ..mechanisms.base import in_one_plane
from ..model.motions import REVOLUTION, MotionSpec
from ..motion_analysis import AlongMotions, MotionAnalysis, load_words
from ..rounding import Scales
from .analysis import reaction_extremes
from .text import csv_text, table


def law_words(m: MotionSpec) -> str:
    """A motion's time law in words: the law's name, or a planned motion's pace."""
    if m.pace is not None:
        return f"a planned pace ({len(m.pace)} rows)"
    if m.law == "trapezoid":
        return f"trapezoid law (acceleration {m.acc_time:g} s)"
    return f"{m.law} law"


def _law(analysis: MotionAnalysis) -> str:
    m = analysis.motion
    if m.along == REVOLUTION:
        path = "one revolution of the input"
    else:
        path = f"point {m.point}'s path" if m.point is not None else "the inputs' own path"
        path += f" through {len(m.times)} waypoints"
        if m.along is not None:
            path += f" (motion {m.along}'s)"
    return f"{m.samples} states over {m.duration:g} s, {law_words(m)}, {path}"


def motions_text(along: AlongMotions, spec: str | None = None) -> str:
    """The readable ``analyze`` report of a linkage along its motions."""
    head = f"balancer analyze — {spec}" if spec else "balancer analyze"
    analyses = along.motions
    first = analyses[0]
    mech = first.mechanism
    gravity = first.gravity
    lines = [head,
             f"{mech.model.type} ({mech.describe()}), driven at {', '.join(first.inputs)}"
             + (f"; gravity ({gravity[0]:g}, {gravity[1]:g}) m/s² included"
                if any(gravity) else "; gravity not included")]
    planar = in_one_plane(mech)
    size = mech.structure.length_scale()
    sc = _scales(along)
    for analysis in analyses:
        loads = analysis.loads()
        rows = [[load_words(mech, key)[0], sc.fmt(figure.rms, load_words(mech, key)[1]),
                 sc.fmt(figure.max, load_words(mech, key)[1]), load_words(mech, key)[1]]
                for key, figure in loads.items()
                if not (key == "rocking_couple" and planar)]
        lines += ["", f"motion {analysis.name}: {_law(analysis)}", "",
                  table(rows, ["quantity", "RMS", "max", "unit"]), "",
                  "the total centre of mass moves up to "
                  f"{_length(analysis.centre_of_mass_excursion, size)} from its mean place "
                  "along it"]
        lines += reactions_lines(analysis.reactions, sc)
    lines += ["", force_balance_words(along)]
    return "\n".join(lines)


def reactions_lines(reactions: Reactions, sc: Scales) -> list[str]:
    """The table of each ground point's force along a motion (a blank line first), or none."""
    rows = []
    for point, values in reactions.ground.items():
        ex = reaction_extremes(values)
        rows.append([f"R{point}", *(sc.fmt(ex[k], "N") for k in
                                    ("max", "x_min", "x_max", "y_min", "y_max"))])
    if not rows:
        return []
    return ["", table(rows, ["reaction (N)", "|R| max", "Rx min", "Rx max", "Ry min",
                             "Ry max"])]


def _scales(along: AlongMotions) -> Scales:
    """The scales of the report's figures (:class:`Scales`), every motion's together.

    Each load's largest under its unit, and each motion's natural scales
    (:meth:`~balancer.motion_analysis.MotionAnalysis.natural_scales`: the ground forces, or
    the motors' torques over the size where a balanced robot's one ground force is its own
    rounding).
    """
    sc = Scales()
    for analysis in along.motions:
        sc.add((load_words(analysis.mechanism, key)[1], figure.max)
               for key, figure in analysis.loads().items())
        sc.add(analysis.natural_scales().items())
    return sc


def force_balance_words(along: AlongMotions) -> str:
    """Whether the design is force-balanced for every motion, in words a designer pictures."""
    w = along.workspace
    size = along.mechanism.structure.length_scale()
    over = ("" if w is None else
            f"; over the workspace ({w.states} of its {w.grid} grid states) the total centre of "
            f"mass moves up to {_length(w.centre_of_mass_excursion, size)} from its mean place")
    if along.force_balanced:
        return ("force-balanced: yes (the total centre of mass stands still for every motion; "
                f"the conditions hold to {along.force_balance_residual:.1e} of the links' first "
                f"moments{over})")
    still = all(a.loads()["shaking_force"].max <= MOTION_ROUNDING * a.natural_scales()["N"]
                for a in along.motions)
    if still:  # ([balance] force = "motion": still along its motions, not everywhere)
        return ("force-balanced along its motions only: the total centre of mass stands "
                "still along each of them (its shaking force is rounding there), not for every "
                f"motion (the conditions are off by {along.force_balance_residual:.2g} of the "
                f"links' first moments{over})")
    return ("force-balanced: no (the conditions are off by "
            f"{along.force_balance_residual:.2g} of the links' first moments{over})")


#: A motion's shaking force at most this share of its force scale is rounding: the design is
#: force-balanced along it.
MOTION_ROUNDING = 1e-9


def _length(metres: float, size: float) -> str:
    """A length for a reader: mm below a metre, else m.

    0 where it is rounding of ``size``: within 1e-10 of the linkage's size, as every readable
    figure (docs: outputs).
    """
    if abs(metres) <= 1e-10 * size:
        return "0 mm"
    return f"{1e3 * metres:.4g} mm" if abs(metres) < 1.0 else f"{metres:.4g} m"


def motions_json(along: AlongMotions, spec: str | None = None) -> dict[str, Any]:
    """``analyze --json`` along the motions: each motion's figures under ``motions.<name>``."""
    first = along.motions[0]
    w = along.workspace
    out: dict[str, Any] = {
        "spec": spec, "mechanism": first.mechanism.model.type, "inputs": list(first.inputs),
        "gravity": list(first.gravity), "force_balanced": along.force_balanced,
        "force_balance_residual": {"relative": along.force_balance_residual},
        "workspace": None if w is None else {
            "states": w.states, "grid": w.grid,
            "centre_of_mass_excursion": w.centre_of_mass_excursion},
        "motions": {}}
    for analysis in along.motions:
        m = analysis.motion
        entry: dict[str, Any] = {"duration": m.duration, "samples": m.samples, "law": m.law,
                                 "point": m.point}
        for key, figure in analysis.loads().items():
            entry[key] = {"rms": figure.rms, "max": figure.max}
        entry["centre_of_mass_excursion"] = analysis.centre_of_mass_excursion
        entry["reactions"] = {p: reaction_extremes(v)
                              for p, v in analysis.reactions.ground.items()}
        out["motions"][analysis.name] = entry
    return out


def motion_csv(analysis: MotionAnalysis) -> str:
    """The values along one motion as CSV text (SI units, full precision)."""
    return csv_text(*analysis.columns())
