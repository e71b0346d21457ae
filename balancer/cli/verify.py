"""``balancer verify``: the proof by simulation that a design is balanced, with its figure."""

from __future__ import annotations

import argparse
import sys

from ..api import verify
from ..errors import SpecError
from ..motion_verification import MotionVerification
from ..plots import motion_verification_figure, save_figure, verification_figure
from ..progress import Progress
from ..report import dumps_json, motion_verification_text, verification_text
from .common import as_option, figure_path, load, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer verify``; the exit code."""
    plot = figure_path(args, args.plot, "--plot")
    design = load(args)

    try:
        with Progress("verifying by simulation", enabled=not args.json) as progress:
            verification = verify(design, method=args.method, duration=args.duration,
                                  progress=progress)
    except SpecError as exc:
        raise as_option(exc, "simulation.duration", "--duration", args.duration) from None
    paths = [] if plot is None else [plot]
    if args.json:
        doc = {"spec": args.spec, **verification.as_dict(), "plots": [str(p) for p in paths]}
        text = dumps_json(doc)
    elif isinstance(verification, MotionVerification):
        text = motion_verification_text(verification, spec=args.spec) + "\n"
    else:
        text = verification_text(verification, spec=args.spec) + "\n"
    if plot is not None:
        save_figure(motion_verification_figure(design, verification)
                    if isinstance(verification, MotionVerification)
                    else verification_figure(design, verification), plot)
        wrote(plot)
    sys.stdout.write(text)
    return 0
