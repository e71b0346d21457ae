"""The spec's tables of a linkage's configuration space and motions.

``[workspace]`` and ``[[motion]]`` (DESIGN.md, "Mechanisms with several inputs"), listed in
:data:`balancer.spec.schema.SECTIONS`.
"""

from __future__ import annotations

from .entries import LINKAGE, Key, Section

MOTION_SECTIONS: tuple[Section, ...] = (
    Section("workspace", "The configuration space of a linkage's inputs: each input's range "
            "as its change from the reference pose, and the grid that samples it.", (
                Key("samples", "—", "40", "Grid points per input, 2 to 10000.", (LINKAGE,),
                    example="40"),
                Key("joints", "table", "none",
                    "Limits of passive joints (`[workspace.joints]`, below).", (LINKAGE,)),
            ), (LINKAGE,),
            names=Key("<input>", "rad", "—",
                      "An input's range `[low, high]`: its change from the reference pose, "
                      "low < high, within 1000 rad.", (LINKAGE,), example="[-0.5, 0.5]")),
    Section("workspace.joints", "Limits of passive joints, named by their point.", (),
            (LINKAGE,),
            names=Key("<point>", "rad", "—",
                      "The change `[low, high]` of the angle between the joint's two links from "
                      "the reference pose.", (LINKAGE,), example="[-0.3, 2.0]")),
    Section("motion[]", "A named motion: waypoints at times, run by a time law. Its path is a "
            "cubic Hermite spline of the time law's argument through the waypoints (zero "
            "slopes at the ends), or a periodic cubic spline for `law = \"spline\"`.", (
                Key("name", "—", "required", "The motion's name (`--motion NAME`).",
                    (LINKAGE,), example='"diamond"'),
                Key("times", "s", "required", "The waypoints' times, increasing.", (LINKAGE,),
                    example="[0.0, 1.0]"),
                Key("path", "m or rad", "required",
                    "The waypoints: `[x, y]` of `point` (m), or, without `point`, each input's "
                    "change from the reference pose (rad), one row per time.", (LINKAGE,),
                    example="[[0.0], [0.1]]"),
                Key("point", "—", "none (the inputs' own path)",
                    "A marker point whose path it is (inverse kinematics; two inputs).",
                    (LINKAGE,), example='"E"'),
                Key("law", "—", '"cubic"',
                    '`"trapezoid"` (with `acc_time`), `"cubic"`, `"quintic"` (rest to rest '
                    'over the whole motion) or `"spline"` (a closed path at its waypoints\' '
                    "pace).", (LINKAGE,), example='"cubic"'),
                Key("acc_time", "s", "none",
                    "The trapezoid's acceleration time: more than 0, at most half the "
                    "duration.", (LINKAGE,), example="0.25"),
                Key("samples", "—", "400", "States along the motion, 8 to 1e6.", (LINKAGE,),
                    example="400"),
            ), (LINKAGE,)),
)
