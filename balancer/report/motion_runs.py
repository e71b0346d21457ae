"""``simulate``'s and ``verify``'s reports for a linkage with several inputs, along its motions."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..mechanisms.base import in_one_plane
from ..motion_analysis import load_words
from ..rounding import Scales
from .along import reactions_lines
from .analysis import reaction_extremes
from .text import csv_text, table

if TYPE_CHECKING:  # annotations only: the commands that make these load them
    from ..motion_verification import MotionCheck, MotionVerification
    from ..simulation.motions import MotionRun


def _run_words(run: MotionRun) -> str:
    if run.drive == "motion":
        return f"every input driven along motion {run.motion}"
    return "free (no motor) from the state where the motion's inputs turn fastest"


def motion_run_text(run: MotionRun, spec: str | None = None) -> str:
    """The readable ``simulate`` report of a run along a motion (or free)."""
    head = f"balancer simulate — {spec}" if spec else "balancer simulate"
    how = ("the motors' work by quadrature" if run.drive == "motion"
           else "integrated by DOP853")
    lines = [head,
             f"{_run_words(run)} for {float(run.t[-1] - run.t[0]):g} s, formulation "
             f"{run.method} ({how}, rtol {run.rtol:g}: {run.evaluations} evaluations)", ""]
    sc = Scales()
    loads = run.loads()
    mech = run.mechanism

    def words(key: str) -> tuple[str, str]:
        return load_words(mech, key)

    sc.add((words(k)[1], f.max) for k, f in loads.items())
    sc.add([("N", run.largest_reaction)])
    planar = in_one_plane(mech)
    rows = [[words(k)[0], sc.fmt(f.rms, words(k)[1]), sc.fmt(f.max, words(k)[1]),
             words(k)[1]] for k, f in loads.items()
            if not (k == "rocking_couple" and planar)
            and not (k.startswith("torque_") and run.drive == "free")]
    lines.append(table(rows, ["quantity over time", "RMS", "max", "unit"]))
    lines += reactions_lines(run.reactions, sc)
    lines += ["", _energy_words(run)]
    return "\n".join(lines)


def _energy_words(run: MotionRun) -> str:
    if run.drive == "motion":
        text = ("energy balance: kinetic energy change = work of the motors, loads and gravity "
                f"to {run.energy_error:.1e} (relative)")
    else:
        text = ("energy balance: kinetic energy change = work of loads and gravity to "
                f"{run.energy_error:.1e} (relative)")
    if run.method == "multibody" and run.drive == "free":
        text += (f"; loop-closure drift before projection {run.drift[0]:.1e} m, "
                 f"{run.drift[1]:.1e} m/s")
    return text


def motion_run_json(run: MotionRun, spec: str | None = None) -> dict[str, Any]:
    """The ``simulate --json`` document of a run along a motion (or free)."""
    def state(index: int) -> dict[str, dict[str, float]]:
        s = run.state
        return {name: {"position": float(s.positions[i][index]),
                       "rate": float(s.rates[i][index]),
                       "acceleration": float(s.accelerations[i][index])}
                for i, name in enumerate(run.inputs)}

    loads: dict[str, Any] = {k: {"rms": f.rms, "max": f.max} for k, f in run.loads().items()}
    loads["reactions"] = {p: reaction_extremes(v) for p, v in run.reactions.ground.items()}
    doc: dict[str, Any] = {} if spec is None else {"spec": spec}
    doc.update({
        "method": run.method, "drive": run.drive, "motion": run.motion,
        "inputs": list(run.inputs), "duration": float(run.t[-1] - run.t[0]),
        "outputs": int(run.t.size), "rtol": run.rtol, "atol": run.atol,
        "steps": run.steps, "evaluations": run.evaluations, "initial": state(0),
        "final": state(-1), "energy_error": run.energy_error,
        "constraint_drift": {"position": run.drift[0], "velocity": run.drift[1]},
        "motions": {run.motion or "free": loads},
        "units": {"position": "rad (m along a slide)", "rate": "rad/s (m/s)",
                  "acceleration": "rad/s² (m/s²)", "force": "N",
                  "moment": "N·m (a slide's actuator: N)", "constraint_drift": "m, m/s"}})
    return doc


def motion_run_csv(run: MotionRun) -> str:
    """The run's values over time as CSV text (``analyze --csv``'s columns along a motion)."""
    return csv_text(*run.columns())


def _verification_scales(v: MotionVerification) -> Scales:
    sc = Scales()
    for check in v.checks:
        for run in (check.run, check.original):
            if run is None:
                continue
            sc.add([("N", run.largest_reaction)])
            sc.add((load_words(run.mechanism, k)[1], f.max) for k, f in run.loads().items())
    return sc


def motion_verification_text(v: MotionVerification, spec: str | None = None) -> str:
    """The readable ``verify`` report along the motions."""
    head = f"balancer verify — {spec}" if spec else "balancer verify"
    lines = [head, f"simulated with the {v.method} formulation: every input driven along each "
             "motion, and free", ""]
    sc = _verification_scales(v)

    def shown(x: float | None, unit: str) -> str:
        return "—" if x is None else sc.number(x, unit, ".4g")

    def row(name: str, c: MotionCheck) -> list[str]:
        return [name, shown(c.max_shaking_force, "N"), shown(c.original_max_shaking_force, "N"),
                sc.ratio(c.max_shaking_force, c.original_max_shaking_force, "N", ".2e"),
                "—" if c.force_level is None else format(c.force_level, ".1e"),
                shown(c.max_shaking_moment, "N·m"), shown(c.original_max_shaking_moment, "N·m"),
                sc.ratio(c.max_shaking_moment, c.original_max_shaking_moment, "N·m", ".2e")]

    rows = [row(f"along {c.name}", c) for c in v.motions] + [row("free", v.free)]
    lines.append(table(rows, ["motion", "max |ΣR| (N)", "original", "ratio", "of scale",
                              "max |Msh| (N·m)", "original", "ratio"]))
    inputs = v.free.run.inputs
    units = [load_words(v.free.run.mechanism, f"torque_{n}")[1] for n in inputs]
    torque_rows = [[f"along {c.name}", *(shown(c.max_torques[n], u)
                                         for n, u in zip(inputs, units, strict=True))]
                   for c in v.motions]
    lines += ["", table(torque_rows, ["motion", *(f"max |{'F' if u == 'N' else 'τ'} {n}| ({u})"
                                                  for n, u in zip(inputs, units, strict=True))])]
    for c in v.motions:
        lines.append(f"along {c.name}: the {c.other.method if c.other else ''} formulation "
                     f"agrees to {c.agreement:.1e}; energy balance to "
                     f"{c.run.energy_error:.1e}")
    lines.append(f"free for {float(v.free.run.t[-1]):g} s: energy balance to "
                 f"{v.free.run.energy_error:.1e}")
    levels = [c.force_level for c in v.checks if c.force_level is not None]
    if levels and max(levels) < 1e-8:
        lines.append("the reaction sums vanish to rounding along every motion and in the free "
                     "run: force-balanced")
    return "\n".join(lines)
