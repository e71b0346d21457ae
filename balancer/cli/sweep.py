"""``balancer sweep``: the certified optimum over a design space, on a Dask cluster."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import OutputError, SpecError
from ..plots import save_figure
from ..progress import Progress
from ..report import dumps_json, sweep_text
from ..sweeps import Perturb, Vary, atlas_figure, spec_values, sweep
from .common import figure_path, load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer sweep``; the exit code."""
    varies = [Vary.parse(text) for text in args.vary or ()]
    perturbs = [Perturb.parse(text) for text in args.perturb or ()]
    if not varies and not perturbs:
        raise SpecError("nothing to vary: give --vary KEY=LOW:HIGH:N (or --perturb KEY=SIGMA)",
                        key="--vary")
    if not args.out.endswith(".parquet"):
        raise OutputError("must name a .parquet file", key="--out", value=args.out)
    out = output_path(args, args.out, "--out") if not args.resume else Path(args.out)
    plot = figure_path(args, args.plot, "--plot")
    load(args)  # its own errors, and a note for a unit that looks wrong
    with Progress("sweeping", unit="points", enabled=not args.json) as progress:
        result = sweep(args.spec, varies, out, perturbs=perturbs, method=args.method,
                       samples=args.samples,
                       seed=args.seed, workers=args.workers, scheduler=args.scheduler,
                       resume=args.resume, force=args.force, batch=args.batch,
                       progress=progress)
    for note in result.notes:
        print(f"balancer: note: {note}", file=sys.stderr)
    wrote(result.out)
    if plot is not None:
        keys = [v.key for v in varies]
        original = spec_values(args.spec, keys or [p.key for p in perturbs])
        save_figure(atlas_figure(result.out, keys or None, original=original,
                                 perturbs=perturbs, headline=result.headline), plot)
    sys.stdout.write(dumps_json(result.as_dict()) if args.json
                     else sweep_text(result, spec=args.spec) + "\n")
    if plot is not None:
        wrote(plot)
    return 0
