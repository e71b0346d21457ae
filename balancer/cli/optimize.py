"""``balancer optimize``: the balanced design, checked by simulation and written as a spec."""

from __future__ import annotations

import argparse
import sys

from ..api import optimize, verify
from ..errors import SolverError, SpecError
from ..outputs import write_atomic
from ..progress import Progress
from ..report import dumps_json, optimization_json, optimization_text
from ..spec import dumps_design, loads_design
from ..verification import check_verification
from .common import as_option, load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer optimize``; the exit code."""
    out = output_path(args, args.out, "--out")
    design = load(args)
    if not args.no_verify:  # the check at the end refuses nothing after the work

        try:
            check_verification(design, duration=args.verify_duration)
        except SpecError as exc:
            raise as_option(exc, "simulation.duration", "--verify-duration",
                             args.verify_duration) from None
    result = optimize(design, backend=args.backend)
    if not result.success:
        raise SolverError(f"the balancing failed: {result.message}")
    balanced = result.balanced_design(design)
    spec_text = dumps_design(balanced)
    loads_design(spec_text, source=str(out or "the balanced spec"))  # it must load again
    before, after = result.operating  # the analyze figures of both (loads and gravity)
    verification = None
    if not args.no_verify:
        try:
            with Progress("verifying by simulation", enabled=not args.json) as progress:
                verification = verify(balanced, duration=args.verify_duration,
                                      progress=progress)
        except SpecError as exc:
            raise as_option(exc, "simulation.duration", "--verify-duration",
                             args.verify_duration) from None
    if args.json:
        text = dumps_json(optimization_json(result, before, after, verification,
                                            spec=args.spec, out=out))
    else:
        text = optimization_text(result, before, after, verification,
                                 spec=args.spec) + "\n"
    if out is not None:
        write_atomic(out, spec_text)
        wrote(out)
    sys.stdout.write(text)
    return 0
