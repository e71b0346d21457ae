"""``simulate``'s and ``verify``'s reports: a trajectory and a verification as text and JSON."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..cycle import Figure
from ..quantities import unit_of
from ..rounding import Scales, speed_text
from .analysis import reaction_extremes
from .text import csv_text, table

if TYPE_CHECKING:  # annotations only (no cycle): the commands that make these load them
    from ..simulation import Trajectory
    from ..verification import Verification


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
    sc.add((unit_of(name), x) for name, fig in figures for x in (fig.rms, fig.max))
    sc.add([("N", traj.largest_reaction)])
    sc.add(("N·m", Figure.of(c).max) for c in traj.slider_couple.values())
    rows = [[name.replace("_", " "), sc.fmt(fig.rms, unit_of(name)), sc.fmt(fig.max, unit_of(name)),
             unit_of(name)] for name, fig in figures]
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
