"""``balancer plan``: a motion's time law planned to shake the frame least."""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace

from ..api.planning import codesign, plan, planned_design
from ..errors import SpecError
from ..model.plan import PlanSpec
from ..outputs import write_atomic
from ..plots.plan import plan_figure
from ..plots.style import save_figure
from ..report import dumps_json
from ..report.plan import codesign_json, codesign_text, plan_json, plan_text
from ..report.text import csv_text
from ..spec import dumps_design, loads_design
from .common import as_option, figure_path, load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer plan``; the exit code."""
    out = output_path(args, args.out, "--out")
    csv = output_path(args, args.csv, "--csv")
    figure = figure_path(args, args.plot, "--plot")
    named = [(option, path) for option, path in (("--out", out), ("--csv", csv),
                                                 ("--plot", figure)) if path is not None]
    for i, (option, path) in enumerate(named):
        for other, already in named[:i]:
            if path.resolve() == already.resolve():
                raise SpecError(f"names the file {other} writes: give each output its own",
                                key=option, value=str(path))
    design = load(args)
    settings = design.plan
    changes = {key: getattr(args, key) for key in ("intervals", "measure", "duration")
               if getattr(args, key) is not None}
    for key, value in changes.items():
        try:
            settings = replace(settings or PlanSpec(), **{key: value})
        except SpecError as exc:
            raise as_option(exc, key, f"--{key}", value) from None
    together = None
    try:
        if args.with_masses:
            together = codesign(design, args.motion, settings=settings)
            result, chosen = together.plan, together.design
        else:
            result, chosen = plan(design, args.motion, settings=settings), design
    except SpecError as exc:
        for key in ("measure", "duration", "intervals"):
            exc = as_option(exc, f"plan.{key}", f"--{key}", getattr(args, key))
        raise exc from None
    spec_text = None
    if out is not None:
        spec_text = dumps_design(planned_design(chosen, result))
        loads_design(spec_text, source=str(out))  # it must load again
    if args.json:
        doc = (plan_json(result, spec=args.spec) if together is None
               else codesign_json(together, spec=args.spec))
        doc["out"] = None if out is None else str(out)
        text = dumps_json(doc)
    elif together is not None:
        text = codesign_text(together, spec=args.spec) + "\n"
    else:
        text = plan_text(result, spec=args.spec) + "\n"
    if spec_text is not None and out is not None:
        write_atomic(out, spec_text)
        wrote(out)
    if csv is not None:
        names, columns = result.after.columns()
        write_atomic(csv, csv_text(names, columns))
        wrote(csv)
    if figure is not None:
        save_figure(plan_figure(result, design.title), figure)
        wrote(figure)
    sys.stdout.write(text)
    return 0
