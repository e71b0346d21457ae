"""What the pictures draw of a mechanism along a motion, computed for them.

The figures (:mod:`balancer.plots`) compute nothing: the mechanism's positions along a motion
— its links at a few poses, its marker point's path, its total centre of mass — are found here
from the analysis' states by the mechanism's forward kinematics, and handed to
:func:`balancer.plots.motion_figure` as a :class:`~balancer.plots.along.MotionDrawing`.
"""

from __future__ import annotations

import numpy as np

from .. import validate as v
from ..mechanisms import geometry
from ..mechanisms.base import frame_positions
from ..model import GROUND
from ..motion_analysis import MotionAnalysis
from ..plots.along import MotionDrawing

#: At most this many poses are drawn.
MAX_POSES = 50


def motion_drawing(analysis: MotionAnalysis, *, poses: int = 5) -> MotionDrawing:
    """What :func:`balancer.motion_figure` draws of the mechanism along an analysed motion.

    The mechanism's points at ``poses`` equally spaced times from the motion's start to its end
    (at the analysis' nearest states; the end left out where the mechanism is back at its first
    pose, a closed path's end), its marker point's path and its total centre of mass at every
    state of the analysis, from the forward kinematics at the analysis' states.

    Parameters
    ----------
    analysis
        A motion's analysis (one of :func:`balancer.analyze_motions`' ``motions``).
    poses
        How many poses to draw, 1 to :data:`MAX_POSES`.

    Raises
    ------
    SpecError
        If ``poses`` is not a whole number within those.
    """
    count = v.integer(poses, "poses", minimum=1, maximum=MAX_POSES)
    mech = analysis.mechanism
    with np.errstate(all="ignore"):
        mo = mech.motion_at(analysis.state)
        points = geometry.points(mech, mo)
    n = analysis.t.size
    index = np.unique(np.rint(np.linspace(0, n - 1, count)).astype(int))
    links = {}
    for name, names in geometry.drawing(mech).items():
        if name == GROUND:
            continue
        ring = [*names, names[0]] if len(names) > 2 else list(names)
        links[name] = np.column_stack([points[p][index] for p in ring])
    size = mech.structure.length_scale()
    if index.size > 1 and all(np.max(np.abs(p[-1] - p[0])) <= 1e-9 * size
                              for p in links.values()):
        index = index[:-1]
        links = {name: p[:-1] for name, p in links.items()}
    point = analysis.motion.point
    return MotionDrawing(t=np.asarray(analysis.t[index], float), links=links,
                         ground=dict(frame_positions(mech)),
                         centre_of_mass=analysis.centre_of_mass,
                         point=point,
                         path=None if point is None else np.asarray(points[point], complex))
