"""``plan --plot``: the loads along a motion before and after its time law was planned.

Rows: the shaking force's magnitude, the shaking moment about the origin, each input's torque
over the motion's time (the spec's time law dashed, the planned one solid), and the path's
argument's rate ``τ̇`` (s/s) — the planned pace against the spec's. Computing nothing: the
caller gives the plan (:class:`~balancer.planning.Plan`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..linkage import trajectory
from ..model.motions import REVOLUTION
from .style import COLOURS, SERIES, legend_outside

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.figure import Figure

    from ..planning import Plan


def plan_figure(plan: Plan, title: str = "") -> Figure:
    """The report figure of ``balancer plan`` (module docstring)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8.5, 11), layout="constrained")
    force, moment, torque, pace = fig.subplots(4, 1)
    what = ("one revolution" if plan.path.along == REVOLUTION
            else f"motion {plan.path.name}")
    fig.suptitle(f"{title or 'design'}\nthe time law of {what} planned "
                 f"(least {plan.spec.measure} of the objective)")
    runs = (("spec's law", plan.before, "--", COLOURS["before"]),
            ("planned", plan.after, "-", COLOURS["after"]))
    for name, analysis, style, colour in runs:
        t, r = analysis.t, analysis.reactions
        force.plot(t, np.abs(r.shaking_force), style, color=colour, label=name)
        moment.plot(t, r.shaking_moment, style, color=colour, label=name)
        for i, (inp, tau) in enumerate(zip(analysis.inputs, r.torques, strict=True)):
            torque.plot(t, tau, style, color=SERIES[i % len(SERIES)], label=f"{inp} ({name})")
        pace.plot(t, trajectory.time_argument(analysis.motion, t)[1], style, color=colour,
                  label=name)
    force.set_title("|shaking force|")
    force.set_ylabel("N")
    moment.set_title("shaking moment about the origin")
    moment.set_ylabel("N·m")
    torque.set_title("input torques (a slide's force, N)")
    torque.set_ylabel("N·m")
    pace.set_title("the path's pace: its argument's rate dτ/dt")
    pace.set_ylabel("s/s")
    for ax in (force, moment, torque, pace):
        ax.set_xlabel("t (s)")
        ax.grid(True, alpha=0.3)
        legend_outside(ax)
    return fig
