"""``optimize``'s report: the balanced design against the original, as text and JSON."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from ..balance.counterweights import UNCHANGED, Counterweight, link_scales
from ..cycle import CycleAnalysis
from ..mechanisms.base import in_one_plane
from ..motion_analysis import AlongMotions, load_words
from ..motion_verification import MotionVerification
from ..orders import order_name
from ..quantities import QUANTITIES, unit_of, words_of
from ..rounding import Scales, speed_text
from ..rounding import figure_text as _fmt
from .analysis import analysis_figures, force_balance_line, orders_list
from .motion import verification_text
from .motion_runs import motion_verification_text
from .text import table

if TYPE_CHECKING:  # annotations only (no cycle): the commands that make these load them
    from ..balance.result import BalanceResult, FlywheelSizing, RotorMasses
    from ..model import Link
    from ..model.mechanisms import ThrowBalance
    from ..verification import Verification


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


def optimization_json(result: BalanceResult, before: CycleAnalysis | AlongMotions,
                      after: CycleAnalysis | AlongMotions,
                      verification: Verification | MotionVerification | None = None,
                      spec: str | None = None,
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
            "orders": {"before": orders_list(before), "after": orders_list(after)},
            "verification": None if verification is None else verification.as_dict(),
            "out": None if out is None else str(out),
            "units": {"objective, lower_bound": "(N·m)², the weighted mean squares "
                      + ("(and squared largest loads) " if _largest_terms(result) else "")
                      + "of the "
                      "inertial shaking (J of [balance.objective])",
                      "objective_terms": "each term's RMS in its 'unit' "
                      + ("(largest_bearing_load: its largest) " if _largest_terms(result)
                         else "") + "(N for a force, N·m "
                      "for a moment or torque; added_mass: kg added)",
                      "max_ground_reaction": "N",
                      "gap": "relative to scale (of √J when rms is given, else of J)",
                      "scale, rms, rms_lower_bound, rms_gap": "N·m", "time": "s",
                      "mass, added_mass": "kg", "inertia": "kg·m²", "e, f, s": "m",
                      **({} if result.rotor_masses is None else {
                          "mr": "kg·m", "phase_deg": "degrees at θ1 = 0", "z, at": "m",
                          "max_bearing_load": "N"}),
                      "sigma": "rad", "disc radius, thickness": "m",
                      **({"speed_fluctuation": "(ω_max − ω_min)/ω_mean; flywheel, "
                          "inertia_added, counter_rotor_added: kg·m²"}
                         if result.flywheel is not None else {}),
                      **({} if result.rotor_masses is None else {
                          "rotating_mr, reciprocating_mr, counterweight_mr": "kg·m",
                          "factor": "dimensionless: counterweight_mr / (rotating_mr + "
                                    "reciprocating_mr/2)"})},
        }
    )
    if result.flywheel is not None:
        doc["speed_fluctuation"] = result.flywheel.as_dict()
    factors = result.original.balance_factors(result.linkage)
    if factors is not None:  # an engine's (after the keys every document has)
        doc["balance_factors"] = {"before": [t.as_dict() for t in factors[0]],
                                  "after": [t.as_dict() for t in factors[1]]}
    return doc


#: A figure that balancing multiplies by more than this is reported as made worse.
WORSE_RATIO = 2.0
#: The figures watched for getting worse, with their names and units.
_WATCHED = tuple((name, words_of(name), unit_of(name))
                 for name in ("shaking_force", "shaking_moment", "driving_torque"))


def _operating_figures(analysis: CycleAnalysis | AlongMotions) -> dict[str, Any]:
    """``optimize``'s ``before``/``after``: the analyze figures and the largest ground load."""
    return {**analysis.summary.as_dict(),
            "max_ground_reaction": analysis.summary.max_ground_reaction}


def worse_figures(before: CycleAnalysis | AlongMotions, after: CycleAnalysis | AlongMotions
                  ) -> list[str]:
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


def flywheel_line(sizing: FlywheelSizing) -> str:
    """What ``[balance] max_speed_fluctuation`` did: the fluctuations and the flywheel added."""
    def delta(value: float) -> str:
        return f"{value:.4g}" if math.isfinite(value) else "∞ (it cannot run at that speed)"

    head = (f"speed fluctuation (ω_max − ω_min)/ω_mean at most {sizing.bound:g} "
            f"(balance.max_speed_fluctuation): {delta(sizing.before)} original, "
            f"{delta(sizing.balanced)} balanced")
    if not sizing.added:
        return head + " (no flywheel needed)"
    shares = [f"{value:.6g} on its inertia" if what == "inertia" else
              f"{value:.6g} on its counter-rotor"
              for what, value in (("inertia", sizing.inertia),
                                  ("counter_rotor", sizing.counter_rotor)) if value]
    return (head + f", {delta(sizing.after)} with a flywheel of {sizing.added:.6g} kg·m² on "
            f"the {sizing.crank} ({', '.join(shares)})")


def _objective_terms(result: BalanceResult) -> dict[str, dict[str, float | str]]:
    """Each term of the objective: its weight and unit, its RMS before and after (inertial)."""
    before, after = result.term_rms(result.before), result.term_rms(result.after)
    return {t.name: {"weight": t.weight, "unit": t.unit, "before": before[t.name],
                     "after": after[t.name]} for t in result.weights.terms}


def _objective_terms_lines(result: BalanceResult, sc: Scales, where: str) -> list[str]:
    """The objective's terms as a table (none with one term: the headline says it)."""
    if result.single_term is not None:
        return []
    largest = _largest_terms(result)
    rows = [[name.replace("_", " "), f"{t['weight']:.4g}",
             sc.fmt(float(t["before"]), str(t["unit"])),
             sc.fmt(float(t["after"]), str(t["unit"])), str(t["unit"])]
            for name, t in _objective_terms(result).items()]
    squares = ("mean square" if not largest else
               "mean square, or the square of the largest")
    return [f"objective J = Σ weight × {squares} (added mass: weight × kg added), "
            f"{where}:", table(rows, ["term", "weight", "RMS before", "RMS after", "unit"])
            + "".join(f"\n{name.replace('_', ' ')}: its largest, not its RMS"
                      for name in largest), ""]


def _largest_terms(result: BalanceResult) -> tuple[str, ...]:
    """The objective's terms that weigh a largest load (not a mean square)."""
    return tuple(t.name for t in result.weights.terms if QUANTITIES[t.name].largest)


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
        rows.append(["crankshaft" if c.crankshaft == 1 else f"crankshaft {c.crankshaft}",
                     f"{1e3 * c.z:.6g}", f"{c.mr:.6g}",
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
        for k in sorted({c.crankshaft for c in masses.counterweights} - {1}):
            point = f"O{k}"  # (a geared crankshaft's axis)
            if point in before.reactions.ground and point in after.reactions.ground:
                b, a = before.summary.ground[point].max, after.summary.ground[point].max
                notes.append(f"crankshaft {k}'s bearings' net reaction R{point}: largest "
                             f"{b:.6g} N before, {a:.6g} N after")
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


def optimization_scales(result: BalanceResult, before: CycleAnalysis | AlongMotions,
                        after: CycleAnalysis | AlongMotions) -> Scales:
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


def optimization_text(result: BalanceResult, before: CycleAnalysis | AlongMotions,
                      after: CycleAnalysis | AlongMotions,
                      verification: Verification | MotionVerification | None = None,
                      spec: str | None = None) -> str:
    """The readable ``optimize`` report."""
    if isinstance(before, AlongMotions) or isinstance(after, AlongMotions):
        assert isinstance(before, AlongMotions) and isinstance(after, AlongMotions)
        assert verification is None or isinstance(verification, MotionVerification)
        return _along_motions_text(result, before, after, verification, spec)
    head = f"balancer optimize — {spec}" if spec else "balancer optimize"
    lines = [
        head,
        f"backend {result.backend}: {result.message}",
        f"{result.iterations} solver iterations in {1e3 * result.time:.1f} ms "
        f"({', '.join(s.name for s in result.stages)}); the objective is the "
        f"{'' if _largest_terms(result) else 'mean-square '}inertial shaking (loads left out)",
        "",
    ]
    sc = optimization_scales(result, before, after)
    rows = []
    planes = () if in_one_plane(after.mechanism) else ("rocking_couple",)
    for name in ("shaking_force", "shaking_moment", "driving_torque", *planes):
        b, a = getattr(before.summary, name), getattr(after.summary, name)
        unit = unit_of(name)
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
    lines += _objective_terms_lines(result, sc, "inertial shaking at the operating speed")
    if result.flywheel is not None:
        lines += [flywheel_line(result.flywheel), ""]
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
    lines.append(force_balance_line(after))
    if verification is not None:
        assert not isinstance(verification, MotionVerification)  # (one input: a revolution)
        lines.append("")
        lines.append(verification_text(verification).split("\n", 1)[1].strip("\n"))
    return "\n".join(lines)


def _along_motions_text(result: BalanceResult, before: AlongMotions, after: AlongMotions,
                        verification: MotionVerification | None, spec: str | None) -> str:
    """``optimize``'s report of a linkage with several inputs, along its motions."""
    from .along import force_balance_words  # (the analysis' words along motions)

    head = f"balancer optimize — {spec}" if spec else "balancer optimize"
    names = ", ".join(a.name for a in before.motions)
    lines = [
        head,
        f"backend {result.backend}: {result.message}",
        f"{result.iterations} solver iterations in {1e3 * result.time:.1f} ms "
        f"({', '.join(s.name for s in result.stages)}); the objective is the mean-square "
        f"inertial shaking along the motions ({names}; loads left out)",
        "",
    ]
    sc = optimization_scales(result, before, after)
    rows = []
    for b_motion, a_motion in zip(before.motions, after.motions, strict=True):
        b_loads, a_loads = b_motion.loads(), a_motion.loads()
        for key, b in b_loads.items():
            if key == "rocking_couple" and in_one_plane(after.mechanism):
                continue
            a = a_loads[key]
            words, unit = load_words(after.mechanism, key)
            rows.append([f"{b_motion.name}: {words}", sc.fmt(b.rms, unit), sc.fmt(a.rms, unit),
                         sc.ratio(a.rms, b.rms, unit), sc.fmt(b.max, unit), sc.fmt(a.max, unit),
                         unit])
    lines.append(table(rows, ["along the motions", "RMS before", "RMS after", "ratio",
                              "max before", "max after", "unit"]))
    lines += [f"warning: {w}" for w in worse_figures(before, after)]
    lines.append("")
    lines += _objective_terms_lines(
        result, sc, "inertial shaking along the motions, each motion by its weight")
    lines += [_parameters_text(result), "", counterweight_text(result.counterweights), "",
              force_balance_words(after)]
    if verification is not None:
        lines += ["", motion_verification_text(verification).split("\n", 1)[1].strip("\n")]
    return "\n".join(lines)
