"""``balancer analyze``: one revolution at the operating speed, or along the spec's motions.

As a table, JSON or CSV.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

from ..api.analysis import analyze, analyze_motions, flywheel, several_inputs
from ..errors import SpecError
from ..model import Design
from ..outputs import write_atomic
from ..report import (
    analysis_csv,
    analysis_json,
    analysis_text,
    dumps_json,
)
from .common import load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer analyze``; the exit code."""
    csv_path = output_path(args, args.csv, "--csv")
    design = load(args)
    if args.motion is not None or several_inputs(design):
        return _along_motions(args, design, csv_path)
    try:
        analysis = analyze(design, route=args.route, gravity=args.gravity)
    except SpecError as exc:
        _option_error(args, exc)
        raise
    asked = design.operation is not None and design.operation.speed_fluctuation is not None
    wheel = flywheel(design, gravity=args.gravity) if asked else None
    return _emit(args, csv_path, lambda: analysis_csv(analysis),
                 lambda: dumps_json(analysis_json(analysis, spec=args.spec, flywheel=wheel)),
                 lambda: analysis_text(analysis, spec=args.spec, flywheel=wheel) + "\n")


def _option_error(args: argparse.Namespace, exc: SpecError) -> None:
    """Raise ``exc`` as the option's error where it is about ``--gravity``'s value."""
    if exc.key == "gravity":  # the option's value, not the spec's
        raise SpecError(exc.detail, key="--gravity", value=",".join(
            map(format, args.gravity))) from None


def _along_motions(args: argparse.Namespace, design: Design, csv_path: str | None) -> int:
    """``analyze`` along the spec's motions (all, or ``--motion``'s)."""
    # (the loads along motions' report: loaded when a spec has motions)
    from ..report import motion_csv, motions_json, motions_text

    if design.operation is not None and design.operation.speed_fluctuation is not None:
        raise SpecError("sizes a flywheel on a crank: a linkage with several inputs, or a "
                        "motion, has none", key="operation.speed_fluctuation",
                        value=design.operation.speed_fluctuation)
    if csv_path is not None and args.motion is None and len(design.motions) > 1:
        raise SpecError("writes one motion's values: name it with --motion "
                        f"({', '.join(m.name for m in design.motions)})", key="--csv",
                        value=str(csv_path))
    try:
        analyses = analyze_motions(design, [args.motion] if args.motion else None,
                                   gravity=args.gravity)
    except SpecError as exc:
        _option_error(args, exc)
        raise
    return _emit(args, csv_path, lambda: motion_csv(analyses.motions[0]),
                 lambda: dumps_json(motions_json(analyses, spec=args.spec)),
                 lambda: motions_text(analyses, spec=args.spec) + "\n")


def _emit(args: argparse.Namespace, csv_path: str | None, csv: Callable[[], str],
          json_text: Callable[[], str], table_text: Callable[[], str]) -> int:
    """Make every output first, then write the CSV file whole and print: nothing partial."""
    csv_text = csv() if csv_path is not None else None
    text = json_text() if args.json else table_text()
    if csv_path is not None:
        assert csv_text is not None  # (made above for that path)
        write_atomic(csv_path, csv_text)
        wrote(csv_path)
    sys.stdout.write(text)
    return 0
