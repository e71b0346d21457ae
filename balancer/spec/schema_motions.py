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
            "slopes at the ends), or for `law = \"spline\"` a cubic spline at the "
            "waypoints' pace (periodic for a closed path, at rest at both ends for an open "
            "one). `file` reads the times and the inputs' path from a CSV file instead.", (
                Key("name", "—", "required", "The motion's name (`--motion NAME`).",
                    (LINKAGE,), example='"diamond"'),
                Key("times", "s", "required (or `file`)", "The waypoints' times, increasing.",
                    (LINKAGE,), example="[0.0, 1.0]"),
                Key("path", "m or rad", "required (or `file`)",
                    "The waypoints: `[x, y]` of `point` (m), or, without `point`, each input's "
                    "change from the reference pose (rad), one row per time.", (LINKAGE,),
                    example="[[0.0], [0.1]]"),
                Key("point", "—", "none (the inputs' own path)",
                    "A marker point whose path it is (inverse kinematics; two inputs).",
                    (LINKAGE,), example='"E"'),
                Key("file", "—", "none",
                    "A CSV file (its path relative to the spec's folder) of the inputs over "
                    "time instead of `times` and `path`: a header `t,<input>,…` (the "
                    "linkage's inputs in its order), then one row per time (s; each input's "
                    "change from the reference pose, rad) — or, with `point`, `t,x,y` (m). Its "
                    "law is `\"spline\"` unless given; a spec written back holds the table as "
                    "`times` and `path`.",
                    (LINKAGE,), example='"motion.csv"'),
                Key("law", "—", '"cubic" ("spline" with `file`)',
                    '`"trapezoid"` (with `acc_time`), `"cubic"`, `"quintic"` (rest to rest '
                    'over the whole motion) or `"spline"` (at the waypoints\' pace: periodic '
                    "for a closed path, from rest to rest for an open one).", (LINKAGE,),
                    example='"cubic"'),
                Key("acc_time", "s", "none",
                    "The trapezoid's acceleration time: more than 0, at most half the "
                    "duration.", (LINKAGE,), example="0.25"),
                Key("samples", "—", "400", "States along the motion, 8 to 1e6.", (LINKAGE,),
                    example="400"),
            ), (LINKAGE,)),
)
