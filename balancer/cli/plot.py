"""``balancer plot``: one revolution's figure, and the mechanism turning."""

from __future__ import annotations

import argparse
import os

from ..api import cycle_analyses
from ..balance.counterweights import counterweights
from ..errors import OutputError, SpecError
from ..mechanisms import mechanism_of
from ..outputs import animation_type, figure_type
from ..plots import animate, cycle_figure, save_figure
from .common import load, output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer plot``; the exit code."""
    if args.animate is None and args.cycle is None:
        raise SpecError("nothing to plot: give --cycle PATH or --animate PATH", key="--cycle")
    cycle = output_path(args, args.cycle, "--cycle")
    animation = output_path(args, args.animate, "--animate")
    if cycle is not None and animation is not None and \
            os.path.realpath(cycle) == os.path.realpath(animation):
        raise OutputError("names the same file as --cycle", key="--animate",
                          value=args.animate)

    if cycle is not None:
        figure_type(cycle, "--cycle")
    if animation is not None:
        animation_type(animation, "--animate")  # its extension, and ffmpeg for an MP4
    design = load(args)

    mechanism_of(design.mechanism).require_full_revolution(
        "a cycle plot" if animation is None else "an animation of one revolution")
    figure = None
    if cycle is not None:
        figure = cycle_figure(*cycle_analyses(design), title=design.title)
    if animation is not None:
        weights = None
        if design.original is not None:  # a balanced spec: draw what was added to the links

            weights = counterweights(design.original, design.mechanism)
        animate(design.mechanism, animation, frames=args.frames, title=design.title,
                counterweights=weights)
        wrote(animation)
    if figure is not None:
        save_figure(figure, cycle)
        wrote(cycle)
    return 0
