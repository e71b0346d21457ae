"""``balancer pareto``: the exact front of shaking moment against a second objective."""

from __future__ import annotations

import argparse
import sys

from ..api import pareto
from ..outputs import write_atomic
from ..plots import front_figure, save_figure
from ..report import dumps_json, front_csv, front_json, front_text
from .common import figure_path, load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer pareto``; the exit code."""
    csv_path = output_path(args, args.csv, "--csv")
    plot = figure_path(args, args.plot, "--plot")
    design = load(args)
    front = pareto(design, against=args.against, points=args.points)
    csv = front_csv(front) if csv_path is not None else None
    text = (dumps_json(front_json(front, spec=args.spec)) if args.json
            else front_text(front, spec=args.spec) + "\n")
    if plot is not None:
        save_figure(front_figure(front, title=design.title), plot)
        wrote(plot)
    if csv_path is not None:
        assert csv is not None  # (made above for that path)
        write_atomic(csv_path, csv)
        wrote(csv_path)
    sys.stdout.write(text)
    return 0
