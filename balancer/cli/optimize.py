"""``balancer optimize``: the balanced design, checked by simulation and written as a spec."""

from __future__ import annotations

import argparse
import sys

from ..api import optimize, verify
from ..api.analysis import several_inputs
from ..cycle import CycleAnalysis
from ..errors import SolverError, SpecError
from ..outputs import write_atomic
from ..parts.cad import cad_folder, require_cad, write_cad
from ..parts.made import parts_of
from ..parts.planes import require_webs
from ..progress import Progress
from ..report import dumps_json, optimization_json, optimization_text, parts_json, parts_text
from ..spec import dumps_design, loads_design
from ..verification import check_verification
from .common import as_option, load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer optimize``; the exit code."""
    out = output_path(args, args.out, "--out")
    cad = None
    if args.cad is not None:
        require_cad()
        cad = cad_folder(args.cad, force=args.force)
    design = load(args)
    if cad is not None:
        require_webs(design)  # (an engine's sectors need their room: said before the work)
    verifying = not args.no_verify
    if verifying and not several_inputs(design):  # the check refuses nothing after the work

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
    if verifying:
        try:
            with Progress("verifying by simulation", enabled=not args.json) as progress:
                verification = verify(balanced, duration=args.verify_duration,
                                      progress=progress)
        except SpecError as exc:
            raise as_option(exc, "simulation.duration", "--verify-duration",
                             args.verify_duration) from None
    parts, built = parts_of(design, result, always=cad is not None)
    if args.json:
        doc = optimization_json(result, before, after, verification, spec=args.spec, out=out)
        if parts:
            doc.update({"parts": parts_json(parts),
                        "as_built": None if built is None else built.summary.as_dict()})
        text = dumps_json(doc)
    else:
        text = optimization_text(result, before, after, verification,
                                 spec=args.spec) + "\n"
        if parts:
            assert isinstance(before, CycleAnalysis) and isinstance(after, CycleAnalysis)
            text += "\n" + parts_text(parts, before, after, built) + "\n"
    if out is not None:
        write_atomic(out, spec_text)
        wrote(out)
    if cad is not None:
        from ..plots.parts import write_part_drawing  # (matplotlib: only for the files)

        if not any(p.sized.profile is not None for p in parts.values()):
            print("balancer: note: no counterweight to make: --cad wrote no files",
                  file=sys.stderr)
        else:
            for path in write_cad(cad, parts, write_part_drawing):
                wrote(path)
    sys.stdout.write(text)
    return 0
