"""The ``balancer`` command: a thin layer over the Python API.

Exit codes: 0 success; 2 bad input (spec or arguments); 1 a computation that fails. Every error
is one line on stderr naming the cause and where; never a traceback for a user error. Heavy
libraries (SciPy's integrators, CVXPY, CasADi, matplotlib) are imported only by the commands that
use them.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from .errors import BalancerError, SpecError


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise SpecError(f"{self.prog}: {message} (see '{self.prog} --help')")


def _output_path(value: str, option: str) -> Path:
    """An output file path whose folder exists."""
    path = Path(value)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise SpecError("the folder to write into does not exist", key=option, value=value)
    if path.is_dir():
        raise SpecError("is a folder, not a file", key=option, value=value)
    return path


def _cmd_analyze(args: argparse.Namespace) -> int:
    from .api import analyze
    from .report import analysis_csv, analysis_json, analysis_text, dumps_json
    from .spec import load_design, write_atomic

    csv_path = _output_path(args.csv, "--csv") if args.csv else None
    design = load_design(args.spec)
    analysis = analyze(design, route=args.route)
    if csv_path is not None:
        write_atomic(csv_path, analysis_csv(analysis))
    if args.json:
        sys.stdout.write(dumps_json(analysis_json(analysis, spec=args.spec)))
    else:
        print(analysis_text(analysis, spec=args.spec))
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``balancer`` command."""
    parser = _Parser(
        prog="balancer",
        description=(
            "Dynamic balancing of planar linkages: analyse the shaking force and moment of a "
            "design, redesign its mass distribution for exact force balance and least shaking "
            "moment, and prove the result by simulation."
        ),
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    p = sub.add_parser(
        "analyze",
        help="shaking force, shaking moment and driving torque over one revolution",
        description=(
            "Reactions at the ground pivots, shaking force, shaking moment about A0 and driving "
            "torque over one crank revolution at the operating speed ([operation] speed)."
        ),
    )
    p.add_argument("spec", metavar="SPEC", help="design spec (TOML)")
    p.add_argument("--json", action="store_true", help="print a JSON document instead of a table")
    p.add_argument("--csv", metavar="PATH", help="write the per-angle values to a CSV file")
    p.add_argument(
        "--route",
        choices=("newton-euler", "mass-matrix"),
        default="newton-euler",
        help="inverse-dynamics route (both agree to rounding; default newton-euler)",
    )
    p.set_defaults(handler=_cmd_analyze)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        handler: Callable[[argparse.Namespace], int] = args.handler
        return handler(args)
    except BalancerError as exc:
        print(f"balancer: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print("balancer: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0


def entry_point() -> None:
    """Console-script entry point."""
    sys.exit(main())
