"""The spec's tables of a linkage's configuration space, motions and motion planning.

``[workspace]`` and ``[[motion]]`` (DESIGN.md, "Mechanisms with several inputs"), listed in
:data:`balancer.spec.schema.SECTIONS`.
"""

from __future__ import annotations

from .entries import FOUR_BAR, LINKAGE, SLIDER_CRANK, Key, Section

#: The mechanisms whose specs take motions and a plan: a general linkage (any inputs), and the
#: closed-form one-input linkages (their crank's path: a revolution, or waypoints).
ONE_INPUT_OR_MORE = (FOUR_BAR, SLIDER_CRANK, LINKAGE)

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
                    ONE_INPUT_OR_MORE, example='"diamond"'),
                Key("times", "s", "required (or `file`)", "The waypoints' times, increasing.",
                    ONE_INPUT_OR_MORE, example="[0.0, 1.0]"),
                Key("path", "m or rad", "required (or `file`)",
                    "The waypoints: `[x, y]` of `point` (m), or, without `point`, each input's "
                    "change from the reference pose (rad), one row per time.",
                    ONE_INPUT_OR_MORE,
                    example="[[0.0], [0.1]]"),
                Key("point", "—", "none (the inputs' own path)",
                    "A marker point whose path it is (inverse kinematics; two inputs).",
                    ONE_INPUT_OR_MORE, example='"E"'),
                Key("file", "—", "none",
                    "A CSV file (its path relative to the spec's folder) of the inputs over "
                    "time instead of `times` and `path`: a header `t,<input>,…` (the "
                    "linkage's inputs in its order), then one row per time (s; each input's "
                    "change from the reference pose, rad) — or, with `point`, `t,x,y` (m). Its "
                    "law is `\"spline\"` unless given; a spec written back holds the table as "
                    "`times` and `path`.",
                    ONE_INPUT_OR_MORE, example='"motion.csv"'),
                Key("law", "—", '"cubic" ("spline" with `file`)',
                    '`"trapezoid"` (with `acc_time`), `"cubic"`, `"quintic"` (rest to rest '
                    'over the whole motion) or `"spline"` (at the waypoints\' pace: periodic '
                    "for a closed path, from rest to rest for an open one).", ONE_INPUT_OR_MORE,
                    example='"cubic"'),
                Key("acc_time", "s", "none",
                    "The trapezoid's acceleration time: more than 0, at most half the "
                    "duration.", ONE_INPUT_OR_MORE, example="0.25"),
                Key("samples", "—", "400", "States along the motion, 8 to 1e6.",
                    ONE_INPUT_OR_MORE,
                    example="400"),
                Key("along", "—", "none",
                    "A planned motion's (`balancer plan` writes it): the motion whose path it "
                    "runs, by name, or `\"revolution\"` (a one-input linkage's input turning "
                    "once from the reference pose at the `[operation]` speed); with `pace` "
                    "instead of `times`, `path`, `point`, `law` and `file`.", ONE_INPUT_OR_MORE,
                    example='"diamond"'),
                Key("pace", "s, s/s", "none",
                    "A planned motion's time law: rows `[τ, τ̇]`, the path's argument (from "
                    "its first waypoint's time to its last, increasing) and its rate (at "
                    "least 0); the argument's acceleration is constant between rows.",
                    ONE_INPUT_OR_MORE, example="[[0.0, 1.0], [1.0, 1.0]]"),
            ), ONE_INPUT_OR_MORE),
)


#: Each limit of ``[plan]``: what it bounds and its unit (an input about a pivot; a slide's).
_LIMITS = {"max_speed": ("rate", "rad/s (a slide's: m/s)"),
           "max_acceleration": ("acceleration", "rad/s² (a slide's: m/s²)"),
           "max_torque": ("torque (a slide's force)", "N·m (a slide's: N)")}

#: Each weight of ``[plan.objective]``: what it weighs and its unit.
_WEIGHTS = {"shaking_moment": ("the shaking moment's", "—"),
            "shaking_force": ("the shaking force's", "(N·m)²/N²"),
            "shaking_force_x": ("the shaking force's x part's", "(N·m)²/N²"),
            "shaking_force_y": ("the shaking force's y part's", "(N·m)²/N²"),
            "rocking_couple": ("the rocking couple's", "—"),
            "torque": ("the inputs' torques' (summed)", "—")}

PLAN_SECTIONS: tuple[Section, ...] = (
    Section("plan", "The time law `balancer plan` chooses for a motion's path: the path stays, "
            "how fast it is run changes, to shake the frame least within the inputs' limits "
            "in the same duration.", (
                Key("motion", "—", "the first motion (one input without motions: "
                    '`"revolution"`)',
                    'The motion whose path is run, by name, or `"revolution"` (a one-input '
                    "linkage's input turning once at the `[operation]` speed).",
                    ONE_INPUT_OR_MORE,
                    example='"turn"'),
                Key("name", "—", "the motion's name and ` planned`", "The planned motion's name.",
                    ONE_INPUT_OR_MORE, example='"turn planned"'),
                Key("duration", "s", "the motion's", "The planned motion's duration.",
                    ONE_INPUT_OR_MORE, example="4.0"),
                Key("measure", "—", '"rms"',
                    '`"rms"` (the objective\'s mean square over time) or `"peak"` (its '
                    "largest value).", ONE_INPUT_OR_MORE, example='"rms"'),
                Key("intervals", "—", "200, or the path's segments where more",
                    "Intervals of the path's argument in the transcription, 4 to 2000, at "
                    "least the path's segments (its waypoints are among the rows).",
                    ONE_INPUT_OR_MORE, example="200"),
                Key("objective", "table", "shaking_moment = 1",
                    "The objective's weights (`[plan.objective]`, below).", ONE_INPUT_OR_MORE),
                *(Key(key, unit, "none",
                      f"The largest {what} of every input, held at the transcription's rows: "
                      "one number, or a table by input.", ONE_INPUT_OR_MORE, example="10.0")
                  for key, (what, unit) in _LIMITS.items()),
            ), ONE_INPUT_OR_MORE),
    Section("plan.objective", "The weights of the objective `plan` minimises: the weighted sum "
            "of the loads' squares, its mean over time or its largest value.", tuple(
                Key(key, unit, "1" if key == "shaking_moment" else "0",
                    f"The weight of {what} square, at least 0.", ONE_INPUT_OR_MORE,
                    example="1.0")
                for key, (what, unit) in _WEIGHTS.items()), ONE_INPUT_OR_MORE),
)
