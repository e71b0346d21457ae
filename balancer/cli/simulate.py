"""``balancer simulate``: forward dynamics in a formulation of the user's choice."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..api import simulate, simulate_motion
from ..api.analysis import several_inputs
from ..errors import SpecError
from ..model import Design
from ..outputs import write_atomic
from ..progress import Progress
from ..report import (
    dumps_json,
    motion_run_csv,
    motion_run_json,
    motion_run_text,
    simulation_csv,
    simulation_json,
    simulation_text,
)
from .common import SIMULATE_OPTIONS, load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer simulate``; the exit code."""
    out = output_path(args, args.out, "--out")
    design = load(args)
    if args.motion is not None or several_inputs(design):
        return _along_motion(args, design, out)
    if args.drive == "motion":
        raise SpecError("drives the inputs along a motion: the spec's [[motion]] with --motion "
                        "NAME", key="--drive", value=args.drive)
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


def _along_motion(args: argparse.Namespace, design: Design, out: Path | None) -> int:
    """``simulate`` along a motion (every input driven) or free from its fastest state."""
    if args.drive == "constant-speed":
        raise SpecError("a linkage driven along a motion has no constant crank speed: choose "
                        "motion or free", key="--drive", value=args.drive)
    if args.drive != "free":  # (a driven run is its motion's: its times and samples)
        for option in ("duration", "outputs"):
            if getattr(args, option) is not None:
                raise SpecError("is a free run's (--drive free); a run driven along a motion "
                                "lasts its [[motion]] times, at its samples",
                                key=f"--{option}", value=getattr(args, option))
    if args.method is not None and args.method not in ("multibody", "input-coordinates"):
        raise SpecError("along a motion the formulations are multibody and input-coordinates",
                        key="--method", value=args.method)
    run = simulate_motion(design, args.motion, method=args.method,
                          drive="free" if args.drive == "free" else "motion",
                          duration=args.duration, rtol=args.rtol, atol=args.atol,
                          outputs=args.outputs)
    csv = motion_run_csv(run) if out is not None else None
    if args.json:
        text = dumps_json(motion_run_json(run, spec=args.spec))
    else:
        text = motion_run_text(run, spec=args.spec) + "\n"
    if out is not None:
        assert csv is not None
        write_atomic(out, csv)
        wrote(out)
    sys.stdout.write(text)
    return 0
