"""Two outputs of one command compared figure by figure, each to what it is certified to.

A recorded output (``tests/golden/outputs``) and the same command's output now, on any machine:
the text between the figures must be the same (counters of a solver's or an integrator's path
and the stages' own solver statuses masked: another machine's rounding may take a step more),
and each figure the same to the tolerance of **what it is**:

``EXACT``
    A closed form or a compiled kernel's figure (``analyze``; a redesign's *before* figures):
    to :data:`EXACT_RELATIVE` of itself (a few thousand ulp, the condition of the formulas at
    the shipped examples' poses), or :data:`EXACT_OF_SCALE` of its quantity's scale (the
    largest figure of the same quantity in the output: a balanced design's 1e-13 N beside its
    original's 697 N is rounding, another machine prints another).
``integrated``
    An integrator's figure (``simulate``, ``verify``): each of its ``N`` accepted steps keeps its
    local error within ``rtol`` of the state, so ``N·rtol`` bounds the global error of a
    non-expanding run (a free 1-DOF run's phase drifts linearly), relative to the figure or its
    quantity's scale. ``N`` and ``rtol`` are the run's own, read from the recorded output.
``objective``
    A certified optimum's objective (``objective``, ``rms`` and their lower bounds): within
    :data:`GAP_TOLERANCE` of the problem's scale (squared for the mean square ``J``), what the
    certificate guarantees.
``design``
    A figure of the optimum's design (its parameters, counterweights, the *after* figures
    other than the objective, the verification of the design): the certificate bounds the
    objective only, and a design whose objective is within ``ε = GAP_TOLERANCE`` of the optimum
    lies within ``√(2ε)`` of it (relative to the quantity's scale) in any direction where the
    objective has unit curvature, and anywhere along a flat valley where it has none (the
    optimum is not unique there: the Stephenson six-bar's driving torque, the Jansen leg's).
    Compared to ``√(2ε)`` of itself or its quantity's scale: it guards against a design that is
    no longer the optimum, not against the optimiser's choice within the optimal set.
error measures
    A figure that measures an error (an optimality gap, the force-balance residual, an energy
    balance's error) is compared by the bound it is certified to: both within it.

Angles (a centre of mass's ``sigma``, a phase) are compared on the circle. A text output (a
table, a written spec) guards the wording and the layout: its figures are compared by its verb's
loosest rule (the JSON output of the same run compares each figure by what it is), a figure's
scale is the largest figure on its line (a table's row), two figures below :data:`TEXT_NOISE`
of the output's largest are both rounding, and a table's figure printed to a few digits may
also differ by one unit of its last digit.
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from balancer.balance.feasibility import ROUNDING_TOLERANCE
from balancer.balance.result import GAP_TOLERANCE

#: Where the total centre of mass stands still (a design force-balanced by its symmetry), its
#: excursion is the rounding of the points' positions: of a machine within metres, m.
POSITION_ROUNDING = 1e-12
#: A closed form's or a compiled kernel's figures on another machine's arithmetic (another
#: SIMD width, another BLAS core, FMA or not): relative to the figure, and to the scale of its
#: quantity in the output.
EXACT_RELATIVE = 1e-9
EXACT_OF_SCALE = 1e-12
#: A design figure, relative to itself or its quantity's scale: √(2·GAP_TOLERANCE).
DESIGN_RELATIVE = math.sqrt(2.0 * GAP_TOLERANCE)
#: In a text table, a figure below this share of the output's largest figure is rounding (a
#: balanced design's shaking force, an optimality gap, a residual).
TEXT_NOISE = 1e-9

#: A number as the outputs print it (JSON, tables, CSV, TOML).
NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")
#: Counters of a solver's or an integrator's path, which rounding on another machine's
#: arithmetic may lengthen or shorten by a step, and a stage's own solver status (Clarabel's
#: "optimal" or "optimal_inaccurate", IPOPT's "Solve_Succeeded" or "Solved_To_Acceptable_Level":
#: the design's status, ``status``, is compared): masked.
_COUNTERS = re.compile(r'("(?:iterations|steps|nfev|evaluations)": )\d+'
                       r'|("solver_status": )"[^"]*"'
                       r"|\b\d+( solver iterations| steps| right-hand sides| evaluations)")


@dataclass(frozen=True)
class Tolerance:
    """``|a − b| ≤ relative·max(|a|, |b|)``, ``≤ of_scale·scale`` (its quantity's scale) or
    ``≤ absolute``."""

    relative: float
    of_scale: float
    absolute: float = 0.0

    def allows(self, a: float, b: float, scale: float, printed: float = 0.0) -> bool:
        """Whether ``a`` and ``b`` agree (``printed``: one unit of a table's last digit)."""
        if math.isinf(self.relative):  # not compared (ANY)
            return True
        d = abs(a - b)
        return d <= max(self.relative * max(abs(a), abs(b)), self.of_scale * scale,
                        self.absolute, printed)

    def loosest(self, other: Tolerance) -> Tolerance:
        """The looser of the two in each part (a design's figure found by an integrator)."""
        return Tolerance(max(self.relative, other.relative), max(self.of_scale, other.of_scale),
                         max(self.absolute, other.absolute))


@dataclass(frozen=True)
class Bound:
    """An error measure: both figures within ``limit``, or else agreeing by ``otherwise``."""

    limit: float
    otherwise: Tolerance | None = None

    def allows(self, a: float, b: float, scale: float, printed: float = 0.0) -> bool:
        """Whether both are within the bound, or agree as ``otherwise`` (default EXACT) says."""
        both_within = abs(a) <= self.limit and abs(b) <= self.limit
        return both_within or (self.otherwise or EXACT).allows(a, b, scale, printed)


EXACT = Tolerance(EXACT_RELATIVE, EXACT_OF_SCALE)
DESIGN = Tolerance(DESIGN_RELATIVE, DESIGN_RELATIVE)
#: A planned time law's objective (``plan``): IPOPT's optimum of a convex transcription, its
#: objective of order one to 1e-10, known from another start to a few 1e-9 of itself.
PLAN_GAP = 1e-8
PLAN_OBJECTIVE = Tolerance(PLAN_GAP, PLAN_GAP)
#: A planned time law's figures (its pace, the loads along it): within √(2ε) of the optimum.
PLAN_DESIGN = Tolerance(math.sqrt(2.0 * PLAN_GAP), math.sqrt(2.0 * PLAN_GAP))
#: A figure that is not compared: of a design that the optimum leaves free (see ``unique``).
ANY = Tolerance(math.inf, math.inf)
Rule = Tolerance | Bound


def integrated(rtol: float, steps: int, travel: float = 0.0) -> Tolerance:
    """An integrator's figures after ``steps`` steps at ``rtol``, its angles up to ``travel``.

    Each step keeps its local error within ``rtol`` of the state, so ``N·rtol`` bounds the
    relative error of a non-expanding run's state; an angle grown to ``travel`` rad is known to
    ``N·rtol·travel`` rad, and a figure that turns with it (a shaking force sampled over a run
    of many revolutions) to that share of its scale. At least :data:`EXACT`.
    """
    t = max(EXACT_RELATIVE, rtol * max(steps, 1) * max(1.0, travel))
    return Tolerance(t, max(EXACT_OF_SCALE, t))


def masked(text: str) -> str:
    """``text`` with the counters and the stages' solver statuses masked."""
    def one(m: re.Match[str]) -> str:
        if m.group(2):
            return m.group(2) + '"<status>"'
        return (m.group(1) or "") + "<n>" + (m.group(3) or "")
    return _COUNTERS.sub(one, text)


def skeleton(text: str) -> list[str]:
    """The text between the numbers, a table's padding and rules reduced to one character.

    (A figure printed one digit shorter narrows its column.)
    """
    return [re.sub(r"-{2,}", "-", re.sub(r"[ \t]+", " ", part)) for part in NUMBER.split(text)]


def last_digit(token: str) -> float:
    """The value of one unit in the last printed digit of a number of fewer than 15 digits."""
    mantissa, _, exponent = token.lower().lstrip("+-").partition("e")
    digits = mantissa.replace(".", "").lstrip("0")
    if len(digits) >= 15:  # a full repr: compared by its tolerance alone
        return 0.0
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (int(exponent or 0) - decimals)


# ---- what each figure is ---------------------------------------------------------------------

#: The quantity a JSON figure measures, from its path (dotted, list items as ``[]``): figures
#: of one quantity share a scale (before and after, each link's, each order's). The first
#: pattern that matches names it; otherwise the path with names and items left out.
_QUANTITIES: tuple[tuple[str, str], ...] = (
    (r"(^|\.)(max_|original_max_)?shaking_force\b|reactions\.|max_ground_reaction"
     r"|bearing_load", "force"),
    (r"(^|\.)(max_|original_max_)?(shaking_moment|rocking_couple)\b"
     r"|driving_torque|mount_torque|couple_max", "moment"),
    (r"(^|\.)(mass|added_mass)$", "mass"),
    (r"(^|\.)(e|f|s)$|disc\.(radius|thickness)$", "length"),
    (r"(^|\.)(inertia|counter_rotor)$", "inertia"),
    (r"first_moment|(^|\.)mr$", "first moment"),
    (r"(^|\.)sigma$", "angle"),
    (r"(^|\.)phase_deg$", "degrees"),
    (r"(^|\.)theta\b", "theta"),
    (r"(^|\.)omega\b", "omega"),
    (r"(^|\.)alpha\b", "alpha"),
)


def quantity(path: str) -> str:
    """The quantity the figure at ``path`` measures (its scale's group)."""
    for pattern, name in _QUANTITIES:
        if re.search(pattern, path):
            return name
    return path


#: Periods of the quantities compared on the circle.
_PERIODS = {"angle": 2 * math.pi, "degrees": 360.0}


def _travel(doc: dict) -> float:
    """The largest angle a simulation's runs reach, rad (their states' or revolutions')."""
    angles = [abs(float(v)) for k in ("initial", "final") if isinstance(doc.get(k), dict)
              for _, v in _figures(doc[k].get("theta")) if _is_figure(v)]
    revolutions = [abs(r.get("revolutions") or 0.0) for r in doc.values() if isinstance(r, dict)]
    return max([*angles, *(2 * math.pi * (r + 1) for r in revolutions)], default=0.0)


def _runs_tolerance(doc: dict, *, turning: bool = True) -> Tolerance:
    """:func:`integrated` of a simulation's document: its runs' steps, rtol and (for a figure
    that turns with the angles, ``turning``) travel."""
    runs = [doc] if "steps" in doc else [v for v in doc.values()
                                          if isinstance(v, dict) and "steps" in v]
    steps = max((r.get("steps") or 0 for r in runs), default=0)
    rtol = max((r.get("rtol") or 0.0 for r in runs), default=0.0)
    return integrated(rtol, steps, _travel(doc) if turning else 0.0)


def _optimize_rule(path: str, doc: dict, unique: bool = True) -> Rule:
    """What a figure of ``optimize --json`` is (see the module docstring).

    Where the optimum is not ``unique`` (the objective leaves a valley of optimal designs, and
    the tie-break's choice in it is only as well determined as its solve), the design's own
    figures are not compared: only what the optimum fixes is — the objective and its bound,
    the figures of the quantities it weighs (a function of ``y = P·u``, unique), the
    constraints met (the shaking force of a force-balanced design), the original's figures.
    """
    scale = float(doc.get("scale") or 0.0)
    squared = doc.get("rms") is None  # J and its bound in J's unit, the scale's square
    if re.match(r"(inertial\.)?before\.|original_links\.|orders\.before\.|original_objective$"
                r"|scale$|objective_terms\.[^.]+\.(before|weight)$", path):
        return EXACT
    if path in ("objective", "lower_bound", "stages[].objective"):
        # (where rms is given, the gap is of √J: J within (√J + ε·s)² − J = ε·s·(2√J + ε·s))
        gap = GAP_TOLERANCE * scale
        root = math.sqrt(abs(float(doc.get("objective") or 0.0)))
        return Tolerance(EXACT_RELATIVE, EXACT_OF_SCALE,
                         GAP_TOLERANCE * scale**2 if squared else gap * (2 * root + gap))
    if path in ("rms", "rms_lower_bound"):
        return Tolerance(EXACT_RELATIVE, EXACT_OF_SCALE, GAP_TOLERANCE * scale)
    if path == "gap":  # relative to the scale (of √J where rms is given, else of J)
        return Bound(GAP_TOLERANCE)
    if path == "rms_gap":
        return Bound(GAP_TOLERANCE * scale)
    if path == "force_balance_residual":  # a constraint met, or the design's own figure
        return Bound(ROUNDING_TOLERANCE, DESIGN if unique else ANY)
    if path.startswith("verification."):
        if not unique:  # a simulation of a design the optimum leaves free
            return ANY
        run = _runs_tolerance(doc.get("verification") or {})
        if path.endswith("energy_error"):
            return Bound(_runs_tolerance(doc["verification"], turning=False).relative)
        if path.endswith("force_ratio") and _rounding_force(doc["verification"], path, run):
            return ANY  # (a ratio of two roundings: the original force-balanced too)
        if re.search(r"_(ratio|level)$", path):  # to the original's (or the reactions'): 1
            return Bound(DESIGN_RELATIVE, DESIGN.loosest(run))
        return DESIGN.loosest(run)
    if unique:
        return DESIGN
    fixed = "|".join(re.escape(k) for k in _weighed(doc))
    if re.match(rf"((inertial\.)?after\.|orders\.after\[\]\.)({fixed})\b"
                rf"|objective_terms\.({fixed})\.after$", path):
        return DESIGN
    return ANY


def _weighed(doc: dict | None) -> list[str]:
    """The quantities an optimisation's objective weighs (``objective_terms``), and the
    shaking force (a force-balanced design's constraint: rounding)."""
    terms = (doc or {}).get("objective_terms") or {}
    return [*(k for k, t in terms.items() if isinstance(t, dict) and t.get("weight")
              and k != "added_mass"), "shaking_force"]


def fixed_lines(doc: dict | None) -> Callable[[str], str]:
    """A text report's lines about what an optimum fixes, where its design is not unique.

    The verdict (objective, bound, gap), the rows and orders of the quantities the objective
    weighs and of the shaking force, and whether it is force-balanced; the rest (the design,
    its counterweights, the warnings about its other figures) lies anywhere in the valley.
    """
    names = "|".join(re.escape(k.replace("_", " ")) for k in _weighed(doc))
    keep = re.compile(rf"^\s*(balancer optimize|backend |force-balanced|(\d+(½)?: )?({names}|"
                      rf"force (forward|backward))\b)")
    return lambda text: "\n".join(line for line in text.splitlines() if keep.match(line))


def _rounding_force(runs: dict, path: str, run: Tolerance) -> bool:
    """Whether the run at ``path`` (``….driven.force_ratio``) leaves a shaking force that is
    rounding of its reactions (its ``force_level``)."""
    level = (runs.get(path.split(".")[-2]) or {}).get("force_level")
    return level is not None and abs(float(level)) <= run.relative


def _reaction_scale(doc: dict) -> float:
    """The reactions' scale of a verification, N: each run's shaking force over its level."""
    runs = [doc] if "force_level" in doc else [v for v in doc.values() if isinstance(v, dict)]
    return max((float(r["max_shaking_force"]) / float(r["force_level"]) for r in runs
                if r.get("force_level") and r.get("max_shaking_force") is not None),
               default=0.0)


def _simulation_rule(path: str, doc: dict) -> Rule:
    """What a figure of ``simulate --json`` or ``verify --json`` is.

    A shaking force is measured against the reactions too (a force-balanced design's is
    their rounding)."""
    run = _runs_tolerance(doc)
    if re.search(r"energy_error$|formulations_agree_to$|constraint_drift\.", path):  # (relative)
        return Bound(_runs_tolerance(doc, turning=False).relative)
    if re.search(r"force_(ratio|level)$", path):  # rounding where force-balanced
        return Bound(run.relative, run)
    if path.endswith("max_shaking_force"):
        return Tolerance(run.relative, run.of_scale, run.relative * _reaction_scale(doc))
    return run


def _plan_rule(path: str, doc: dict) -> Rule:
    """What a figure of ``plan --json`` is: the path's own (exact), or the optimum's."""
    if re.match(r"(before\.|objective_before$|lower_bound$|duration_before$|intervals$)", path):
        return EXACT
    if path == "violation":
        return Bound(PLAN_GAP)
    if re.match(r"(objective_after|transcription_objective|halved_objective|starts)", path):
        return PLAN_OBJECTIVE
    return PLAN_DESIGN


def json_rules(verb: str, unique: bool = True) -> Callable[[str, dict], Rule]:
    """The rule that says what each figure of ``verb``'s JSON is (``unique``: its optimum)."""
    if verb == "plan":
        return _plan_rule
    if verb in ("optimize", "pareto"):
        return lambda path, doc: _optimize_rule(path, doc, unique)
    if verb in ("simulate", "verify"):
        return _simulation_rule
    return lambda path, doc: (Tolerance(EXACT_RELATIVE, EXACT_OF_SCALE, POSITION_ROUNDING)
                              if path == "centre_of_mass_excursion" else EXACT)


def text_rule(verb: str, text: str, sibling: dict | None = None,
              unique: bool = True) -> Tolerance:
    """The tolerance of a text output's figures: its verb's loosest.

    (The JSON output of the same run compares each figure by what it is; a text output guards
    the wording and the layout.) An integrator's run is known by the ``sibling`` JSON document
    of the same command (its steps, ``rtol``, travel), or else by what the text says
    (``rtol 1e-10: 29 steps``). An optimum that is not ``unique``: the wording alone.
    """
    if verb in ("simulate", "verify"):
        return _runs_tolerance(sibling) if sibling else _integrated_of_text(text)
    if verb == "plan":
        return PLAN_DESIGN
    if verb in ("optimize", "pareto"):
        return DESIGN.loosest(_integrated_of_text(text)) if unique else ANY
    return EXACT


def _integrated_of_text(text: str) -> Tolerance:
    steps = [int(s) for s in re.findall(r"\b(\d+) steps\b", text)]
    rtols = [float(r) for r in re.findall(r"\brtol(?: =)? ([0-9.]+(?:e[-+]?\d+)?)", text)]
    return integrated(max(rtols, default=1e-10), max(steps, default=0))


# ---- comparison ------------------------------------------------------------------------------


#: Keys of a solver's or an integrator's path (counters, a stage's own solver status) and of
#: wall-clock time: not compared (another machine's rounding may take a step more).
_UNCOMPARED = {"iterations", "steps", "nfev", "evaluations", "solver_status", "time", "seconds"}


def _figures(value: object, path: str = "") -> Iterator[tuple[str, object]]:
    """Each leaf of a document with its dotted path (list items as ``[]``)."""
    if isinstance(value, dict):
        for k, v in value.items():
            if k not in _UNCOMPARED:
                yield from _figures(v, f"{path}.{k}" if path else str(k))
    elif isinstance(value, list):
        for v in value:
            yield from _figures(v, f"{path}[]")
    else:
        yield path, value


def _is_figure(v: object) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def compare_data(recorded: dict, now: dict, rule: Callable[[str, dict], Rule],
                 text: Tolerance) -> str | None:
    """Where two parsed documents (JSON, TOML) differ beyond each figure's rule, or ``None``.

    The same keys and items; each figure by ``rule(path, recorded)``, on the circle where it
    is an angle; each string by its wording, the figures in it by ``text``.
    """
    def compared(leaves: list[tuple[str, object]]) -> list[tuple[str, object]]:
        # a leaf of a design the optimum leaves free (ANY): not compared, nor its presence
        return [(p, v) for p, v in leaves if rule(p, recorded) is not ANY]

    xs, ys = compared(list(_figures(recorded))), compared(list(_figures(now)))
    if [p for p, _ in xs] != [p for p, _ in ys]:
        return "other keys or items:\n" + _first_difference(recorded, now)
    scales: dict[str, float] = {}
    for (path, x), (_, y) in zip(xs, ys, strict=True):
        if _is_figure(x) and _is_figure(y):
            q = quantity(path)
            scales[q] = max(scales.get(q, 0.0), abs(float(x)), abs(float(y)))
    largest = max(scales.values(), default=0.0)
    for (path, x), (_, y) in zip(xs, ys, strict=True):
        if isinstance(x, str) and isinstance(y, str):
            problem = None
            if skeleton(masked(x)) != skeleton(masked(y)):
                problem = "its wording differs"
            else:
                problem = line_difference(x, y, text, largest, table=True)
            if problem is not None:
                return f"{path}: {problem}\n  recorded: {x}\n  now:      {y}"
            continue
        if not (_is_figure(x) and _is_figure(y)):
            if x != y:
                return f"{path}: recorded {x!r}, now {y!r}"
            continue
        fx, fy = float(x), float(y)
        q = quantity(path)
        period = _PERIODS.get(q)
        if period is not None:  # on the circle
            fy = fx + math.remainder(fy - fx, period)
        how = rule(path, recorded)
        if not how.allows(fx, fy, scales[q]):
            return f"{path}: recorded {x!r}, now {y!r} ({how})"
    return None


def _first_difference(a: object, b: object) -> str:
    paths_a, paths_b = [p for p, _ in _figures(a)], [p for p, _ in _figures(b)]
    for pa, pb in zip(paths_a, paths_b, strict=False):
        if pa != pb:
            return f"  recorded {pa}, now {pb}"
    return f"  {len(paths_a)} leaves recorded, {len(paths_b)} now"


#: A unit a table's row or a line ends its figures with: figures of one unit share a scale.
_UNIT = re.compile(r"(?<![\w·/])(kg·m²|N·m|kg|N|mm|m|rad/s²|rad/s|rad|s)(?![\w·²/])")
#: A figure printed right after this is an angle (a written spec's comment: ``sigma = π rad``).
_ANGLE_BEFORE = re.compile(r"(sigma|σ)\s*=\s*$")


def compare_text(recorded: str, now: str, tolerance: Tolerance, *, table: bool = True
                 ) -> str | None:
    """Where two texts differ beyond ``tolerance`` (the wording exactly), or ``None``.

    A figure's scale is the largest figure of its line's unit in the text (the largest on the
    line where it names none); two figures below :data:`TEXT_NOISE` of the text's largest are
    rounding; in a ``table`` (figures printed to a few digits), a figure may also differ by a
    unit of its last printed digit.
    """
    a, b = masked(recorded), masked(now)
    if a == b:
        return None
    lines_a, lines_b = a.splitlines(), b.splitlines()
    if len(lines_a) != len(lines_b):
        return f"a different number of lines ({len(lines_a)} recorded, {len(lines_b)} now)"
    largest = largest_figure(a)
    units: dict[str, float] = {}
    for line in lines_a + lines_b:
        unit = _UNIT.search(line)
        if unit:
            units[unit.group(1)] = max(units.get(unit.group(1), 0.0), largest_figure(line))
    for line_a, line_b in zip(lines_a, lines_b, strict=True):
        if skeleton(line_a) != skeleton(line_b):
            return f"text differs:\n  recorded: {line_a}\n  now:      {line_b}"
        unit = _UNIT.search(line_a)
        scale = units[unit.group(1)] if unit else 0.0
        problem = line_difference(line_a, line_b, tolerance, largest, table=table, scale=scale)
        if problem is not None:
            return f"{problem}\n  in: {line_b}"
    return None


def largest_figure(text: str) -> float:
    """The largest figure (in magnitude) a text prints."""
    return max((abs(float(x)) for x in NUMBER.findall(text)), default=0.0)


def line_difference(line_a: str, line_b: str, tolerance: Tolerance, largest: float, *,
                    table: bool = True, scale: float = 0.0) -> str | None:
    """The first figure of two lines of the same wording that differs beyond ``tolerance``.

    Its scale: ``scale``, or the largest figure on the line; two figures both below
    :data:`TEXT_NOISE` of ``largest`` (the text's) are rounding; in a ``table``, a unit of its
    last printed digit is allowed too; a figure after ``sigma =`` is an angle.
    """
    xs, ys = NUMBER.findall(line_a), NUMBER.findall(line_b)
    if len(xs) != len(ys):
        return "another count of figures"
    if not xs:
        return None
    scale = max(scale, *(abs(float(x)) for x in xs + ys))
    noise = TEXT_NOISE * largest
    before = NUMBER.split(line_a)
    for i, (x, y) in enumerate(zip(xs, ys, strict=True)):
        fx, fy = float(x), float(y)
        if _ANGLE_BEFORE.search(before[i]):
            fy = fx + math.remainder(fy - fx, 2 * math.pi)
        printed = 1.000001 * max(last_digit(x), last_digit(y)) if table else 0.0
        if max(abs(fx), abs(fy)) <= noise:  # both rounding (a residual, a gap)
            continue
        if not tolerance.allows(fx, fy, scale, printed):
            return f"a figure differs: recorded {x}, now {y} ({tolerance})"
    return None


def compare_csv(recorded: str, now: str, tolerance: Tolerance) -> str | None:
    """Where two CSV tables differ beyond ``tolerance``, column by column, or ``None``.

    The header must be the same; a figure's scale is the largest figure of the table (the
    columns mix angles, forces and moments of one machine: its rounding is relative to the
    largest).
    """
    rows_a, rows_b = recorded.splitlines(), now.splitlines()
    if not rows_a or rows_a[0] != (rows_b[0] if rows_b else None):
        return f"the header differs:\n  recorded: {rows_a[:1]}\n  now:      {rows_b[:1]}"
    if len(rows_a) != len(rows_b):
        return f"a different number of rows ({len(rows_a)} recorded, {len(rows_b)} now)"
    header = rows_a[0].split(",")
    table_a = [r.split(",") for r in rows_a[1:]]
    table_b = [r.split(",") for r in rows_b[1:]]
    largest = max((abs(float(v)) for r in table_a + table_b for v in r if _is_number(v)),
                  default=0.0)
    for i, (ra, rb) in enumerate(zip(table_a, table_b, strict=True), start=1):
        for column, x, y in zip(header, ra, rb, strict=True):
            if not (_is_number(x) and _is_number(y)):
                if x != y:
                    return f"row {i}, {column}: recorded {x!r}, now {y!r}"
                continue
            if not tolerance.allows(float(x), float(y), largest):
                return f"row {i}, {column}: recorded {x}, now {y} ({tolerance})"
    return None


def _is_number(v: str) -> bool:
    """A finite figure (``nan`` where a quantity is not defined is compared as text)."""
    try:
        return math.isfinite(float(v))
    except ValueError:
        return False


def compare_document(recorded: str, now: str, kind: str,
                     rule: Callable[[str, dict], Rule], text: Tolerance) -> str | None:
    """A JSON or TOML document compared figure by figure by ``rule`` (strings by ``text``)."""
    if kind == "json":
        a, b = json.loads(recorded), json.loads(now)
    else:
        a, b = tomllib.loads(recorded), tomllib.loads(now)
    return compare_data(a, b, rule, text)
