"""``verify --plot`` for a linkage with several inputs: its runs along the motions, and free.

One column per run (each motion the inputs are driven along, then the free run); rows: the
shaking force's magnitude, the shaking moment about the origin, each input's torque, over time,
the design's beside the unbalanced original's where the spec names one. Computing nothing: the
caller gives the verification (:class:`~balancer.motion_verification.MotionVerification`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..model import Design
from .style import COLOURS, SERIES, legend_outside

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.figure import Figure

    from ..motion_verification import MotionVerification


def motion_verification_figure(design: Design, verification: MotionVerification) -> Figure:
    """The report figure of ``balancer verify`` along the motions (module docstring)."""
    from matplotlib.figure import Figure

    checks = verification.checks
    fig = Figure(figsize=(5.5 * len(checks) + 2.5, 10), layout="constrained")
    grid = fig.subplots(3, len(checks), squeeze=False)
    title = design.title or "design"
    fig.suptitle(f"{title}: verification by simulation ({verification.method} formulation)")
    inputs = verification.free.run.inputs
    slides = any(d.load_unit == "N" for d in verification.free.run.mechanism.structure.drivers)
    loads, unit = ("torques and forces", "N·m; N along a slide") if slides else ("torques", "N·m")
    for col, check in enumerate(checks):
        label = "free (no motor)" if check.name == "free" else f"along {check.name}"
        runs = [("design", check.run, "-", COLOURS["after"])]
        if check.original is not None:
            runs.append(("original", check.original, "--", COLOURS["before"]))
        force, moment, torque = grid[:, col]
        for name, run, style, colour in runs:
            t = run.t
            force.plot(t, np.abs(run.reactions.shaking_force), style, color=colour,
                       label=f"{name}")
            moment.plot(t, run.reactions.shaking_moment, style, color=colour, label=name)
            for i, (inp, tau) in enumerate(zip(inputs, run.reactions.torques, strict=True)):
                torque.plot(t, tau, style, color=SERIES[i % len(SERIES)],
                            label=f"{inp} ({name})")
        force.set_title(f"|shaking force|, {label}")
        force.set_ylabel("N")
        moment.set_title(f"shaking moment about the origin, {label}")
        moment.set_ylabel("N·m")
        torque.set_title(f"input {loads}, {label}" if check.name != "free"
                         else f"input {loads}: none (free)")
        torque.set_ylabel(unit)
        for ax in (force, moment, torque):
            ax.set_xlabel("t (s)")
            ax.grid(True, alpha=0.3)
    for ax in grid[:, -1]:
        if ax.get_legend_handles_labels()[0]:
            legend_outside(ax)
    return fig
