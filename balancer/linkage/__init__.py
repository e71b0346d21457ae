"""The general linkage core: any planar linkage with one degree of freedom.

Revolute joints (compound hinges included), prismatic pairs with the guide on the ground or on a
moving link, linear springs, counter-rotors on links pivoted to the ground, loads as on the
four-bar. Three modules, each importing only the ones before it:

:mod:`.structure`
    From the model (:class:`balancer.model.Linkage`) to equations: each link's frame, the
    constraints of the joints in absolute coordinates ``(x, y, θ)`` per link, mobility and a
    regular reference pose, and the order in which the links are found — Assur groups, solved
    in closed form (dyads RRR, RRP, PRR, RPR) or numerically (any other group).
:mod:`.kinematics`
    Positions on the branch continuous from the reference pose, velocities and accelerations,
    vectorised over arrays of crank angles.
:mod:`.dynamics`
    Inverse dynamics: the reaction of every joint (group by group, in reverse order), the
    forces on the ground, the shaking force and moment, the driving torque — and all of them
    as linear maps of the links' inertial parameters (regressors).

Vectors are pairs of real arrays (:mod:`.vectors`), so that the same equations can also be
evaluated with CasADi's symbols.
"""
