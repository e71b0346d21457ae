"""Every key a design spec may hold: its unit, default, meaning and the mechanisms it applies to.

The one list of the spec's keys. The reader takes the keys it knows from here — a table is
screened when it is opened (:func:`screen`) and declares its keys for the spec's mechanism
(:func:`known`) — so that it cannot accept a key that has no entry; the documentation's
reference of the spec format (``docs/spec.md``) is generated from these entries when the site is
built, and the tests hold the three together (``tests/spec/test_schema.py``: every entry is accepted
where it says, refused elsewhere, and nothing else is accepted).

Tables are named by their pattern: the dotted path of the table with a link's name written
``<link>`` and an array of tables ``[]`` (``links.<link>.com``, ``mechanism.sliders[]``); the top
level is ``""``. A table whose keys are names the spec chooses (the points of a general
linkage, its links, the links listed in ``[balance]``) describes them by one entry in angle
brackets (:attr:`Section.names`).
"""

from __future__ import annotations

import re
from dataclasses import replace
from functools import lru_cache

from .entries import (  # (the mechanism types are the schema's names too)
    ENGINE,
    FOUR_BAR,
    LINKAGE,
    MECHANISMS,  # noqa: F401
    SLIDER_CRANK,
    Key,
    Section,
)
from .schema_engines import ENGINE_BALANCE, ENGINE_BALANCE_SECTIONS, GEARED_CRANKSHAFT
from .schema_motions import MOTION_SECTIONS, PLAN_SECTIONS

_CLOSED = (FOUR_BAR, SLIDER_CRANK)
#: The linkages (every mechanism but the engine): their links are the design's.
_LINKAGES = (FOUR_BAR, SLIDER_CRANK, LINKAGE)


_LINK_BODY = ("A link's frame: origin at its first joint (a general linkage: its first point), "
              "x-axis towards its second (a slider-crank's slider: global axes, from its pin).")

#: The centre of mass: one of three forms (the same keys in ``[links]`` and ``[original]``).
_COM = (
    Key("s", "m", "required with sigma",
        "Distance of the centre of mass from the link's first joint (s̄ = s·exp(iσ)); "
        "at least 0. Give `s` and `sigma`, or `e` and `f`, or `at`.", example="0.6"),
    Key("sigma", "rad", "required with s",
        "Angle of the centre of mass from the link's line (from its first joint towards its "
        "second), counter-clockwise positive.", example="0.3"),
    Key("e", "m", "required with f",
        "Centre of mass along the link's line from its first joint (s̄ = e + i·f). A "
        "slider-crank's slider: along x from its pin, in global axes.", example="0.4"),
    Key("f", "m", "required with e",
        "Centre of mass across the link's line, positive to its left. A slider-crank's slider: "
        "along y from its pin, in global axes.", example="0.0"),
)

def _link_keys(com_forms: str, engine: bool = False) -> tuple[Key, ...]:
    """A link's mass properties and loads (``[links.<link>]``, ``[original.<link>]``).

    ``engine``: the engine's links take their mass, inertia and centre of mass too (as
    :data:`_ENGINE_LINKS` says which link takes which).
    """
    linkages = _LINKAGES
    both = (*_LINKAGES, ENGINE) if engine else _LINKAGES
    return (
        Key("mass", "kg", "required",
            "Mass of the link; positive. An engine's `crankshaft`: optional (its weight under "
            "gravity).", both, example="2.1"),
        Key("inertia", "kg·m²", "required (a slider-crank's slider: 0)",
            "Moment of inertia about the centre of mass; at least 0. A slider-crank's slider "
            "does not turn: its inertia may be left out. An engine's `crankshaft`: about its "
            "axis (its masses included); its `rod`: about the rod's centre of mass; its "
            "`piston` has none.", both, example="1.1"),
        Key("com", "table", "required",
            f"The centre of mass in the link's frame (the table `com` below): {com_forms}. An "
            "engine's `rod` only (its frame: big end, x towards the small end).",
            both, example="{ e = 0.4, f = 0.0 }"),
        Key("force", "N", "[0, 0]",
            "A constant force `[Fx, Fy]` in global axes at the centre of mass, from outside the "
            "machine (no reaction on the frame).", linkages, example="[1.1, 1.2]"),
        Key("moment", "N·m", "0",
            "A constant moment on the link, counter-clockwise positive, from outside the "
            "machine.", linkages, example="0.37"),
        Key("counter_rotor", "kg·m²", "0",
            "Inertia of a counter-rotor: a disc coaxial with the link's ground pivot, geared to "
            "turn at −1 times the link's angular velocity (only its inertia counts). Only on a "
            "link pivoted to the ground: a four-bar's crank and rocker, a slider-crank's crank, "
            "a general linkage's links with a ground point. At least 0.", linkages,
            example="0.5"),
        Key("z", "m", "0",
            "The plane the link moves in, along the crank's axis (z = 0: the crank's plane). "
            "Links in different planes rock the frame about x and y (the rocking couple); the "
            "link is a lamina in its plane. An engine's rods and pistons move in their "
            "cylinders' planes.", linkages, example="0.1"),
    )


#: An engine's links and the keys each takes (of ``[links.<link>]``'s).
ENGINE_LINKS = {"crankshaft": ("inertia", "mass", "masses"),
                    "rod": ("mass", "inertia", "com"), "piston": ("mass",)}

#: A mass·radius at an angle in a plane: the crankshaft's masses, a shaft's eccentrics.
_ECCENTRIC = (
    Key("mr", "kg·m", "required",
        "Its mass times the distance of its centre from the axis; at least 0.", (ENGINE,),
        example="0.015"),
    Key("phase_deg", "°", "0",
        "Its direction from the axis at θ1 = 0, from +x towards +y.", (ENGINE,),
        example="180.0"),
    Key("z", "m", "0", "Its plane along the crankshaft.", (ENGINE,), example="-0.132"),
)

#: The lengths of an engine's cylinders (``[mechanism.lengths]``, each cylinder's override).
_CYLINDER_LENGTHS = (
    Key("crank", "m", "required", "Crank radius: half the stroke; positive.", (ENGINE,),
        example="0.040"),
    Key("rod", "m", "required",
        "Connecting rod between its pin centres; longer than crank + |offset|.", (ENGINE,),
        example="0.135"),
    Key("offset", "m", "0",
        "Désaxé: the piston pin's line from the crank's axis, along the cylinder's axis turned "
        "+90° (signed).", (ENGINE,), example="0.0"),
    Key("bore", "m", "none (required with [gas])",
        "The cylinder's bore: the gas force is (p − crankcase)·π·bore²/4; positive.",
        (ENGINE,), example="0.080"),
)


SECTIONS: tuple[Section, ...] = (
    Section("", "The spec file itself: a title and the tables below.", (
        Key("title", "—", '""', "Free text naming the design in reports.",
            example='"PB1: partial balancing"'),
        Key("mechanism", "table", "required", "The linkage's type and geometry."),
        Key("links", "table", "required", "Each moving link's mass properties and loads."),
        Key("springs", "table", "none", "Linear springs between two points (`[[springs]]`).",
            (LINKAGE,)),
        Key("balance_shafts", "table", "none",
            "An engine's balance shafts, geared to the crank (`[[balance_shafts]]`, below).",
            (ENGINE,)),
        Key("crankshafts", "table", "none",
            "An engine's further crankshafts, geared to the first (`[[crankshafts]]`, below).",
            (ENGINE,)),
        Key("gas", "table", "none",
            "An engine's gas pressure over the working cycle (`[gas]`, below).", (ENGINE,)),
        Key("operation", "table", "none",
            "The operating condition that `analyze`, `optimize`, `pareto`, `sweep` and `plot` "
            "refer to; they refuse a spec without it."),
        Key("simulation", "table", "the defaults below",
            "How `simulate` and `verify` run the equations of motion."),
        Key("balance", "table", "none",
            "The redesign problem that `optimize`, `pareto` and `sweep` solve (an engine's: "
            "its counterweights and new shafts, which `optimize` sizes)."),
        Key("original", "table", "none",
            "The unbalanced design a balanced one was derived from (same geometry), as "
            "`optimize --out` writes it: `verify` and `plot` show both.", _LINKAGES),
        Key("workspace", "table", "none",
            "The configuration space of a linkage with several inputs (`[workspace]`, "
            "below).", (LINKAGE,)),
        Key("motion", "table", "none",
            "Named motions of a linkage's inputs or of a marker point (`[[motion]]`, below).",
            _LINKAGES),
        Key("plan", "table", "none",
            "The time law `plan` chooses for a motion's path (`[plan]`, below).", _LINKAGES),
    )),
    Section("mechanism", "The type of linkage and its geometry.", (
        Key("type", "—", "required",
            '`"four-bar"` (Meijaard & van der Wijk 2020), `"slider-crank"` (Wunderlich 1964), '
            '`"linkage"` (any planar linkage with one degree of freedom) or `"engine"` '
            "(cylinders on one crankshaft).",
            example='"four-bar"'),
        Key("branch", "—", '"+"',
            'The assembly: a four-bar\'s `"+"` puts A2 to the left of the directed line A1→A3 '
            '(the paper\'s Fig. 1); a slider-crank\'s `"+"` puts the slider on the +x side of '
            'the crank pin; `"-"` the other assembly (a general linkage\'s is fixed by its '
            "reference pose).", _CLOSED, example='"+"'),
        Key("lengths", "table", "required",
            "The link lengths (the table below); an engine's: every cylinder's.",
            (*_CLOSED, ENGINE)),
        Key("strokes", "—", "4",
            "An engine's working cycle: 4 (720° of crank angle) or 2 (360°).", (ENGINE,),
            example="4"),
        Key("firing_order", "—", "none (required with [gas])",
            "The cylinders (numbered from 1, in the order of `[[mechanism.cylinders]]`) in the "
            "order they fire: the first at its first top dead centre at or after θ1 = 0, each "
            "next at its own first top dead centre after the previous firing, all within one "
            "working cycle.", (ENGINE,), example="[1, 3, 4, 2]"),
        Key("main_bearings", "m", "none (the main bearings' load summed as `O`)",
            "An engine's main bearings: their planes along the crankshaft, two or more, "
            "increasing. Each load on the crankshaft (a crank pin's force from its rods, a "
            "mass's centrifugal force and weight) is shared by the two bearings around its plane "
            "by the lever rule, and `analyze` gives each bearing's load (`B1`, `B2`, …).",
            (ENGINE,), example="[-0.2, -0.1, 0.0, 0.1, 0.2]"),
        Key("cylinders", "table", "required",
            "An engine's cylinders, cylinder 1 first (`[[mechanism.cylinders]]`, below).",
            (ENGINE,)),
        Key("input", "—", "required",
            "The name of the driven link (the crank); its first point is its ground pivot. A "
            "linkage driven at several links names them in `inputs` instead.",
            (LINKAGE,), example='"crank"'),
        Key("inputs", "—", "none",
            "The names of the driven links of a linkage with several inputs (a five-bar's "
            "two cranks), each turned about its first point, a ground pivot — or driven along "
            "its slide on a ground guide (`[[mechanism.sliders]]`, a link pinned to no ground "
            "point: its position in m, its actuator's load a force in N); the linkage's "
            "degrees of freedom must equal their count. Instead of `input`.",
            (LINKAGE,), example='["left", "right"]'),
        Key("points", "table", "required",
            "Every point at the reference pose (the table below).", (LINKAGE,)),
        Key("sliders", "table", "none",
            "Prismatic pairs (`[[mechanism.sliders]]`, below).", (LINKAGE,)),
        Key("gears", "table", "none",
            "Gear pairs (`[[mechanism.gears]]`, below).", (LINKAGE,)),
    )),
    Section("mechanism.lengths", "The lengths, m, each between 1e-50 and 1e50 m (a slider-crank's "
            "offset is signed, and may be 0).", (
        Key("crank", "m", "required", "A0→A1, the crank (l1).", (FOUR_BAR,), example="1.0"),
        Key("coupler", "m", "required", "A1→A2, the coupler (l2).", (FOUR_BAR,),
            example="3.0"),
        Key("rocker", "m", "required", "A2→A3, the rocker (l3).", (FOUR_BAR,), example="2.0"),
        Key("frame", "m", "required",
            "A0→A3, the frame (l4): A0 at the origin, A3 at (l4, 0).", (FOUR_BAR,),
            example="3.2"),
        Key("crank", "m", "required", "A0→A1, the crank radius (half the stroke).",
            (SLIDER_CRANK,), example="0.0196"),
        Key("rod", "m", "required", "A1→A2, the connecting rod; A2 is the slider's pin.",
            (SLIDER_CRANK,), example="0.085"),
        Key("offset", "m", "0",
            "Signed distance of the guide line (along +x) from A0: the guide is y = offset.",
            (SLIDER_CRANK,), example="0.0"),
        *_CYLINDER_LENGTHS,
    ), (*_CLOSED, ENGINE)),
    Section("mechanism.cylinders[]", "An engine's cylinder: its plane along the crankshaft, its "
            "crank pin's angle and its axis' angle (in-line, V, W, boxer, radial: cylinders "
            "with their own angles; cylinders on one crank pin share its phase). Its top dead "
            "centre is where its crank pin points along its axis (θ1 + phase = bank).", (
                Key("z", "m", "0", "Its plane along the crankshaft (z).", (ENGINE,),
                    example="-0.132"),
                Key("phase_deg", "°", "0",
                    "Its crank pin's angle at θ1 = 0, from +x towards +y.", (ENGINE,),
                    example="180.0"),
                Key("bank_deg", "°", "0",
                    "Its axis' angle, from the crank towards the head, from +x towards +y.",
                    (ENGINE,), example="90.0"),
                *(Key(k.name, k.unit, "`[mechanism.lengths]`'s",
                      f"{k.meaning[:-1]} — this cylinder's, where it differs.", (ENGINE,),
                      k.example) for k in _CYLINDER_LENGTHS),
                Key("crankshaft", "—", "1",
                    "The crankshaft its pin is on: 1 the first (`[links.crankshaft]`), 2 and on "
                    "those of `[[crankshafts]]` (its pin at ratio·θ1 + phase from that shaft's "
                    "axis, its axis through it).", (ENGINE,), example="2"),
            ), (ENGINE,)),
    Section("mechanism.points", "A general linkage's points at the reference pose, which fixes "
            "the assembly branch: every other pose is reached from it continuously as the crank "
            "turns.", (), (LINKAGE,),
            names=Key("<point>", "m", "—",
                      "A point's position `[x, y]` at the reference pose, within 1e50 m of the "
                      "origin. A point named by two links is a revolute joint between them (by "
                      "k links, a compound hinge); one named by one link only is a marker (a "
                      "coupler point, a spring's anchor).", (LINKAGE,), example="[0.0, 1.0]")),
    Section("mechanism.sliders[]", "A prismatic pair of a general linkage: a point of `link` "
            "runs on a line fixed in `guide`, which also keeps the two links' relative angle. "
            "Frictionless: the guide carries a normal force and a couple.", (
                Key("link", "—", "required",
                    "The sliding link (it may have a single point: its frame's x-axis is then "
                    "`direction`).", (LINKAGE,), example='"ram"'),
                Key("guide", "—", "required",
                    'The link that carries the guide line (`"ground"` for the frame).',
                    (LINKAGE,), example='"ground"'),
                Key("point", "—", "required",
                    "The point of `link` that runs on the line; the line passes through its "
                    "reference position.", (LINKAGE,), example='"D"'),
                Key("direction", "—", "required",
                    "The line's direction `[dx, dy]` at the reference pose (any length but "
                    "zero).", (LINKAGE,), example="[1.0, 0.0]"),
            ), (LINKAGE,)),
    Section("mechanism.gears[]", "A pair of spur gears between two links of a general "
            "linkage, each turned about its first point, a ground pivot: `driven` turns at "
            "`ratio` times `driver`. Their pitch circles touch on the line of the pivots; the "
            "teeth push along the common tangent there (the separating force of a pressure "
            "angle left out), and `analyze` gives that tooth load.", (
                Key("name", "—", "required", "The pair's name, as outputs call its tooth load.",
                    (LINKAGE,), example='"mesh"'),
                Key("driver", "—", "required",
                    "An input, or a link driven by a gear named before.", (LINKAGE,),
                    example='"crank"'),
                Key("driven", "—", "required", "The link the gear turns (not an input).",
                    (LINKAGE,), example='"wheel"'),
                Key("ratio", "—", "required",
                    "Its speed over the driver's: negative for two gears in mesh, above 1 for a "
                    "pinion in a ring gear; not 0 nor 1. Turned by one crank, each geared link "
                    "at a whole number of the crank's speed.", (LINKAGE,), example="-1.0"),
            ), (LINKAGE,)),
    Section("links", "The moving links by name. A four-bar's and a slider-crank's names are "
            "fixed; a general linkage names its own.", (
                Key("crank", "table", "required", "Link 1, A0→A1.", (FOUR_BAR,)),
                Key("coupler", "table", "required", "Link 2, A1→A2.", (FOUR_BAR,)),
                Key("rocker", "table", "required", "Link 3, A2→A3.", (FOUR_BAR,)),
                Key("crank", "table", "required", "The crank, A0→A1.", (SLIDER_CRANK,)),
                Key("rod", "table", "required", "The connecting rod, A1→A2.", (SLIDER_CRANK,)),
                Key("slider", "table", "required",
                    "The slider (piston) on the pin A2; it does not turn.", (SLIDER_CRANK,)),
                Key("ground", "table", "required",
                    "The frame: a link without mass whose points do not move.", (LINKAGE,)),
                Key("crankshaft", "table", "required",
                    "An engine's crankshaft: its inertia, mass and the mass·radius it carries.",
                    (ENGINE,)),
                Key("rod", "table", "required",
                    "Every cylinder's connecting rod (`rod1`, `rod2`, … in the outputs).",
                    (ENGINE,)),
                Key("piston", "table", "required",
                    "Every cylinder's reciprocating group: piston, rings, pin, a point mass at "
                    "the piston pin (`piston1`, … in the outputs).", (ENGINE,)),
            ),
            names=Key("<link>", "table", "—",
                      "A moving link of a general linkage, by the name the spec gives it "
                      '(not `ground`, `objective` nor `force_balance`).', (LINKAGE,))),
    Section("links.<link>", f"A moving link's mass properties and the loads on it. "
            f"{_LINK_BODY}", (
                Key("points", "—", "required",
                    "The names of the link's points, first its frame's origin, second the "
                    "direction of its x-axis (ternary and quaternary links too).", (LINKAGE,),
                    example='["A0", "A1"]'),
                *_link_keys("`{ s, sigma }`, `{ e, f }` or, in a general linkage, "
                            "`{ at = [x, y] }`", engine=True),
                Key("masses", "table", "none",
                    "An engine's crankshaft: every mass·radius it carries (pins, webs, "
                    "counterweights), a list of `{ mr, phase_deg, z, label }` (below).",
                    (ENGINE,), example="[{ mr = 0.015, phase_deg = 0.0, z = -0.132 }]"),
                Key("gas_force", "N", "none",
                    "A force on the slider along the guide (+x), from the frame: a number, or "
                    "a table of it over the crank angle (below). It acts between piston and "
                    "cylinder head, so it drives the crank without shaking the frame except "
                    "through the torque reaction. The slider only.", (SLIDER_CRANK,),
                    example="-1500.0"),
            )),
    Section("links.<link>.masses[]", "A mass·radius the crankshaft carries.", (
        *_ECCENTRIC,
        Key("label", "—", '""',
            'What it is (`"counterweight"`: one that `optimize` may replace).', (ENGINE,),
            example='"counterweight"'),
    ), (ENGINE,)),
    Section("links.ground", "A general linkage's frame.", (
        Key("points", "—", "required",
            "Its points: the ground pivots, and the anchors of springs and guides on the frame.",
            (LINKAGE,), example='["A0", "B0"]'),
    ), (LINKAGE,)),
    Section("links.<link>.com", "A link's centre of mass, in one of three forms: `{ s, sigma }`, "
            "`{ e, f }` or `{ at }`.", (
                *_COM,
                Key("at", "m", "—",
                    "The centre of mass's global position `[x, y]` at the reference pose (a "
                    "general linkage's links).", (LINKAGE,), example="[0.4, 0.0]"),
            )),
    Section("links.<link>.gas_force", "A slider-crank's gas force as a table over the crank "
            "angle, interpolated by a periodic cubic spline.", (
                Key("crank_angle", "rad", "required",
                    "Crank angles, increasing within one period from 0.", (SLIDER_CRANK,),
                    example="[0.0, 3.14159]"),
                Key("force", "N", "required",
                    "The force along +x at those angles (as many values).", (SLIDER_CRANK,),
                    example="[-3500.0, -30.0]"),
                Key("period", "rad", "2π",
                    "The period in crank angle (4π for a four-stroke cycle); positive.",
                    (SLIDER_CRANK,), example="6.283185307179586"),
            ), (SLIDER_CRANK,)),
    Section("springs[]", "A linear spring between two points of a general linkage (of one or two "
            "links, or the ground). One anchored to the frame counts in the shaking sums, not "
            "in the pin reactions.", (
                Key("points", "—", "required", "The two anchor points (different).", (LINKAGE,),
                    example='["B", "A3"]'),
                Key("stiffness", "N/m", "required", "Its stiffness; at least 0.", (LINKAGE,),
                    example="4530.0"),
                Key("free_length", "m", "required",
                    "The length at which it carries no force; at least 0.", (LINKAGE,),
                    example="0.07785"),
            ), (LINKAGE,)),
    Section("balance_shafts[]", "An engine's balance shaft: a shaft on an axis parallel to the "
            "crankshaft's, geared to the crank, with eccentrics in several planes.", (
                Key("ratio", "—", "required",
                    "Its speed over the crank's: a non-zero whole number (negative: it turns "
                    "the other way; ±2: a Lanchester shaft).", (ENGINE,), example="2"),
                Key("at", "m", "[0, 0]", "Its axis in the x–y plane `[x, y]`.", (ENGINE,),
                    example="[-0.10, 0.07]"),
                Key("inertia", "kg·m²", "0",
                    "About its axis, its eccentrics included (the free simulation); at least 0.",
                    (ENGINE,), example="0.0005"),
                Key("eccentrics", "table", "none",
                    "Its masses off the axis, a list of `{ mr, phase_deg, z }` (below; their "
                    "angles at θ1 = 0).", (ENGINE,),
                    example="[{ mr = 0.0037, phase_deg = 180.0, z = 0.0 }]"),
            ), (ENGINE,)),
    Section("balance_shafts[].eccentrics[]", "A mass·radius on a balance shaft.", _ECCENTRIC,
            (ENGINE,)),
    Section("crankshafts[]", "A further crankshaft of an engine, geared to the first (twin-"
            "crank, U and opposed-piston engines): the cylinders that name it have their pins "
            "on it; `analyze` gives the gear pair's tooth load.", GEARED_CRANKSHAFT, (ENGINE,)),
    Section("gas", "An engine's gas pressure: cylinder 1's absolute pressure over its working "
            "cycle from its firing top dead centre, a periodic cubic spline through the points; "
            "every cylinder follows it from its own firing (`mechanism.firing_order`). The gas "
            "force acts between piston and head: it drives the crank without shaking the frame "
            "except through the torque's reaction.", (
                Key("crank_angle_deg", "°", "required",
                    "Crank angles from the firing top dead centre, increasing within one "
                    "working cycle from 0.", (ENGINE,), example="[0.0, 360.0]"),
                Key("pressure", "Pa", "required",
                    "The absolute pressure at those angles (as many values); at least 0.",
                    (ENGINE,), example="[5.8e6, 1.0e5]"),
                Key("crankcase", "Pa", "1e5",
                    "The pressure under the piston; at least 0.", (ENGINE,),
                    example="1.0e5"),
            ), (ENGINE,)),
    Section("operation", "The operating condition of a cycle analysis and of a balancing: the "
            "crank at constant speed over one revolution, sampled at θ1 = 2πk/samples.", (
                Key("speed", "rad/s", "required",
                    "The constant crank speed, counter-clockwise positive; not 0.",
                    example="10.0"),
                Key("samples", "—", "360",
                    "Equally spaced crank angles over one revolution, from θ1 = 0; a whole "
                    "number, at least 8.", example="360"),
                Key("gravity", "m/s²", "[0, 0] (none)",
                    "Gravitational acceleration `[gx, gy]` the cycle analysis includes: the "
                    "frame then carries the links' weights (`analyze --gravity` overrides it).",
                    example="[0.0, -9.81]"),
                Key("speed_fluctuation", "—", "none",
                    "The largest speed fluctuation (ω_max − ω_min)/ω_mean allowed: `analyze` then "
                    "gives the least flywheel inertia on the crank that keeps it, from the "
                    "machine's exact energy balance (one input); in (0, 2).",
                    example="0.02"),
            )),
    *MOTION_SECTIONS,
    *PLAN_SECTIONS,
    Section("simulation", "Forward dynamics (`simulate`, `verify`).", (
        Key("duration", "s", "5", "Simulated time; positive.", example="5.0"),
        Key("theta1", "rad", "the reference pose (0 for a four-bar and a slider-crank)",
            "Initial crank angle, within ±1e5 rad.", example="1.0"),
        Key("omega1", "rad/s", "0",
            'Initial crank speed; with `drive = "constant-speed"` the speed held (where it is '
            "0, the operating speed `[operation] speed`).", example="0.0"),
        Key("gravity", "m/s²", "[0, 0] (none)", "Gravitational acceleration `[gx, gy]`.",
            example="[0.0, -9.81]"),
        Key("drive", "—", '"free"',
            '`"free"`: the crank moves under the loads alone; `"constant-speed"`: a motor on '
            "the ground holds it at constant speed.", example='"free"'),
        Key("method", "—", "the mechanism's first",
            "The formulation of the equations of motion: a four-bar's `opened-loop` (the "
            "default), `complex-masses`, `mass-matrix`, `lie-group`; a slider-crank's "
            "`mass-matrix` (the default), `complex-masses`; and for every mechanism "
            "`multibody` and `crank-angle` (a general linkage's default where its crank turns "
            "fully, else `multibody`).", example='"complex-masses"'),
        Key("rtol", "—", "1e-10",
            "Relative tolerance of the integrator; at least 100 ε (2.2e-14), below 1.",
            example="1e-10"),
        Key("atol", "—", "1e-12",
            "Absolute tolerance of the integrator (in the states' units); at least 1e-150.",
            example="1e-12"),
        Key("outputs", "—", "501",
            "Equally spaced output times, both ends included; a whole number, at least 2.",
            example="501"),
    )),
    Section("balance", "The redesign problem: exact shaking-force balance as constraints, the "
            "objective minimised over one revolution at `[operation] speed`, within each listed "
            "link's bounds. A link not listed stays as it is.", (
                Key("force_balance", "—", "true",
                    "Impose exact shaking-force balance (Eq. 57–58; Wunderlich's Eq. 10d, "
                    "20a–b; for a general linkage, the conditions found from the linkage "
                    "itself) as equality constraints.", example="true"),
                Key("force", "—", '"every-motion"',
                    'A linkage with several inputs: `"every-motion"` (the total centre of mass '
                    'still over the whole configuration space) or `"motion"` (still along each '
                    "of the spec's motions only: fewer conditions, more freedom for the "
                    "objective).", (LINKAGE,), example='"motion"'),
                Key("objective", "table", "the defaults below",
                    "The weights of the objective (the table below).",
                    example="{ shaking_moment = 1.0 }"),
                Key("motions", "table", "each motion alike",
                    "A linkage with several inputs: each motion's weight in the objective's "
                    "mean squares (`[balance.motions]`, below).", (LINKAGE,),
                    example="{ turn = 2.0 }"),
                Key("max_speed_fluctuation", "—", "none",
                    "A one-input linkage's: the largest `(ω_max − ω_min)/ω_mean` of the crank "
                    "at `[operation] speed` the balanced design may have (0 to 2), by the exact "
                    "energy balance with its loads; the least flywheel that keeps it goes on "
                    "the crank (half on its counter-rotor where that may change), within its "
                    "`inertia` and `counter_rotor` ranges.", (FOUR_BAR, SLIDER_CRANK, LINKAGE),
                    example="0.02"),
            ),
            names=Key("<link>", "table", "—",
                      "A moving link that may change, by its name: its bounds (the table "
                      "below).")),
    Section("balance.motions", "The weight of each motion in the objective of a linkage with "
            "several inputs: its terms are the mean squares along the motions, each motion's "
            "mean weighted by its share of the weights (those not named weigh 1).", (),
            (LINKAGE,),
            names=Key("<motion>", "—", "1",
                      "A motion's weight, by its name: at least 0; one of them positive.",
                      (LINKAGE,), example="2.0")),
    Section("balance.objective", "The weights of the objective J = w_M·mean(Msh²) + "
            "w_τ·mean(τ²) + w_F·mean(|F̄sh|²) + w_R·mean(|M̄rock|²) + w_m·Δm, in (N·m)², over "
            "the sampled crank angles; the inertial shaking only (applied loads are left "
            "out). Each weight is at least 0.", (
                Key("shaking_moment", "—", "1", "w_M, of the mean-square shaking moment.",
                    example="1.0"),
                Key("driving_torque", "—", "0",
                    "w_τ, of the mean-square driving torque ((N·m)²/(N·m)²); with several "
                    "inputs, of their torques' mean squares summed.", example="0.0"),
                Key("torque", "—", "0",
                    "`driving_torque` by the name a linkage with several inputs gives it "
                    "(one of the two; written back as `driving_torque`).", (LINKAGE,),
                    example="0.5"),
                Key("shaking_force", "m²", "0",
                    "w_F, of the mean-square shaking force ((N·m)²/N²; useful with "
                    "`force_balance = false`).", example="0.0"),
                Key("shaking_force_x", "m²", "0",
                    "Weight of the shaking force's x component (a slider-crank's: along the "
                    "guide), added to `shaking_force`'s.", example="1.0"),
                Key("shaking_force_y", "m²", "0",
                    "Weight of the shaking force's y component (across the guide), added to "
                    "`shaking_force`'s.", example="1.0"),
                Key("rocking_couple", "—", "0",
                    "w_R, of the rocking couple's mean-square magnitude ((N·m)²/(N·m)²): for "
                    "links in several planes along the crank's axis (`[links.<name>] z`).",
                    example="1.0"),
                Key("added_mass", "(N·m)²/kg", "0",
                    "w_m, of the mass added to the linkage (total minus the original's).",
                    example="0.0"),
            )),
    Section("balance.<link>", "What may change on one link, within which bounds. Either its own "
            "bounds (mass, centre of mass, inertia) or one `counterweight` added to the link "
            "as it is. The inertia about the centre of mass is free (at least m·ρ²) when the "
            "mass or the centre of mass may change or `min_gyration` is given; otherwise it "
            "stays.", (
                Key("mass", "kg", "the spec's mass, fixed",
                    "A range `[low, high]`, or one number that fixes it; positive, its high "
                    "end at most 1e9 times its low end.",
                    example="[2.1, 8.4]"),
                Key("com_radius", "m", "the spec's centre of mass, fixed",
                    "The centre of mass may lie anywhere within this distance of `com_about`; "
                    "at least 0.", example="1.0"),
                Key("com_about", "—", "the link's ground pivot, else its first point",
                    "A point of the link (a four-bar's A0 … A3, a slider-crank's A0 … A2) that "
                    "`com_radius` is measured from; with a `counterweight`, the point its "
                    "`radius` is measured from (default then: the link's first point). Needs "
                    "`com_radius` or `counterweight`.", example='"A0"'),
                Key("min_gyration", "m", "0",
                    "Least radius of gyration ρ about the centre of mass: inertia ≥ m·ρ²; at "
                    "least 0.", example="0.1"),
                Key("inertia", "kg·m²", "see above",
                    "A range `[low, high]` of the inertia about the centre of mass, or one "
                    "number that fixes it; at least 0.", example="[0.5, 2.0]"),
                Key("counter_rotor", "kg·m²", "the spec's counter_rotor, fixed",
                    "A range `[low, high]` of the counter-rotor's inertia, or one number; at "
                    "least 0. Only on a link pivoted to the ground.", example="[0.0, 20.0]"),
                Key("com_on_line", "—", "false",
                    "`true`: the centre of mass stays on the link's line (f = 0), within "
                    "`com_radius` of `com_about`.", example="true"),
                Key("counterweight", "table", "none",
                    "Keep the link as it is and add one counterweight: "
                    "`{ mass = [low, high], radius = r, gyration = ρ }` (below). Not with "
                    "`mass`, `com_radius`, `min_gyration` or `inertia`.",
                    example="{ mass = [0.01, 6.6], radius = 2.0, gyration = 0.05 }"),
            )),
    Section("balance.<link>.counterweight", "The one rigid body a kept link may get.", (
        Key("mass", "kg", "required",
            "Its mass: a range `[low, high]` (low = 0: none may be the answer) or one number; "
            "at least 0.", example="[0.01, 6.6]"),
        Key("radius", "m", "required",
            "Its centre lies within this distance of the link's `com_about` point; at least 0.",
            example="2.0"),
        Key("gyration", "m", "0",
            "Its own least radius of gyration about its centre; at least 0.", example="0.05"),
        Key("part", "table", "none",
            "The part that makes it: a shape family, its room and material (below). "
            "`optimize` sizes it, and its room narrows `mass`, `radius` and `gyration` to "
            "what the part can be.",
            example='{ shape = "ring", inner_radius = 0.01, outer_radius = 0.1, '
                    'thickness = 0.05 }'),
    )),
    Section("balance.<link>.counterweight.part", "The part that makes a counterweight: a "
            "prism of one material centred on the link's plane, its dimensions solved within "
            "its room for the mass, centre and inertia the optimiser asks (docs: From optimum "
            "to part). Each shape takes its own keys; lengths in m.", (
        Key("shape", "—", "required",
            '`"ring"` (on a stud at the centre), `"washers"` (a stack of ISO 7089 washers), '
            '`"sector"` (a crank-web crescent about `com_about`), `"block"`, `"insert"` (a '
            "pocket in the link filled with a denser material).", example='"ring"'),
        Key("material", "—", '"steel" (an insert: required)',
            "steel (7850 kg/m³), brass (8500), tungsten-alloy (17000) or lead (11340); any "
            "name with `density`.", example='"brass"'),
        Key("density", "kg/m³", "the material's",
            "The material's density; positive.", example="8800.0"),
        Key("inner_radius", "m", "0",
            "ring: the stud's hole; sector: the hub's radius about `com_about`. At least 0.",
            example="0.01"),
        Key("outer_radius", "m", "required (ring, sector)",
            "ring, sector: the largest outer radius; more than `inner_radius`.",
            example="0.1"),
        Key("angle_deg", "°", "required (sector)",
            "sector: the largest full angle, in (0, 360].", example="120.0"),
        Key("length", "m", "required (block)",
            "block: its length along the link's x-axis; positive.", example="0.04"),
        Key("width", "m", "required (block)",
            "block: its largest width across; positive.", example="0.1"),
        Key("radius", "m", "required (insert)",
            "insert: the pocket's largest radius; positive.", example="0.02"),
        Key("size", "—", "required (washers)",
            'washers: an ISO 7089 size, `"M3"` … `"M36"`.', example='"M12"'),
        Key("thickness", "m", "required",
            "The largest thickness along the crank's axis (washers: the stack's height; "
            "insert: the pocket's depth); positive.", example="0.05"),
        Key("host", "—", '"steel"',
            "insert: the link's own material, which the pocket takes away.",
            example='"steel"'),
        Key("host_density", "kg/m³", "the host's",
            "insert: the link's density; positive.", example="7850.0"),
    )),
    Section("original", "The unbalanced design, as `optimize --out` writes it: the same links "
            "by name (a general linkage's moving links), each with its own mass properties.", (
                Key("crank", "table", "required", "The original crank.", _CLOSED),
                Key("coupler", "table", "required", "The original coupler.", (FOUR_BAR,)),
                Key("rocker", "table", "required", "The original rocker.", (FOUR_BAR,)),
                Key("rod", "table", "required", "The original connecting rod.", (SLIDER_CRANK,)),
                Key("slider", "table", "required", "The original slider.", (SLIDER_CRANK,)),
            ),
            names=Key("<link>", "table", "—",
                      "A general linkage's original moving link, by its name; every one.",
                      (LINKAGE,))),
    Section("original.<link>", "An original link's mass properties and loads (its points are "
            "the design's).", _link_keys("`{ s, sigma }` or `{ e, f }`")),
    Section("original.<link>.com", "An original link's centre of mass: `{ s, sigma }` or "
            "`{ e, f }`.", _COM),
)



def _for_linkages(section: Section) -> Section:
    """A section of the linkages' only: its keys (and chosen names) for them alone."""
    def only(key: Key) -> Key:
        return replace(key, mechanisms=tuple(m for m in key.mechanisms if m in _LINKAGES))

    mechanisms = tuple(m for m in section.mechanisms if m in _LINKAGES)
    return replace(section, keys=tuple(only(k) for k in section.keys), mechanisms=mechanisms,
                   names=None if section.names is None else only(section.names))


#: The redesign of linkages' links (``[balance]``) and their originals (``[original]``) are the
#: linkages': an engine is balanced by counterweights and shafts of its own.
SECTIONS = tuple(_for_linkages(s) if s.pattern.split(".")[0] in ("balance", "original") else s
                 for s in SECTIONS)

#: An engine's ``[original]`` (as ``optimize --out`` writes it): the links and balance shafts
#: of the engine before its balancing, which chose its counterweights and shafts.
_ENGINE_ORIGINAL: dict[str, tuple[Key, ...]] = {
    "": (Key("original", "table", "none",
             "An engine's: the engine before its balancing, as `optimize --out` writes it: "
             "`verify` and `plot` show both.", (ENGINE,)),),
    "original": (
        Key("crankshaft", "table", "required",
            "The original crankshaft: its inertia, mass and masses (counterweights included).",
            (ENGINE,)),
        Key("rod", "table", "required", "The original connecting rod.", (ENGINE,)),
        Key("piston", "table", "required", "The original piston.", (ENGINE,)),
        Key("balance_shafts", "table", "none",
            "The original balance shafts (`[[original.balance_shafts]]`, as "
            "`[[balance_shafts]]`); none where absent.", (ENGINE,)),
        Key("crankshafts", "table", "none",
            "The original geared crankshafts (`[[original.crankshafts]]`, as "
            "`[[crankshafts]]`); the design's where absent.", (ENGINE,)),
    ),
    "original.<link>": (
        *(replace(k, mechanisms=(ENGINE,)) for k in _link_keys("`{ s, sigma }` or `{ e, f }`",
                                                                engine=True)
          if ENGINE in k.mechanisms),
        Key("masses", "table", "none",
            "The original crankshaft's masses, as `[links.crankshaft] masses`.", (ENGINE,),
            example="[{ mr = 0.015, phase_deg = 0.0, z = -0.132 }]"),
    ),
    "original.<link>.com": tuple(replace(k, mechanisms=(ENGINE,)) for k in _COM),
}
SECTIONS = tuple(
    replace(s, keys=s.keys + ENGINE_BALANCE[s.pattern], mechanisms=(*s.mechanisms, ENGINE))
    if s.pattern in ENGINE_BALANCE else s for s in SECTIONS)
SECTIONS = tuple(
    replace(s, keys=s.keys + _ENGINE_ORIGINAL[s.pattern],
            mechanisms=tuple(dict.fromkeys((*s.mechanisms, ENGINE))))
    if s.pattern in _ENGINE_ORIGINAL else s for s in SECTIONS) + (
    Section("original.<link>.masses[]", "A mass·radius the original crankshaft carried.",
            next(s for s in SECTIONS if s.pattern == "links.<link>.masses[]").keys, (ENGINE,)),
    Section("original.balance_shafts[]", "An original balance shaft of an engine (as "
            "`[[balance_shafts]]`).",
            next(s for s in SECTIONS if s.pattern == "balance_shafts[]").keys, (ENGINE,)),
    Section("original.balance_shafts[].eccentrics[]", "A mass·radius on an original balance "
            "shaft.", _ECCENTRIC, (ENGINE,)),
    Section("crankshafts[].masses[]", "A mass·radius a geared crankshaft carries.",
            next(s for s in SECTIONS if s.pattern == "links.<link>.masses[]").keys, (ENGINE,)),
    Section("original.crankshafts[]", "An original geared crankshaft (as `[[crankshafts]]`).",
            GEARED_CRANKSHAFT, (ENGINE,)),
    Section("original.crankshafts[].masses[]", "A mass·radius an original geared crankshaft "
            "carried.", next(s for s in SECTIONS if s.pattern == "links.<link>.masses[]").keys,
            (ENGINE,)),
) + ENGINE_BALANCE_SECTIONS

_BY_PATTERN = {s.pattern: s for s in SECTIONS}
_INDEX = re.compile(r"\[\d+\]$")


@lru_cache(maxsize=1024)  # (a spec's tables are read by the thousand in a sweep)
def pattern(path: str) -> str:
    """The pattern of a table's dotted path (``links.crank.com`` → ``links.<link>.com``)."""
    parts = [_INDEX.sub("[]", part) for part in path.split(".")] if path else []
    if len(parts) >= 2 and parts[0] in ("links", "original", "balance"):
        kept = {"links": ("ground",), "original": ("balance_shafts[]", "crankshafts[]"),
                "balance": ("objective", "counterweights", "shafts", "shafts[]", "motions")}.get(
            parts[0], ())
        if parts[1] not in kept:
            parts[1] = "<link>"
    return ".".join(parts)


@lru_cache(maxsize=1024)  # (a spec's tables are read by the thousand in a sweep)
def section(path: str) -> Section | None:
    """The section of a table by its dotted path (or pattern), ``None`` if it has none."""
    return _BY_PATTERN.get(pattern(path))


@lru_cache(maxsize=1024)  # (a spec's tables are read by the thousand in a sweep)
def screen(path: str) -> tuple[str, ...] | None:
    """The keys a table may hold whatever the mechanism (``None``: names the spec chooses)."""
    found = section(path)
    if found is None or found.names is not None:
        return None
    return tuple(dict.fromkeys(k.name for k in found.keys))


@lru_cache(maxsize=1024)  # (a spec's tables are read by the thousand in a sweep)
def known(path: str, mechanism: str | None = None) -> tuple[str, ...]:
    """The fixed keys of a table in a spec of ``mechanism`` (``None``: of any), in order."""
    found = section(path)
    if found is None:
        raise KeyError(f"the spec schema has no table {pattern(path)!r}")
    return tuple(dict.fromkeys(k.name for k in found.keys_for(mechanism)))
