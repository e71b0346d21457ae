"""A balancing under a bound on the crank's speed fluctuation: the flywheel it puts on the crank.

``[balance] max_speed_fluctuation = δ``: the balanced design's crank must turn at the operating
speed with ``(ω_max − ω_min)/ω_mean ≤ δ``, by the exact energy balance of the machine with its
loads under a constant torque (:mod:`balancer.speed_fluctuation`: the inertia the crank sees,
``J(θ)``, from the inverse dynamics). At constant speed the crank's own inertia and its
counter-rotor change nothing the objective measures (their regressor columns vanish: inert,
:attr:`~.problem_data.ProblemData.inert`), and each adds to ``J(θ)`` a constant, as a flywheel
does (a counter-rotor turns at the crank's speed). So the balancing's certified optimum stays
the optimum under the bound, and the bound is met by the least flywheel ``I_f``
(:func:`balancer.speed_fluctuation.flywheel`) on the crank of the balanced design:

- half on the crank's inertia and half on its counter-rotor, where both may change (their
  difference, which a change of crank speed makes the frame feel — what settling chose,
  :meth:`~.settling.Settling.settle` — stays as it was), what one's range cannot take on the
  other;
- a crank that keeps its link and gets a counterweight: on the counter-rotor alone (the
  counterweight's inertia is its shape's, no flywheel).

The bound holds for the energy balance on the operating samples (a free run of the design swings
by it to about 1e-7 of it at 360 samples per revolution: the samples' reach of ``J(θ)`` and the
loads).

Where their ranges (``[balance.<crank>] inertia``, ``counter_rotor``) cannot take it, the
balancing says so, naming the key and the inertia needed (the other links' inertias are not
traded against the shaking for it).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..mechanisms import mechanism_of
from ..model import MechanismModel
from ..speed_fluctuation import CrankEnergy, fluctuation_alone
from ..speed_fluctuation import flywheel as least_flywheel
from .problem import NumericProblem
from .result import FlywheelSizing, InfeasibleError

#: What the built design's speed fluctuation may exceed the bound by, relative, and still be
#: taken as keeping it (the energy balance's root finding is to 1e-13; the physical values'
#: rounding far less than this).
SAMPLED = 1e-9
#: Room on the flywheel, relative to all the inertia the crank then sees: the root finder's
#: tolerance on ``I_f`` is 1e-13 of it; this much more keeps the bound after the design's
#: rounding.
ROOM = 1e-9


def sized(data: NumericProblem, x: NDArray[np.float64], bound: float,
          gravity: tuple[float, float]) -> tuple[NDArray[np.float64], FlywheelSizing]:
    """The balanced design ``x`` with the least flywheel on its crank for ``bound``.

    Raises
    ------
    InfeasibleError
        Where the crank's inertia and counter-rotor ranges cannot take the flywheel needed.
    """
    assert data.speed is not None, "a one-input mechanism at its operating speed"
    physical = dict(data.physical(x))
    crank = data.mechanism.linkage.input
    b = next(link for link in data.links if link.name == crank)
    needed = least_flywheel(_energy(data, data.linkage_of(x), gravity), data.speed, bound)
    before = fluctuation_alone(_energy(data, data.linkage, gravity), data.speed)
    m, e, f, inertia, rotor = physical[crank]
    # (with room on the whole inertia the crank sees, of which δ is nearly inverse)
    added = (needed.inertia + ROOM * (needed.inertia + needed.mechanism_inertia[1])
             if needed.inertia > 0 else 0.0)
    # What each may take: the crank's own inertia where it is a link the balancing sizes (a
    # counterweight's inertia is its shape's, no flywheel), the counter-rotor within its range.
    rotor_range = b.counter_rotor or (rotor, rotor)
    room_rotor = (rotor_range[1] - rotor if rotor_range[0] < rotor_range[1]
                  and data.inert[b.rotor_entry] else 0.0)
    room_inertia = (b.inertia[1] - inertia if b.offset is None and b.inertia[0] < b.inertia[1]
                    and data.inert[b.start + 3] else 0.0)
    on_rotor = on_inertia = 0.0
    if added > 0:
        if room_rotor + room_inertia < added:
            key = f"{b.key}.counter_rotor" if b.counter_rotor is not None and (
                b.offset is not None or not room_inertia) else f"{b.key}.inertia"
            raise InfeasibleError(
                f"a speed fluctuation of at most {bound:g} (balance.max_speed_fluctuation) "
                f"needs a flywheel of {needed.inertia:.6g} kg·m² on the {crank}: more than "
                f"its inertia and counter-rotor may take ({room_inertia + room_rotor:.6g} "
                f"kg·m² within their ranges); widen {key}",
                needed=((key, (rotor if key.endswith("counter_rotor") else inertia) + added
                         - (room_inertia if key.endswith("counter_rotor") else room_rotor),
                         rotor_range[1] if key.endswith("counter_rotor") else b.inertia[1],
                         "kg·m²"),))
        # half on each where both may take it, what one cannot on the other
        on_rotor = min(room_rotor, max(added / 2 if room_inertia else added,
                                       added - room_inertia))
        on_inertia = added - on_rotor
        physical[crank] = (m, e, f, inertia + on_inertia, rotor + on_rotor)
        x = data.vector_of(physical)
    after = fluctuation_alone(_energy(data, data.linkage_of(x), gravity), data.speed)
    if after > bound * (1 + SAMPLED):
        raise InfeasibleError(
            f"the flywheel for a speed fluctuation of at most {bound:g} "
            f"(balance.max_speed_fluctuation) could not be put on the {crank}: it turns with "
            f"{after:.6g}", needed=(("balance.max_speed_fluctuation", after, bound, ""),))
    return x, FlywheelSizing(bound=bound, before=before, balanced=needed.fluctuation_without,
                             after=after, added=added, crank=crank,
                             inertia=on_inertia, counter_rotor=on_rotor)


def _energy(data: NumericProblem, model: MechanismModel, gravity: tuple[float, float]
            ) -> CrankEnergy:
    """The energy balance's terms of ``model`` over its cycle at the problem's samples."""
    mech = mechanism_of(model)
    return CrankEnergy.over_cycle(mech, data.samples // mech.model.cycle_revolutions, gravity)


__all__ = ["sized"]
