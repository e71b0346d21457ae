"""The ``balancer`` command: a thin layer over the Python API.

Exit codes: 0 success; 2 bad input (spec or arguments); 1 a computation that fails; 130
interrupted (SIGINT, Ctrl-C, at any moment: :mod:`balancer.interrupts`). Every error is one
line on stderr naming the cause and where; never a traceback for a user error. Each verb is
a module of its own (:mod:`.analyze`, :mod:`.simulate`, …, with what they share in
:mod:`.common`), loaded when it is asked for: ``balancer --help`` loads no numerics, and heavy
libraries (SciPy's integrators, CVXPY, CasADi, matplotlib) come with the commands that use them.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

from .. import interrupts
from ..errors import BalancerError, OutputError, SpecError

#: ``--drive`` values: :data:`balancer.model.DRIVES`, here so that ``--help`` needs no model
#: (a test keeps the two equal).
DRIVES: tuple[str, ...] = ("free", "constant-speed")


#: ``--method`` values: every formulation of any mechanism (:mod:`balancer.formulations`), here
#: so that ``--help`` needs no numerics (a test keeps them equal to the registry's).
FORMULATION_NAMES: tuple[str, ...] = (
    "opened-loop", "complex-masses", "mass-matrix", "lie-group", "multibody", "crank-angle",
    "input-coordinates")


#: Most frames per revolution of an animation: ten a degree, more than any screen shows.
MAX_FRAMES = 3600


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit code 2.

    An option's value that begins with ``-`` (``--gravity -1,-9.81``) reads as another
    option, and argparse says only that the option expected an argument: the error then
    shows the ``=`` form that takes it (``--gravity=-1,-9.81``).
    """

    # (one body for typeshed's overloads, which tell the namespace's type from the argument)
    def parse_known_args(  # type: ignore[override]
            self, args: Sequence[str] | None = None, namespace: Any = None
    ) -> tuple[Any, list[str]]:
        self._given = list(sys.argv[1:] if args is None else args)
        return super().parse_known_args(args, namespace)

    def error(self, message: str) -> NoReturn:
        raise SpecError(f"{message}{self._dash_hint(message)} (see '{self.prog} --help')")

    def _dash_hint(self, message: str) -> str:
        """For an option whose value begins with '-': its ``=`` form, else nothing."""
        prefix, sep, rest = message.partition(": expected one argument")
        if not sep or rest or not prefix.startswith("argument "):
            return ""
        names = prefix.removeprefix("argument ").split("/")
        given = getattr(self, "_given", [])
        for i, token in enumerate(given[:-1]):
            value = given[i + 1]
            if (token in names and value.startswith("-")
                    and value.split("=")[0] not in self._option_string_actions):
                return (f"; a value that begins with '-' is given after '=': "
                        f"{token}={value}")
        return ""


#: The CSV files' units (their header keeps the plain names a csv reader expects).
_CSV_UNITS = ("columns in SI units: t s; theta rad, omega rad/s, alpha rad/s² per link; "
              "R<point>x, R<point>y, N_<link> N; C_<link> N·m; x<k> m, v<k> m/s, a<k> m/s² "
              "along a slider's guide; shaking_force_x, shaking_force_y N; shaking_moment, "
              "driving_torque N·m")


#: ``--force``: the one switch for every output path of a command.
_FORCE_HELP = ("overwrite output files that exist (without it, an output path that names an "
               "existing file, the input spec included, is refused with exit code 2)")


def _spec_and_force(p: argparse.ArgumentParser, balance: bool = False) -> None:
    """The arguments every verb on a spec takes: the spec, and ``--force``."""
    p.add_argument("spec", metavar="SPEC", help="design spec (TOML)"
                   + (" with a [balance] section" if balance else ""))
    p.add_argument("--force", action="store_true", help=_FORCE_HELP)


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not value > 0 or value != value or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number: {text!r}")
    return value


def _gravity(text: str) -> tuple[float, float]:
    """``GX,GY``: two finite numbers, m/s²."""
    parts = text.split(",")
    try:
        gx, gy = (float(p) for p in parts)
    except ValueError:
        gx = gy = float("nan")
    if not all(abs(x) < float("inf") for x in (gx, gy)):
        raise argparse.ArgumentTypeError(f"must be two finite numbers GX,GY in m/s²: {text!r}")
    return gx, gy


def _frames(text: str) -> int:
    """Frames per revolution: from 2 to :data:`MAX_FRAMES`."""
    value = _count(text)
    if value > MAX_FRAMES:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_FRAMES} frames per "
                                          f"revolution (ten a degree): {text!r}")
    return value


def _whole(text: str, least: int) -> int:
    """A whole number of the command line, at least ``least``."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if value < least:
        raise argparse.ArgumentTypeError(f"must be at least {least}: {text!r}")
    return value


def _intervals(text: str) -> int:
    """A transcription's intervals: at least 4 (``PlanSpec``'s least)."""
    return _whole(text, 4)


def _count(text: str) -> int:
    """A count of samples, outputs or points: at least 2."""
    return _whole(text, 2)


def _version() -> str:
    """The installed package's version."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("balancer")
    except PackageNotFoundError:  # pragma: no cover - run from a source tree
        return "unknown (not installed)"


class _VersionAction(argparse.Action):
    """``--version``: the installed version, looked up only when asked for."""

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS,
                 default: Any = argparse.SUPPRESS,
                 help: str = "show the version and exit") -> None:  # noqa: A002 - argparse's
        super().__init__(option_strings, dest, nargs=0, default=default, help=help)

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: str | Sequence[Any] | None, option_string: str | None = None) -> None:
        parser._print_message(f"balancer {_version()}\n", sys.stdout)
        parser.exit()


#: Each verb's one-line help and description, in the order ``balancer --help`` lists them.
_VERB_TEXTS: dict[str, tuple[str, str]] = {
    "analyze": (
        "shaking force, shaking moment and driving torque over one revolution",
        "Reactions at the ground pivots, shaking force, shaking moment about A0 and "
        "driving torque over one crank revolution at the operating speed ([operation] "
        "speed); for a linkage with several inputs, or with --motion, the same loads and "
        "each input's torque along the spec's motions ([[motion]]).",
    ),
    "simulate": (
        "forward dynamics in a formulation of your choice",
        "Forward dynamics of the linkage from the spec's [simulation] settings: free "
        "motion under the loads (and gravity), or the crank held at constant speed by a "
        "motor. Prints the initial and final angles, rates and accelerations, the "
        "shaking figures, the energy balance and the constraint drift. A linkage with "
        "several inputs (or with --motion) is driven along the spec's motion ([[motion]]), "
        "every input prescribed, or with --drive free coasts from the state where the "
        "motion's inputs turn fastest.",
    ),
    "verify": (
        "prove a design balanced by simulation, with plots",
        "Simulate the design with a formulation other than the optimiser's, driven at the "
        "operating speed and in free motion from the spec's initial state; report the "
        "largest shaking force and moment, relative to the unbalanced original where the "
        "spec names one ([original]); optionally plot reactions, shaking moment and the "
        "path of the total centre of mass (PNG, SVG or PDF). A linkage with several inputs "
        "is driven along each of its motions ([[motion]]) in two formulations that must "
        "agree, and runs free once.",
    ),
    "optimize": (
        "redesign the links for exact force balance and least shaking moment",
        "Solve the redesign problem of the spec's [balance] section: exact shaking-force "
        "balance as constraints, the shaking moment (and optional weighted terms) "
        "minimised over one revolution at the operating speed. The convex backend solves "
        "the second-order cone program in the inertial parameters (a global optimum: the "
        "lower bound); the nlp backend then solves the designer's physical parametrisation "
        "with IPOPT from it and reports the gap. The result is checked by an independent "
        "simulation and can be written as a complete spec.",
    ),
    "plot": (
        "pictures for a report: one revolution's shaking, its orders, an animation; the "
        "loads along a motion",
        "Pictures of one crank revolution at the operating speed. --cycle: the "
        "shaking force's polar diagram (and the rocking couple's, for links in several "
        "planes), and the shaking moment and driving torque over the crank angle, of the "
        "design and (for a balanced spec that names its [original]) of the original before "
        "it. --orders: the order table as bars, forward and backward whirl, before and after. "
        "--phasors: each plane's force and couple at orders 1 and 2 as arrows, head to tail. "
        "--animate: the linkage turning, its total centre of mass traced. For a linkage with "
        "several inputs, or with --motion, --cycle draws the loads along the spec's motion "
        "([[motion]]) over time instead, with the mechanism at a few poses along it, and "
        "--animate the mechanism moving along it. The file "
        "type comes from the extension.",
    ),
    "pareto": (
        "the exact front of shaking moment against driving torque, added mass or force",
        "The least RMS shaking moment against a second objective, under the "
        "balancing constraints of the spec's [balance] section (force balance and every "
        "link's bounds): an even grid of bounds on the second objective between its two "
        "ends, each point the global optimum of a convex program with its certified lower "
        "bound; the knee marked. An engine's front (its [balance.counterweights] and "
        "[[balance.shafts]]) is of its weighted shaking against the mass it adds "
        "(--against added-mass).",
    ),
    "sweep": (
        "the certified balanced optimum over a design space, on a Dask cluster",
        "Vary spec keys over ranges (a grid, or --samples points of a Latin "
        "hypercube or a Sobol' sequence); at each point analyse the design and solve its "
        "redesign problem to the certified global optimum (the convex backend), one row per "
        "point in a Parquet table. The batches run on dask.distributed: a local cluster on "
        "this machine's cores, or the scheduler at --scheduler. Each finished batch is kept "
        "beside the table, so that an interrupted sweep resumes with --resume.",
    ),
    "plan": (
        "the time law of a motion's path that shakes the frame least",
        "Keep the path of a motion of the spec ([plan] motion, or --motion; a one-input "
        "linkage's revolution) and choose how fast it is run — its time law, within the "
        "inputs' speed, acceleration and torque limits of [plan], in the same duration — to "
        "minimise the mean square (or the peak) of the weighted shaking force, shaking "
        "moment, rocking couple and input torques ([plan.objective]). Direct transcription "
        "solved by IPOPT: convex where the duration binds, and then the optimum is global for "
        "its mesh (the report says which). Reports the loads before and after; writes the "
        "spec with the planned motion (--out), its loads over time (--csv) and a figure "
        "(--plot).",
    ),
    "search": (
        "an engine's crank arrangements and firing orders, ranked by what they leave free",
        "For an engine's cylinders as the spec places them (planes, banks, V pairs on shared "
        "pins), every crank whose cylinders fire evenly over the working cycle and every "
        "firing order it allows, cylinder 1 first, each judged exactly from its cylinders' "
        "inertial loads at the operating speed: ranked by what crank counterweights cannot "
        "take (the primary force's and couple's backward whirls, the secondary force and "
        "couple), then by the driving torque's energy swing over the working cycle (what a "
        "flywheel must hold: it ranks uneven firings, --step), then by the firings that "
        "follow in the same half of the crank. The flat-plane four, the in-line six's "
        "1-5-3-6-2-4 and the cross-plane V8 come out on top.",
    ),
    "example": (
        "write a shipped example spec (without NAME: list them)",
        "The example specs shipped with the package: the paper's four-bar "
        "(meijaard2020), its balancing problems PB1 and PB2, an engine, six-bars and more. "
        "Without NAME, list them; with NAME, print its spec, or write it to --out PATH.",
    ),
}
#: The verbs, in the order ``balancer --help`` lists them.
VERBS: tuple[str, ...] = tuple(_VERB_TEXTS)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of the ``balancer`` command.

    ``only``: the one verb to build (its parser and arguments); ``None`` every verb with its
    arguments; any other value (``""``, an unknown verb) every verb listed with its help alone,
    so that ``balancer --help`` and an unknown verb's error name them all. A command builds its
    own verb alone (:func:`_verb_of`): argparse's parsers, 72 arguments and their help cost a
    tenth of a short command's time.
    """
    parser = _Parser(
        prog="balancer",
        description=(
            "Dynamic balancing of planar linkages: analyse the shaking force and moment of a "
            "design, redesign its mass distribution for exact force balance and least shaking "
            "moment, and prove the result by simulation."
        ),
    )
    parser.add_argument("--version", action=_VersionAction)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    # (a known verb: its parser alone; else every verb, listed for the help or the error)
    for name in (only,) if only in VERBS else VERBS:
        help_text, description = _VERB_TEXTS[name]
        p = sub.add_parser(name, help=help_text, description=description)
        if only is None or only == name:
            _ARGUMENTS[name](p)
            p.set_defaults(verb=name)
    return parser


def _analyze_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer analyze``'s arguments."""
    _spec_and_force(p)
    p.add_argument("--json", action="store_true", help="print a JSON document instead of a table")
    p.add_argument("--csv", metavar="PATH", help="write the per-angle values to a CSV file; "
                   + _CSV_UNITS)
    p.add_argument(
        "--route",
        choices=("newton-euler", "mass-matrix"),
        default="newton-euler",
        help="inverse-dynamics route (both agree to rounding; default newton-euler)",
    )
    p.add_argument(
        "--motion", metavar="NAME",
        help="the loads along the spec's motion NAME ([[motion]]) instead of one revolution; "
        "a linkage with several inputs is analysed along every motion without it",
    )
    p.add_argument(
        "--gravity", type=_gravity, metavar="GX,GY",
        help="gravitational acceleration, m/s², instead of the spec's [operation] gravity "
        "(default none): the frame then carries the weights too. Write a negative first "
        "value as --gravity=-1,-9.81",
    )


def _simulate_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer simulate``'s arguments."""
    _spec_and_force(p)
    p.add_argument("--method", choices=FORMULATION_NAMES,
                   help="formulation (default: the spec's, or the mechanism's first: "
                   "opened-loop for a four-bar, mass-matrix for a slider-crank, crank-angle for "
                   "a general linkage whose crank turns fully, multibody for one whose crank does "
                   "not)")
    p.add_argument("--drive", choices=(*DRIVES, "motion"),
                   help="free motion or constant crank speed "
                   "(default: the spec's); the constant speed is [simulation] omega1 where "
                   "the spec gives it non-zero, else the operating speed [operation] speed; "
                   "along a motion: motion (default, every input prescribed) or free")
    p.add_argument("--motion", metavar="NAME",
                   help="drive the inputs along the spec's motion NAME ([[motion]]); a "
                   "linkage with several inputs runs along its first motion without it")
    p.add_argument("--duration", type=_positive_float, metavar="T", help="simulated time, s")
    p.add_argument("--rtol", type=_positive_float, metavar="R", help="relative tolerance")
    p.add_argument("--atol", type=_positive_float, metavar="A", help="absolute tolerance")
    p.add_argument("--outputs", type=_count, metavar="N", help="number of output times")
    p.add_argument("--out", metavar="CSV", help="write the time histories to a CSV file; "
                   + _CSV_UNITS + "; kinetic_energy, work J")
    p.add_argument("--all-columns", action="store_true",
                   help="add shaking force and moment, driving torque, energy to the CSV")
    p.add_argument("--json", action="store_true", help="print a JSON document instead")


def _verify_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer verify``'s arguments."""
    _spec_and_force(p)
    p.add_argument("--plot", metavar="PATH",
                   help="write the report figure to PATH (.png, .svg or .pdf)")
    p.add_argument("--duration", type=_positive_float, metavar="T",
                   help="simulated time of each run, s (default: the spec's)")
    p.add_argument("--method", choices=FORMULATION_NAMES,
                   help="formulation for the simulations (default: one the optimiser did not "
                   "use: complex-masses for a four-bar whose crank turns fully, opened-loop for "
                   "one that swings or passes change points, complex-masses for a "
                   "slider-crank, multibody for a general linkage and one with several "
                   "inputs, checked against input-coordinates)")
    p.add_argument("--json", action="store_true", help="print a JSON document instead")


def _optimize_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer optimize``'s arguments."""
    _spec_and_force(p, balance=True)
    p.add_argument("--out", metavar="BALANCED.toml", help="write the balanced design as a spec")
    p.add_argument("--backend", choices=("nlp", "convex"), default="nlp",
                   help="optimiser (default nlp: convex first, then IPOPT)")
    p.add_argument("--json", action="store_true", help="print a JSON document instead")
    p.add_argument("--no-verify", action="store_true",
                   help="skip the check by simulation")
    p.add_argument("--verify-duration", type=_positive_float, metavar="T",
                   help="simulated time of each check, s (default: the spec's)")
    p.add_argument("--cad", metavar="DIR",
                   help="write each counterweight as a part into the folder DIR: a STEP solid "
                   "and a DXF profile in the link's frame (mm) and a dimensioned drawing (SVG, "
                   "PNG), named after the link; an engine's crank-web sectors (its "
                   "[balance.counterweights] part) named by their plane, crankshaft_z<z>mm "
                   "(needs the cad extra: pip install 'balancer[cad]')")


def _plot_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer plot``'s arguments."""
    _spec_and_force(p)
    p.add_argument("--cycle", metavar="PATH",
                   help="write the figure of one revolution (or, along a motion, of the "
                   "motion) to PATH (.png, .svg or .pdf)")
    p.add_argument("--motion", metavar="NAME",
                   help="with --cycle: the loads along the spec's motion NAME ([[motion]]) "
                   "over time and the mechanism at a few poses along it, instead of one "
                   "revolution; a linkage with several inputs is drawn along its first motion "
                   "without it")
    p.add_argument("--orders", metavar="PATH",
                   help="write the order table's bars to PATH (.png, .svg or .pdf)")
    p.add_argument("--phasors", metavar="PATH",
                   help="write the phasors of orders 1 and 2 to PATH (.png, .svg or .pdf): "
                   "each plane's force (and couple) as arrows at θ1 = 0, forward and backward "
                   "whirls head to tail, and their sums")
    p.add_argument("--animate", metavar="PATH",
                   help="write an animation to PATH (.gif, or .mp4 with ffmpeg)")
    p.add_argument("--frames", type=_frames, default=72, metavar="N",
                   help=f"frames, at most {MAX_FRAMES} (default 72): per revolution, or "
                   "along a motion")
    p.add_argument("--log", action="store_true",
                   help="with --orders: the bars on a logarithmic axis (magnitudes; bars at "
                   "rounding of the largest left out)")


def _pareto_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer pareto``'s arguments."""
    _spec_and_force(p, balance=True)
    p.add_argument("--against", required=True,
                   choices=("driving-torque", "added-mass", "shaking-force"),
                   help="the second objective")
    p.add_argument("--points", type=_count, default=11, metavar="N",
                   help="number of points, both ends included (default 11)")
    p.add_argument("--plot", metavar="PATH", help="draw the front to PATH (.png, .svg or .pdf)")
    p.add_argument("--csv", metavar="PATH", help="write the points to a CSV file")
    p.add_argument("--json", action="store_true", help="print a JSON document instead")


def _sweep_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer sweep``'s arguments."""
    _spec_and_force(p, balance=True)
    p.add_argument("--vary", action="append", metavar="KEY=LOW:HIGH:N",
                   help="a dotted spec key and its range, e.g. mechanism.lengths.coupler="
                   "2.5:3.5:11 (N values on a grid; repeat for more keys)")
    p.add_argument("--perturb", action="append", metavar="KEY=SIGMA",
                   help="instead of --vary: --samples draws of a key around its spec value, "
                   "normal with deviation SIGMA (its unit), e.g. links.crank.mass=0.01; each "
                   "row the perturbed design's own figures (robust balancing)")
    p.add_argument("--out", required=True, metavar="FILE.parquet",
                   help="the table to write (Parquet)")
    p.add_argument("--method", choices=("grid", "lhs", "sobol"), default="grid",
                   help="how the points are placed (default grid)")
    p.add_argument("--samples", type=_count, metavar="N",
                   help="number of points for lhs and sobol")
    p.add_argument("--seed", type=int, default=0, help="seed of lhs and sobol (default 0)")
    p.add_argument("--workers", type=int, metavar="N",
                   help="worker processes of the local cluster (default: the machine's "
                   "cores; 0: in this process, without Dask)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="a running Dask scheduler, e.g. tcp://10.0.0.5:8786")
    p.add_argument("--resume", action="store_true",
                   help="continue the interrupted sweep whose parts lie beside --out")
    p.add_argument("--batch", type=int, default=None, metavar="N",
                   help="points per task (default: 25, fewer where a worker would get fewer "
                        "than 8 tasks; resumed: the interrupted sweep's)")
    p.add_argument("--plot", metavar="PATH",
                   help="draw the atlas (.png, .svg or .pdf): a heat map over two keys")
    p.add_argument("--json", action="store_true", help="print a JSON summary instead")


def _plan_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer plan``'s arguments."""
    _spec_and_force(p)
    p.add_argument("--motion", metavar="NAME",
                   help="the motion whose path is run (default: [plan] motion, else the "
                   "spec's first; 'revolution' for a one-input linkage's revolution)")
    p.add_argument("--measure", choices=("rms", "peak"),
                   help="minimise the objective's mean square over time or its largest value "
                   "(default: [plan] measure, rms)")
    p.add_argument("--duration", type=_positive_float, metavar="T",
                   help="the planned motion's duration, s (default: the motion's)")
    p.add_argument("--intervals", type=_intervals, metavar="N",
                   help="intervals of the path in the transcription (default: [plan] "
                   "intervals, 200)")
    p.add_argument("--with-masses", action="store_true",
                   help="choose the links' masses of [balance] with the time law: each "
                   "lever's certified problem in turn until neither improves; report what "
                   "the masses, the time law and both buy")
    p.add_argument("--out", metavar="PLANNED.toml",
                   help="write the spec with the planned motion ([[motion]] along the path, "
                   "at its pace), and with --with-masses the chosen masses")
    p.add_argument("--csv", metavar="PATH",
                   help="write the loads along the planned motion to a CSV file (analyze "
                   "--motion's columns)")
    p.add_argument("--plot", metavar="PATH",
                   help="write the figure of the loads before and after and the pace (.png, "
                   ".svg or .pdf)")
    p.add_argument("--json", action="store_true", help="print a JSON document instead")


def _search_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer search``'s arguments."""
    p.add_argument("spec", metavar="SPEC", help="an engine's design spec (TOML)")
    p.add_argument("--top", type=lambda text: _whole(text, 1), default=10, metavar="N",
                   help="the best N cranks and firing orders (default 10)")
    p.add_argument("--balance", action="store_true",
                   help="balance each of them as the spec's [balance] asks (its certified "
                   "counterweights and shafts) and give the objective left")
    p.add_argument("--step", type=float, metavar="DEG",
                   help="uneven firing too: every crank whose pins' phases are multiples of "
                   "DEG from cylinder 1's (DEG divides 360) and every firing order that fits "
                   "in the working cycle")
    p.add_argument("--json", action="store_true", help="print a JSON document instead")


def _example_arguments(p: argparse.ArgumentParser) -> None:
    """``balancer example``'s arguments."""
    p.add_argument("name", metavar="NAME", nargs="?", help="the example (e.g. pb1)")
    p.add_argument("--out", metavar="PATH", help="write the spec to PATH instead of printing it")
    p.add_argument("--force", action="store_true", help=_FORCE_HELP)


#: Each verb's arguments (the verb's own module runs it: :mod:`.analyze`, …).
_ARGUMENTS: dict[str, Callable[[argparse.ArgumentParser], None]] = {
    "analyze": _analyze_arguments,
    "simulate": _simulate_arguments,
    "verify": _verify_arguments,
    "optimize": _optimize_arguments,
    "plot": _plot_arguments,
    "pareto": _pareto_arguments,
    "sweep": _sweep_arguments,
    "plan": _plan_arguments,
    "search": _search_arguments,
    "example": _example_arguments,
}


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code.

    A SIGINT at any moment of the command — also one a library swallowed, or one that came
    while an error was being reported — ends it with exit code 130 and the one line
    ``balancer: interrupted`` (:mod:`balancer.interrupts`).
    """
    return _main(argv, whole_process=False)


def _main(argv: Sequence[str] | None, *, whole_process: bool) -> int:
    """:func:`main`, or the process's command (``whole_process``, :func:`entry_point`).

    A process that ends with the command sets aside for good what loading made (:func:`_loaded`).
    """
    with interrupts.handling():
        try:
            try:
                code, line = _run(argv, whole_process=whole_process)
            except KeyboardInterrupt as exc:
                code, line = 130, _interrupted(exc)
            with interrupts.shielded():  # from here on a SIGINT only counts
                if code != 130 and interrupts.received():
                    code, line = 130, _interrupted(None)
                if line:
                    print(line, file=sys.stderr)
        except KeyboardInterrupt:  # a second one, before the shield was up
            with interrupts.shielded():
                code = 130
                print(_interrupted(None), file=sys.stderr)
    return code


def _interrupted(exc: KeyboardInterrupt | None) -> str:
    """The line that says the command was interrupted (and what it kept, if it says)."""
    what = str(exc) if exc is not None else ""
    return f"balancer: interrupted: {what}" if what else "balancer: interrupted"


def _loaded(load: Callable[[], Any], whole_process: bool) -> Any:
    """What ``load()`` returns; in a whole process, loaded with the collector held off.

    Loading numpy and a verb's layers makes some 10⁵ objects (functions, classes, their
    dictionaries) that live as long as the process does, none of them garbage. The cyclic
    garbage collector, left on, goes over the young ones every 700 allocations and over all of
    them now and then: a seventh of a short command's time (``analyze`` of the paper's
    four-bar, benchmarks/bench_commands.py). In a process that ends with the command it is
    held off while they load, and what they made is frozen (:func:`gc.freeze`, as Python's
    documentation advises for a process that loads, then works): the command's own
    collections go over its own objects only. Called from a longer process (a notebook, the
    tests), :func:`main` leaves the collector as it is.
    """
    if not whole_process:
        return load()
    gc.disable()
    try:
        return load()
    finally:
        gc.freeze()
        gc.enable()


def _verb_of(argv: Sequence[str]) -> str:
    """The verb a command line asks for: its first word that is no option (``""``: none)."""
    return next((a for a in argv if not a.startswith("-")), "")


def _run(argv: Sequence[str] | None, *, whole_process: bool) -> tuple[int, str | None]:
    """Parse and run the command: its exit code and the error line to print, if any."""
    parser = build_parser(_verb_of(sys.argv[1:] if argv is None else argv))
    args = None
    try:
        args = parser.parse_args(argv)
        # Each verb's module imports what it needs: only the one asked for is loaded.
        # A user sees results or one line of error: the libraries' warnings (an overflow in an
        # intermediate, a solver's note) are not theirs to read. Results are checked finite
        # before they are written (report.dumps_json, report.csv_text).
        verb = _loaded(lambda: importlib.import_module(f".{args.verb}", __name__),
                       whole_process)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return verb.run(args), None
    except BalancerError as exc:
        spec = getattr(args, "spec", None)
        if (isinstance(exc, SpecError) and not isinstance(exc, OutputError)
                and exc.source is None and spec and exc.key and not exc.key.startswith("-")):
            exc = exc.with_source(spec)  # a spec key found wrong after loading: name the file
        message = str(exc)
        if not isinstance(exc, SpecError) and spec and spec not in message:
            message = f"{spec}: {message}"  # a failed computation: name the file it concerns
        return exc.exit_code, f"balancer: error: {_one_line(message)}"
    except BrokenPipeError:
        return 0, None
    except MemoryError:
        return 1, "balancer: error: out of memory (ask for fewer samples or outputs)"
    except Exception as exc:  # a defect of ours: one line, never a traceback for the user
        where = _innermost(exc)
        return 1, (f"balancer: internal error: {type(exc).__name__}: {_one_line(str(exc))} "
                   f"({where}); please report it with the spec")


def _one_line(text: str) -> str:
    return " ".join(text.split())


def _innermost(exc: BaseException) -> str:
    """``file:line`` of the innermost frame of ``exc`` inside this package."""
    import traceback

    frames = [f for f in traceback.extract_tb(exc.__traceback__) if "balancer" in f.filename]
    if not frames:
        return "outside balancer"
    f = frames[-1]
    return f"{Path(f.filename).name}:{f.lineno}"


def entry_point() -> None:
    """Console-script entry point (``balancer`` and ``python -m balancer``).

    OpenBLAS runs on one thread unless the user chose otherwise: the commands' linear algebra
    is small (tens to hundreds of rows), where its threads only cost — they spin while numpy
    loads and wait on every small solve, some 60 ms of a 0.3 s ``analyze`` on a busy 2-core
    machine, and a small QR took 150 ms threaded against 1 ms on one thread. Set before numpy
    is imported; a sweep's worker processes inherit it (one worker per core). The results are
    the same either way.

    A SIGINT from the moment this runs until the process ends gives exit code 130.
    """
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    # main() handles SIGINT itself; one that comes just before or after it is counted (and
    # decides the exit code), never raised as a traceback.
    with interrupts.handling(), interrupts.shielded():
        code = _main(None, whole_process=True)
        if interrupts.closing() and code != 130:
            print(_interrupted(None), file=sys.stderr)
            code = 130
    # The process ends: Python's last collection at exit would go over every object it made,
    # none of them garbage worth the time (a tenth of a short command's time).
    gc.freeze()
    sys.exit(code)
