"""``search``'s report: the ranked cranks and firing orders, as a table and a JSON document."""

from __future__ import annotations

from typing import Any

from ..arrangements import ROUNDING, Arrangement, Search
from ..model import Design
from ..rounding import Scales, speed_text
from .text import table


def search_text(found: Search, design: Design, spec: str | None = None) -> str:
    """The readable ``search`` report: one row per crank and firing order, best first."""
    head = f"balancer search — {spec}" if spec else "balancer search"
    rows = []
    # (a figure at rounding of its unit's scale prints as 0: the free loads of a balanced
    # crank, beside a cylinder's own force m·r·ω²)
    sc = Scales([("N", found.scale), *((unit, value) for a in found.arrangements
                                       for unit, value in _figures(a))])

    def fmt(value: float, unit: str) -> str:
        return sc.number(value, unit)

    rounding = ROUNDING * found.torque_scale
    for a in found.arrangements:
        lowest = a.lowest_torque_order(rounding)
        rows.append([str(a.rank), " ".join(f"{p:g}" for p in a.phases),
                     "-".join(str(k) for k in a.firing_order),
                     " ".join(f"{i:g}" for i in a.intervals),
                     *(fmt(value, unit) for unit, value in _figures(a)),
                     "—" if lowest is None else f"{lowest:g}", str(a.same_half),
                     *([] if a.balanced is None else [f"{a.balanced.objective:.6g}",
                                                      str(a.balanced.status)])])
    balanced = bool(found.arrangements) and found.arrangements[0].balanced is not None
    which = ("every crank whose cylinders fire evenly" if found.step is None else
             f"every crank whose pins are a multiple of {found.step:g}° apart and every firing "
             "order that fits in the working cycle")
    return "\n".join([
        head,
        f"{design.title or 'engine'}: {which}, at {speed_text(found.speed)}; each cylinder's "
        "rods and pistons (the crankshaft's own masses left out), ranked by what crank "
        "counterweights cannot take, then by the driving torque's energy swing",
        "",
        table(rows, ["rank", "pin phases (°, by cylinder)", "firing order", "intervals (°)",
                     "F1 bwd (N)", "C1 bwd (N·m)", "F2 (N)", "C2 (N·m)", "ΔE (J)",
                     "F1 fwd (N)", "C1 fwd (N·m)", "T lowest order", "same half",
                     *(["balanced J", "status"] if balanced else [])]),
        "",
        "F1/C1: the primary force and couple, bwd turning against the crank (left free), fwd "
        "with it (what counterweights can take); F2/C2: the secondary force and couple, both "
        "whirls; intervals: the crank angles from each firing to the next; ΔE: the energy "
        "swing of the driving torque (inertial, and the gas where [gas] gives it) over the "
        "working cycle, what a flywheel must hold; T lowest order: the driving torque's lowest "
        "order; same half: firings that follow one another in the same half of the crank"
        + ("; balanced J: the objective of [balance] left by the certified counterweights and "
           "shafts of each ((N·m)²)" if balanced else ""),
    ])


def _figures(a: Arrangement) -> list[tuple[str, float]]:
    """An arrangement's figures in the table's order, each with its unit."""
    return [("N", a.free["force_1_backward"]), ("N·m", a.free["couple_1_backward"]),
            ("N", a.free["force_2"]), ("N·m", a.free["couple_2"]), ("J", a.energy_swing),
            ("N", a.counterweights["force_1_forward"]),
            ("N·m", a.counterweights["couple_1_forward"])]


def search_json(found: Search, spec: str | None = None) -> dict[str, Any]:
    """The ``search --json`` document."""
    doc: dict[str, Any] = {} if spec is None else {"spec": spec}
    doc.update({"speed": found.speed, "scale": found.scale, "step_deg": found.step,
                "arrangements": [a.as_dict() for a in found.arrangements],
                "units": {"force_1_backward, force_1_forward, force_2": "N",
                          "couple_1_backward, couple_1_forward, couple_2": "N·m",
                          "phases_deg, firing_intervals_deg, step_deg": "°",
                          "energy_swing": "J", "torque_orders": "N·m (amplitude)",
                          "scale": "N (a cylinder's m·r·ω²)"}})
    return doc
