"""The spec's tables of an engine's balancing: its ``[balance]``'s keys and sections.

``[balance]``, ``[balance.objective]``, ``[balance.counterweights]`` (and its crank-web
``part``) and ``[[balance.shafts]]`` (DESIGN.md, "Balancing an engine"), joined to
:data:`balancer.spec.schema.SECTIONS`.
"""

from __future__ import annotations

from .entries import ENGINE, Key, Section

#: An engine's ``[balance]`` (DESIGN.md, "Balancing an engine"): the objective's weights, the
#: crankshaft's planes for counterweights, the new shafts.
ENGINE_BALANCE: dict[str, tuple[Key, ...]] = {
    "balance": (
        Key("objective", "table", "the defaults below",
            "The weights of the objective (the table below).", (ENGINE,),
            example="{ rocking_couple = 1.0 }"),
        Key("counterweights", "table", "none",
            "Where counterweights may go on the crankshaft (`[balance.counterweights]`, "
            "below).", (ENGINE,)),
        Key("shafts", "table", "none",
            "New balance shafts, sized by the optimiser (`[[balance.shafts]]`, below); those "
            "of `[[balance_shafts]]` stay as given.", (ENGINE,)),
        Key("max_bearing_load", "N", "none",
            "An engine's: the largest load any main bearing may carry over the cycle "
            "(inertial: at the operating speed, without gas or weights), a bound the balancing "
            "keeps (needs `[mechanism] main_bearings`); positive.", (ENGINE,),
            example="6000.0"),
    ),
    "balance.objective": (
        Key("rocking_couple", "—", "1",
            "An engine's: w_R, of the rocking couple's mean-square magnitude.", (ENGINE,),
            example="1.0"),
        Key("shaking_force", "m²", "0",
            "An engine's: w_F, of the shaking force's mean-square magnitude ((N·m)²/N²).",
            (ENGINE,), example="0.04"),
        Key("shaking_moment", "—", "0",
            "An engine's: w_M, of the mean-square shaking moment about z.", (ENGINE,),
            example="0.0"),
        Key("unbalance", "m²", "0",
            "An engine's: w_U, of Σ (mr·ω²)² over the chosen counterweights and eccentrics (ω "
            "the crank's speed): the load they put on their bearings.", (ENGINE,),
            example="0.0004"),
        Key("main_bearing_load", "m²", "0",
            "An engine's: w_B, of its main-bearing loads' mean-square magnitude over its "
            "bearings and the cycle (inertial; needs `[mechanism] main_bearings`).", (ENGINE,),
            example="0.01"),
        Key("largest_bearing_load", "m²", "0",
            "An engine's: w_L, of the square of its largest main-bearing load over its bearings "
            "and the cycle (the min–max objective; inertial; needs `[mechanism] "
            "main_bearings`).", (ENGINE,), example="1.0"),
    ),
}

#: An engine's own ``[balance]`` tables: the crankshaft's counterweights, their part, the new
#: shafts.
ENGINE_BALANCE_SECTIONS: tuple[Section, ...] = (
    Section("balance.counterweights", "An engine's counterweights on the crankshaft: the "
            "optimiser chooses each one's mass·radius (within `max_mr`) and angle (any); they "
            "replace the counterweights labelled `\"counterweight\"` in these planes.", (
                Key("planes", "m", "each cylinder's plane",
                    "The z of each plane, each once.", (ENGINE,),
                    example="[-0.088, 0.0, 0.088]"),
                Key("max_mr", "kg·m", "required",
                    "The largest mass·radius in each plane: one number, or one per plane; "
                    "positive.", (ENGINE,), example="0.035"),
                Key("radius", "m", "none",
                    "The counterweights' radius: the report then gives each one's mass; "
                    "positive.", (ENGINE,), example="0.05"),
                Key("part", "table", "none",
                    "The crank-web sector that makes each plane's counterweight (below): "
                    "`optimize` sizes it, and its room caps `max_mr` at what it holds.",
                    (ENGINE,), example='{ shape = "sector", inner_radius = 0.02, '
                    'outer_radius = 0.075, angle_deg = 160.0, thickness = 0.018 }'),
                Key("crankshafts", "—", "every crankshaft",
                    "The crankshafts that carry them, by number (1 the first, 2 and on those "
                    "of `[[crankshafts]]`): a counterweight in each plane on each.", (ENGINE,),
                    example="[1, 2]"),
            ), (ENGINE,)),
    Section("balance.counterweights.part", "The crank-web sector of each plane's "
            "counterweight, about the crank's axis, centred on its plane: its angle solved "
            "for the plane's mass·radius at the full outer radius and thickness (docs: From "
            "optimum to part). Lengths in m.", (
                Key("shape", "—", "required", '`"sector"` (the one shape of a crank web).',
                    (ENGINE,), example='"sector"'),
                Key("material", "—", '"steel"',
                    "steel (7850 kg/m³), brass (8500), tungsten-alloy (17000) or lead "
                    "(11340); any name with `density`.", (ENGINE,), example='"steel"'),
                Key("density", "kg/m³", "the material's", "The material's density; positive.",
                    (ENGINE,), example="7850.0"),
                Key("inner_radius", "m", "0", "The hub's radius about the crank's axis; at "
                    "least 0.", (ENGINE,), example="0.02"),
                Key("outer_radius", "m", "required", "The web's outer radius; more than "
                    "`inner_radius`.", (ENGINE,), example="0.075"),
                Key("angle_deg", "°", "required", "The largest full angle, in (0, 360].",
                    (ENGINE,), example="160.0"),
                Key("thickness", "m", "required", "The web's thickness along the crank's "
                    "axis; positive.", (ENGINE,), example="0.018"),
            ), (ENGINE,)),
    Section("balance.shafts[]", "A new balance shaft, geared to the crank, with an eccentric "
            "in each of its planes sized by the optimiser.", (
                Key("ratio", "—", "required",
                    "Its speed over the crank's, a non-zero whole number; negative turns the "
                    "other way.", (ENGINE,), example="-1"),
                Key("at", "m", "[0, 0]", "Its axis in the x–y plane `[x, y]`.", (ENGINE,),
                    example="[-0.06, 0.09]"),
                Key("planes", "m", "required", "The z of each eccentric, each once.",
                    (ENGINE,), example="[0.11, -0.11]"),
                Key("max_mr", "kg·m", "required",
                    "The largest mass·radius of each eccentric: one number, or one per plane; "
                    "positive.", (ENGINE,), example="0.006"),
            ), (ENGINE,)),
)

#: An engine's geared crankshafts (``[[crankshafts]]``): twin-crank, U and opposed-piston
#: engines.
GEARED_CRANKSHAFT = (
    Key("at", "m", "required",
        "Its axis in the x–y plane `[x, y]`, parallel to the first crankshaft's and away from "
        "it; the gear pair's pitch circles touch midway.", (ENGINE,), example="[0.16, 0.0]"),
    Key("ratio", "—", "-1",
        "Its speed over the first crankshaft's: -1, two equal gears in mesh, turning opposite "
        "ways; 1, through an idler gear midway between the axes, turning the same way (each "
        "pitch radius a quarter of the axes' distance).", (ENGINE,), example="-1"),
    Key("inertia", "kg·m²", "0", "About its axis, its masses included; at least 0.", (ENGINE,),
        example="0.012"),
    Key("mass", "kg", "0", "Its mass, for its weight under gravity; at least 0.", (ENGINE,),
        example="6.0"),
    Key("masses", "table", "none",
        "Every mass·radius it carries (pins, webs, counterweights), as `[links.crankshaft] "
        "masses`: their angles at θ1 = 0.", (ENGINE,),
        example="[{ mr = 0.015, phase_deg = 180.0, z = 0.0 }]"),
    Key("idler_inertia", "kg·m²", "0",
        "At ratio 1, the idler gear's inertia about its axis (its centre of mass on it); at "
        "least 0.", (ENGINE,), example="0.0"),
    Key("main_bearings", "m", "none",
        "Its main bearings' planes, increasing (as `[mechanism] main_bearings` for the first): "
        "`analyze` then gives each one's load, `B2.1`, `B2.2`, …, and the balancing's bearing "
        "terms take them.", (ENGINE,),
        example="[-0.09, 0.0, 0.09]"),
    Key("gear_z", "m", "0",
        "The plane of the gear pair (and idler) that turns it: where the teeth push on it and "
        "on the first crankshaft, for their main bearings' shares.", (ENGINE,),
        example="0.0"),
)
