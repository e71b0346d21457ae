"""``plan``'s report: the time law chosen for a motion's path, and what it buys."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..mechanisms.base import in_one_plane
from ..motion_analysis import load_words
from ..rounding import Scales
from .text import table

if TYPE_CHECKING:  # annotations only: the command that makes it loads it
    from ..planning import Plan
    from ..planning.codesign import CoDesign

#: What the report calls each objective term.
_TERM_WORDS = {"shaking_moment": "shaking moment", "shaking_force": "shaking force",
               "shaking_force_x": "shaking force along x",
               "shaking_force_y": "shaking force along y",
               "rocking_couple": "rocking couple", "torque": "inputs' torques"}


def _objective_words(plan: Plan) -> str:
    terms = plan.spec.objective.terms()
    words = " + ".join(f"{w:g}·{_TERM_WORDS[k]}²" if w != 1 else f"{_TERM_WORDS[k]}²"
                       for k, w in terms.items())
    return (f"the mean square over time of {words}" if plan.spec.measure == "rms"
            else f"the largest value of {words}")


def _path_words(plan: Plan) -> str:
    path = plan.path
    if path.along == "revolution":
        steady = path.pace is not None and len({rate for _, rate in path.pace}) == 1
        return ("one revolution of the input at constant speed" if steady else
                f"one revolution of the input (motion {path.name}'s pace to start from)")
    what = f"point {path.point}'s path" if path.point else "the inputs' path"
    return f"motion {path.name} ({what} through {len(path.times)} waypoints, law {path.law})"


def _figure(value: float, measure: str) -> float:
    """The objective's figure in its load's unit: the root of ``J``."""
    return math.sqrt(max(value, 0.0))


def plan_text(plan: Plan, spec: str | None = None) -> str:
    """The readable ``plan`` report."""
    head = f"balancer plan — {spec}" if spec else "balancer plan"
    solution = plan.solution
    lines = [head,
             f"time law planned for {_path_words(plan)}: {plan.planned.name}, "
             f"{plan.planned.duration:g} s (was {plan.path.duration:g} s)",
             f"objective: {_objective_words(plan)}", ""]
    before, after = plan.before.loads(), plan.after.loads()
    mech = plan.before.mechanism
    sc = Scales()
    sc.add((load_words(mech, k)[1], f.max) for k, f in (*before.items(), *after.items()))
    planar = in_one_plane(mech)
    rows = []
    for key, old in before.items():
        if key == "rocking_couple" and planar:
            continue
        new = after[key]
        what, unit = load_words(mech, key)
        rows.append([what, sc.fmt(old.rms, unit), sc.fmt(new.rms, unit), _change(old.rms, new.rms),
                     sc.fmt(old.max, unit), sc.fmt(new.max, unit), _change(old.max, new.max),
                     unit])
    lines.append(table(rows, ["load", "RMS before", "RMS after", "change", "max before",
                              "max after", "change", "unit"]))
    lines += ["", *_certificate_lines(plan, solution)]
    return "\n".join(lines)


def _change(before: float, after: float) -> str:
    if before == 0.0:
        return "—"
    return f"{100.0 * (after / before - 1.0):+.1f} %"


def _certificate_lines(plan: Plan, solution: Any) -> list[str]:
    root = "√J" if plan.spec.measure == "rms" else "√(max)"
    how = "by quadrature" if plan.spec.measure == "rms" else "its largest"
    lines = [f"objective {root}: {_figure(plan.objective_before, plan.spec.measure):.6g} before, "
             f"{_figure(plan.objective_after, plan.spec.measure):.6g} after (along each motion, "
             f"{how}); the transcription's optimum "
             f"{_figure(solution.objective, plan.spec.measure):.6g} on "
             f"{plan.problem.loads.tau.size - 1} intervals"
             + ("" if plan.halved is None else
                f" ({_figure(plan.halved, plan.spec.measure):.6g} on half as many)")]
    if plan.bound is not None:
        lines.append(f"least possible from rest to rest (closed form, any time law): "
                     f"{_figure(plan.bound, plan.spec.measure):.6g}")
    if solution.certified:
        starts = ("" if len(plan.starts) == 1 else f" (the same from {len(plan.starts)} starts "
                  f"to {_spread(plan.starts):.0e})")
        lines.append("the optimum is the transcription's global one (convex, or reaching its "
                     f"convex relaxation's bound){starts}")
    else:
        lines.append("a local optimum: a faster motion would shake less, and the duration is "
                     f"held (best of {len(plan.starts)} starts, spread {_spread(plan.starts):.0e})")
    lines += _limit_lines(plan)
    lines.append(f"largest limit violation at the transcription's rows {solution.violation:.1e} "
                 f"of its limit; IPOPT: {solution.iterations} solver iterations")
    return lines


def _limit_lines(plan: Plan) -> list[str]:
    """Each limit of the plan against the largest value along the planned motion."""
    after, out = plan.after, []
    state, torques = after.state, after.reactions.torques
    kinds = (("max_speed", "speed", state.rates), ("max_acceleration", "acceleration",
                                                   state.accelerations),
             ("max_torque", "torque", torques))
    for key, words, values in kinds:
        for i, name in enumerate(after.inputs):
            limit = getattr(plan.spec, key).of(name)
            if limit is None:
                continue
            reached = float(np.max(np.abs(np.asarray(values[i]))))
            lines = f"{words} of {name}: at most {reached:.6g} along the planned motion, "
            out.append(lines + f"its limit {limit:g} ({100 * reached / limit:.1f} %)")
    return out


def _spread(values: tuple[float, ...]) -> float:
    top = max(abs(x) for x in values) or 1.0
    return (max(values) - min(values)) / top


def plan_json(plan: Plan, spec: str | None = None) -> dict[str, Any]:
    """The ``plan --json`` document."""
    def loads(analysis: Any) -> dict[str, Any]:
        return {k: {"rms": f.rms, "max": f.max} for k, f in analysis.loads().items()}

    doc: dict[str, Any] = {} if spec is None else {"spec": spec}
    doc.update({
        "motion": plan.path.name, "planned": plan.planned.name,
        "measure": plan.spec.measure, "objective": plan.spec.objective.terms(),
        "duration": plan.planned.duration, "duration_before": plan.path.duration,
        "intervals": int(plan.problem.loads.tau.size - 1),
        "objective_before": plan.objective_before, "objective_after": plan.objective_after,
        "transcription_objective": plan.solution.objective, "lower_bound": plan.bound,
        "halved_objective": plan.halved,
        "certified": plan.solution.certified, "starts": list(plan.starts),
        "violation": plan.solution.violation, "iterations": plan.solution.iterations,
        "before": loads(plan.before), "after": loads(plan.after),
        "pace": [[float(t), float(r)] for t, r in plan.planned.pace or ()],
        "pace_times": [float(t) for t in np.asarray(plan.planned.pace_times)],
    })
    return doc


#: What the co-design's table calls each case.
_LEVER_WORDS = {"spec": "as specified", "masses": "the masses alone",
                "motion": "the time law alone", "both": "both"}


def codesign_text(result: CoDesign, spec: str | None = None) -> str:
    """The readable ``plan --with-masses`` report: each lever alone and both together."""
    plan = result.plan
    head = f"balancer plan --with-masses — {spec}" if spec else "balancer plan --with-masses"
    lines = [head,
             f"the masses of [balance] and the time law of {_path_words(plan)} chosen together "
             f"({(len(result.rounds) - 1) // 2} rounds)",
             f"objective: {_objective_words(plan)}", ""]
    mech = plan.before.mechanism
    keys = [k for k in plan.before.loads()
            if not (k == "rocking_couple" and in_one_plane(mech))]
    sc = Scales()
    loads = {lever: a.loads() for lever, a in result.analyses.items()}
    sc.add((load_words(mech, k)[1], f.rms) for one in loads.values() for k, f in one.items())
    root = "√J" if plan.spec.measure == "rms" else "√(max)"
    heading = ["lever", root, "change"] + [f"RMS {load_words(mech, k)[0]} "
                                            f"({load_words(mech, k)[1]})" for k in keys]
    start = result.objectives["spec"]
    rows = []
    for lever in ("spec", "masses", "motion", "both"):
        value = result.objectives[lever]
        rows.append([_LEVER_WORDS[lever], f"{_figure(value, plan.spec.measure):.6g}",
                     "—" if lever == "spec" else _change(_figure(start, ""), _figure(value, "")),
                     *(sc.fmt(loads[lever][k].rms, load_words(mech, k)[1]) for k in keys)])
    lines.append(table(rows, heading))
    steps = ", ".join(f"{_figure(j, ''):.6g}" for j in result.rounds)
    lines += ["", "each step's problem is convex and solved to its optimum; together they are "
              "not: the result is where neither lever alone does better"]
    if result.projected:
        lines.append("the spec's masses do not meet [balance]'s constraints (its force "
                     "balance): the first masses step projects onto them and √J rose; from "
                     f"there it never rose ({steps})")
    else:
        lines.append(f"√J never rose ({steps})")
    return "\n".join(lines)


def codesign_json(result: CoDesign, spec: str | None = None) -> dict[str, Any]:
    """The ``plan --with-masses --json`` document: the plan's, with each lever's figures."""
    doc = plan_json(result.plan, spec=spec)
    doc["levers"] = {lever: {"objective": result.objectives[lever],
                             "loads": {k: {"rms": f.rms, "max": f.max}
                                       for k, f in result.analyses[lever].loads().items()}}
                     for lever in result.objectives}
    doc["rounds"] = list(result.rounds)
    return doc
