"""Presentation of results: readable tables, JSON documents and CSV files.

Computation lives elsewhere; these modules only turn result objects into text, one module per
command family: :mod:`.text` (tables, JSON and CSV forms), :mod:`.analysis` (``analyze``),
:mod:`.motion` (``simulate``, ``verify``), :mod:`.balancing` (``optimize``), :mod:`.fronts`
(``pareto``, ``sweep``), :mod:`.parts` (counterweights as parts). Each is loaded when one of
its names is first used (PEP 562): the analysis' report does not load the balancing's. The
JSON field names that other tools rely on are fixed in DESIGN.md.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..lazy import lazy_exports

#: Where each name lives.
_EXPORTS = {
    "dimensions": "parts",
    "dimensions_text": "parts",
    "parts_json": "parts",
    "parts_text": "parts",
    "table": "text",
    "markdown_table": "text",
    "dumps_json": "text",
    "csv_text": "text",
    "reaction_extremes": "analysis",
    "figures_dict": "analysis",
    "orders_list": "analysis",
    "analysis_figures": "analysis",
    "orders_text": "analysis",
    "analysis_json": "analysis",
    "analysis_text": "analysis",
    "force_balance_line": "analysis",
    "analysis_csv": "analysis",
    "motions_text": "along",
    "motions_json": "along",
    "motion_csv": "along",
    "simulation_csv": "motion",
    "simulation_json": "motion",
    "simulation_text": "motion",
    "verification_text": "motion",
    "motion_run_text": "motion_runs",
    "motion_run_json": "motion_runs",
    "motion_run_csv": "motion_runs",
    "motion_verification_text": "motion_runs",
    "link_parameters": "balancing",
    "optimization_json": "balancing",
    "WORSE_RATIO": "balancing",
    "worse_figures": "balancing",
    "counterweight_text": "balancing",
    "rotor_masses_text": "balancing",
    "balance_factors_text": "balancing",
    "MARKED_CHANGE": "balancing",
    "optimization_scales": "balancing",
    "optimization_text": "balancing",
    "front_json": "fronts",
    "front_text": "fronts",
    "front_csv": "fronts",
    "SweepSummary": "fronts",
    "sweep_text": "fronts",
}

__all__ = [
    "dimensions",
    "dimensions_text",
    "parts_json",
    "parts_text",
    "MARKED_CHANGE",
    "SweepSummary",
    "WORSE_RATIO",
    "analysis_csv",
    "motion_csv",
    "motion_run_csv",
    "motion_run_json",
    "motion_run_text",
    "motion_verification_text",
    "motions_json",
    "motions_text",
    "analysis_figures",
    "analysis_json",
    "analysis_text",
    "balance_factors_text",
    "counterweight_text",
    "csv_text",
    "dumps_json",
    "figures_dict",
    "force_balance_line",
    "front_csv",
    "front_json",
    "front_text",
    "link_parameters",
    "markdown_table",
    "optimization_json",
    "optimization_scales",
    "optimization_text",
    "orders_list",
    "orders_text",
    "reaction_extremes",
    "rotor_masses_text",
    "simulation_csv",
    "simulation_json",
    "simulation_text",
    "sweep_text",
    "table",
    "verification_text",
    "worse_figures",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())


if TYPE_CHECKING:  # for type checkers and editors: the names as they are
    from .along import motion_csv, motions_json, motions_text
    from .analysis import (
        analysis_csv,
        analysis_figures,
        analysis_json,
        analysis_text,
        figures_dict,
        force_balance_line,
        orders_list,
        orders_text,
        reaction_extremes,
    )
    from .balancing import (
        MARKED_CHANGE,
        WORSE_RATIO,
        balance_factors_text,
        counterweight_text,
        link_parameters,
        optimization_json,
        optimization_scales,
        optimization_text,
        rotor_masses_text,
        worse_figures,
    )
    from .fronts import (
        SweepSummary,
        front_csv,
        front_json,
        front_text,
        sweep_text,
    )
    from .motion import (
        simulation_csv,
        simulation_json,
        simulation_text,
        verification_text,
    )
    from .motion_runs import (
        motion_run_csv,
        motion_run_json,
        motion_run_text,
        motion_verification_text,
    )
    from .parts import dimensions, dimensions_text, parts_json, parts_text
    from .text import (
        csv_text,
        dumps_json,
        markdown_table,
        table,
    )
