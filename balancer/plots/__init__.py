"""Figures for a designer's report (matplotlib, Agg; never ``show()``).

Each ``plot_*`` function draws on the axes it is given (or a new figure's) and returns them;
the ``*_figure`` functions assemble a report's figure from results (a cycle analysis, a
motion's analysis, a simulation's verification, a front, a sweep's table), computing nothing
themselves; and :func:`save_figure` writes one as PNG, SVG or PDF (from the extension), whole
or not at all. matplotlib is imported by the functions that draw, not by importing this package.

=================  ===========================================================================
``revolution``     one revolution: the shaking force's polar diagram, moment and torque
``along``          along a motion of the inputs: the loads over time, the mechanism at a few
                   poses with its point's path and its centre of mass' track
``orders``         the order table as bars: forward and backward whirl, before and after
``phasors``        each plane's force and couple at an order as arrows, head to tail, and sums
``motion``         a simulated motion: forces on the ground, shaking moment, the centre of
                   mass' path; ``balancer verify``'s figure
``motion_runs``    ``balancer verify``'s figure of a linkage with several inputs: its runs
                   along the motions and free
``animation``      the mechanism turning (GIF, MP4)
``plan``           ``balancer plan``'s figure: the loads before and after a planned time law,
                   and its pace
``fronts``         a trade-off front
``atlas``          a sweep's atlas and a tolerance histogram
``style``          colours, styles, axes, numbers, writing files
``drawing``        what pictures draw of a mechanism: its frame, links and centres of mass
                   over a revolution, from its kinematics
=================  ===========================================================================
"""

from __future__ import annotations

from .along import (
    MotionDrawing,
    motion_figure,
    plot_centre_of_mass_track,
    plot_over_time,
    plot_poses,
)
from .animation import animate, animation_figure
from .atlas import sweep_figure
from .fronts import front_figure
from .motion import plot_com_path, plot_reactions, plot_shaking_moment, verification_figure
from .motion_runs import motion_verification_figure
from .orders import orders_figure, plot_orders
from .phasors import phasors_figure, plot_phasors
from .plan import plan_figure
from .revolution import (
    cycle_figure,
    plot_over_crank_angle,
    plot_rocking_couple_polar,
    plot_shaking_force_polar,
)
from .style import COLOURS, SERIES, save_figure, save_png

__all__ = [
    "COLOURS",
    "SERIES",
    "MotionDrawing",
    "animate",
    "animation_figure",
    "cycle_figure",
    "front_figure",
    "motion_figure",
    "motion_verification_figure",
    "orders_figure",
    "phasors_figure",
    "plan_figure",
    "plot_centre_of_mass_track",
    "plot_com_path",
    "plot_orders",
    "plot_phasors",
    "plot_over_crank_angle",
    "plot_over_time",
    "plot_poses",
    "plot_reactions",
    "plot_rocking_couple_polar",
    "plot_shaking_force_polar",
    "plot_shaking_moment",
    "save_figure",
    "save_png",
    "sweep_figure",
    "verification_figure",
]
