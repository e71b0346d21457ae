"""``balancer simulate``: forward dynamics in a formulation of the user's choice."""

from __future__ import annotations

import argparse
import sys

from ..api import simulate
from ..errors import SpecError
from ..outputs import write_atomic
from ..progress import Progress
from ..report import dumps_json, simulation_csv, simulation_json, simulation_text
from .common import SIMULATE_OPTIONS, load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer simulate``; the exit code."""
    out = output_path(args, args.out, "--out")
    design = load(args)
    progress = Progress("simulating", enabled=not args.json)
    try:
        traj = simulate(
            design,
            method=args.method,
            drive=args.drive,
            duration=args.duration,
            rtol=args.rtol,
            atol=args.atol,
            outputs=args.outputs,
            progress=progress,
        )
    except SpecError as exc:
        name = (exc.key or "").removeprefix("simulation.")  # a setting, or the spec's key
        if name in SIMULATE_OPTIONS and getattr(args, name) is not None:
            raise SpecError(exc.detail, key=f"--{name}", value=exc.value) from None
        raise
    finally:
        progress.close()
    csv = simulation_csv(traj, all_columns=args.all_columns) if out is not None else None
    if args.json:
        text = dumps_json(simulation_json(traj, spec=args.spec))
    else:
        text = simulation_text(traj, spec=args.spec) + "\n"
    if out is not None:
        assert csv is not None  # (made above for that path)
        write_atomic(out, csv)
        wrote(out)
    sys.stdout.write(text)
    return 0
