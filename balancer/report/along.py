"""``analyze``'s report along a motion: a table per motion, a JSON document and CSV."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..motion_analysis import MotionAnalysis
from ..rounding import Scales
from .analysis import reaction_extremes
from .text import csv_text, table

#: What a table calls each load, and its unit.
_WORDS = {"shaking_force": ("shaking force", "N"),
          "shaking_moment": ("shaking moment", "N·m"),
          "rocking_couple": ("rocking couple", "N·m")}


def _words(key: str) -> tuple[str, str]:
    if key.startswith("torque_"):
        return f"torque on {key[len('torque_'):]}", "N·m"
    return _WORDS[key]


def _law(analysis: MotionAnalysis) -> str:
    m = analysis.motion
    law = (f"trapezoid law (acceleration {m.acc_time:g} s)" if m.law == "trapezoid"
           else f"{m.law} law")
    path = f"point {m.point}'s path" if m.point is not None else "the inputs' own path"
    return (f"{m.samples} states over {m.duration:g} s, {law}, {path} through "
            f"{len(m.times)} waypoints")


def motions_text(analyses: Sequence[MotionAnalysis], spec: str | None = None) -> str:
    """The readable ``analyze`` report of a linkage along its motions."""
    head = f"balancer analyze — {spec}" if spec else "balancer analyze"
    first = analyses[0]
    mech = first.mechanism
    gravity = first.gravity
    lines = [head,
             f"{mech.kind} ({mech.describe()}), driven at {', '.join(first.inputs)}"
             + (f"; gravity ({gravity[0]:g}, {gravity[1]:g}) m/s² included"
                if any(gravity) else "; gravity not included")]
    planar = mech.in_one_plane()
    for analysis in analyses:
        loads = analysis.loads()
        sc = Scales([(key, figure.max) for key, figure in loads.items()])
        rows = [[_words(key)[0], sc.fmt(figure.rms, _words(key)[1]),
                 sc.fmt(figure.max, _words(key)[1]), _words(key)[1]]
                for key, figure in loads.items()
                if not (key == "rocking_couple" and planar)]
        lines += ["", f"motion {analysis.name}: {_law(analysis)}", "",
                  table(rows, ["quantity", "RMS", "max", "unit"])]
        reactions = []
        for point, values in analysis.reactions.ground.items():
            ex = reaction_extremes(values)
            reactions.append([f"R{point}", *(sc.fmt(ex[k], "N") for k in
                                             ("max", "x_min", "x_max", "y_min", "y_max"))])
        if reactions:
            lines += ["", table(reactions, ["reaction (N)", "|R| max", "Rx min", "Rx max",
                                            "Ry min", "Ry max"])]
    return "\n".join(lines)


def motions_json(analyses: Sequence[MotionAnalysis], spec: str | None = None
                 ) -> dict[str, Any]:
    """``analyze --json`` along the motions: each motion's figures under ``motions.<name>``."""
    first = analyses[0]
    out: dict[str, Any] = {"spec": spec, "mechanism": first.mechanism.kind,
                           "inputs": list(first.inputs), "gravity": list(first.gravity),
                           "motions": {}}
    for analysis in analyses:
        m = analysis.motion
        entry: dict[str, Any] = {"duration": m.duration, "samples": m.samples, "law": m.law,
                                 "point": m.point}
        for key, figure in analysis.loads().items():
            entry[key] = {"rms": figure.rms, "max": figure.max}
        entry["reactions"] = {p: reaction_extremes(v)
                              for p, v in analysis.reactions.ground.items()}
        out["motions"][analysis.name] = entry
    return out


def motion_csv(analysis: MotionAnalysis) -> str:
    """The values along one motion as CSV text (SI units, full precision)."""
    return csv_text(*analysis.columns())
