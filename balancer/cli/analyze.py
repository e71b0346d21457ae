"""``balancer analyze``: one revolution at the operating speed, as a table, JSON or CSV."""

from __future__ import annotations

import argparse
import sys

from ..api import analyze
from ..errors import SpecError
from ..outputs import write_atomic
from ..report import analysis_csv, analysis_json, analysis_text, dumps_json
from .common import load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer analyze``; the exit code."""
    csv_path = output_path(args, args.csv, "--csv")
    design = load(args)
    try:
        analysis = analyze(design, route=args.route, gravity=args.gravity)
    except SpecError as exc:
        if exc.key == "gravity":  # the option's value, not the spec's
            raise SpecError(exc.detail, key="--gravity", value=",".join(
                map(format, args.gravity))) from None
        raise
    csv = analysis_csv(analysis) if csv_path is not None else None
    if args.json:
        text = dumps_json(analysis_json(analysis, spec=args.spec))
    else:
        text = analysis_text(analysis, spec=args.spec) + "\n"
    if csv_path is not None:
        assert csv is not None  # (made above for that path)
        write_atomic(csv_path, csv)
        wrote(csv_path)
    sys.stdout.write(text)
    return 0
