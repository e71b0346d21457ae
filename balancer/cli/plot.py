"""``balancer plot``: one revolution's figure, and the mechanism turning; or along a motion."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from ..api import cycle_analyses
from ..api.analysis import analyze_motion, phasors, several_inputs
from ..api.drawings import motion_drawing
from ..errors import OutputError, SpecError
from ..mechanisms import mechanism_of
from ..mechanisms.base import require_full_revolution, require_one_input
from ..model import Design
from ..outputs import animation_type, figure_type
from ..plots import (
    animate,
    cycle_figure,
    motion_figure,
    orders_figure,
    phasors_figure,
    save_figure,
)
from .common import load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer plot``; the exit code."""
    if (args.animate is None and args.cycle is None and args.orders is None
            and args.phasors is None):
        raise SpecError("nothing to plot: give --cycle PATH, --orders PATH, --phasors PATH or "
                        "--animate PATH", key="--cycle")
    if args.log and args.orders is None:
        raise SpecError("draws the order bars on a logarithmic axis: give --orders PATH too",
                        key="--log")
    cycle = output_path(args, args.cycle, "--cycle")
    orders = output_path(args, args.orders, "--orders")
    animation = output_path(args, args.animate, "--animate")
    phasor = output_path(args, args.phasors, "--phasors")
    named: dict[str, str] = {}
    for option, path in (("--cycle", cycle), ("--orders", orders), ("--phasors", phasor),
                         ("--animate", animation)):
        if path is None:
            continue
        same = named.get(os.path.realpath(path))
        if same is not None:
            raise OutputError(f"names the same file as {same}", key=option, value=str(path))
        named[os.path.realpath(path)] = option
    for option, path in (("--cycle", cycle), ("--orders", orders), ("--phasors", phasor)):
        if path is not None:
            figure_type(path, option)
    if animation is not None:
        animation_type(animation, "--animate")  # its extension, and ffmpeg for an MP4
    design = load(args)
    if args.motion is not None or several_inputs(design):
        if phasor is not None:
            require_one_input(mechanism_of(design.mechanism), "a phasor picture")
            raise SpecError("phasors are of one crank revolution, not of a motion",
                            key="--phasors", value=str(phasor))
        return _along_motion(args, design, cycle, orders, animation)

    require_full_revolution(mechanism_of(design.mechanism),
        "an animation of one revolution" if animation is not None else "a cycle plot")
    figures = []
    if cycle is not None:
        figures.append((cycle_figure(*cycle_analyses(design), title=design.title), cycle))
    if orders is not None:
        # At the spec's samples: the orders `analyze` gives (a spec without an operating
        # speed is refused by cycle_analyses, as for --cycle).
        analyses = cycle_analyses(design, samples=None if design.operation is None
                                  else design.operation.samples)
        figures.append((orders_figure(*analyses, title=design.title, log=args.log), orders))
    if phasor is not None:
        figures.append((phasors_figure(phasors(design), title=design.title), phasor))
    if animation is not None:  # (a balanced spec: what was added to the links drawn too)
        animate(design, animation, frames=args.frames)
        wrote(animation)
    for figure, path in figures:
        save_figure(figure, path)
        wrote(path)
    return 0


def _along_motion(args: argparse.Namespace, design: Design, cycle: Path | None,
                  orders: Path | None, animation: Path | None) -> int:
    """``plot --cycle`` and ``--animate`` along the spec's motion ``--motion`` (its first).

    The loads over time and the mechanism at a few poses along the motion, with the spec's
    gravity (as ``analyze`` along its motions); the mechanism moving along it. The order bars
    are of one crank revolution: refused here (exit code 2).
    """
    if orders is not None:
        require_one_input(mechanism_of(design.mechanism), "an order table")  # (its words)
        raise SpecError("an order table is of one crank revolution, not of a motion: --motion "
                        "draws its loads with --cycle PATH and the mechanism with --animate "
                        "PATH", key="--orders", value=str(orders))
    motion = design.motion(args.motion)  # (without --motion: the first, said below)
    if args.motion is None and len(design.motions) > 1:
        others = ", ".join(m.name for m in design.motions[1:])
        print(f"balancer: note: drawing motion {motion.name}, the spec's first; --motion NAME "
              f"draws another ({others})", file=sys.stderr)
    if cycle is not None:
        analysis = analyze_motion(design, motion.name)
        figure = motion_figure(analysis, motion_drawing(analysis), title=design.title)
        save_figure(figure, cycle)
        wrote(cycle)
    if animation is not None:
        animate(design, animation, frames=args.frames, motion=motion)
        wrote(animation)
    return 0
