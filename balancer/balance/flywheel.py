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

- half on the crank's inertia and half on its counter-rotor, where the counter-rotor may change
  (their difference, which a change of crank speed makes the frame feel — what settling chose,
  :meth:`~.settling.Settling.settle` — stays as it was);
- else all on the crank's inertia.

Where their ranges (``[balance.<crank>] inertia``, ``counter_rotor``) cannot take it, the
balancing says so, naming the key and the inertia needed (the other links' inertias are not
traded against the shaking for it).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..cycle import sample_angles
from ..mechanisms import mechanism_of
from ..model import MechanismModel
from ..speed_fluctuation import CrankEnergy, Flywheel
from ..speed_fluctuation import flywheel as least_flywheel
from .problem import NumericProblem
from .result import FlywheelSizing, InfeasibleError

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
    crank = data.mechanism.input
    b = next(link for link in data.links if link.name == crank)
    needed = _flywheel(data, data.linkage_of(x), bound, gravity)
    before = _flywheel(data, data.linkage, bound, gravity).fluctuation_without
    m, e, f, inertia, rotor = physical[crank]
    # (with room on the whole inertia the crank sees, of which δ is nearly inverse)
    added = (needed.inertia + ROOM * (needed.inertia + needed.mechanism_inertia[1])
             if needed.inertia > 0 else 0.0)
    on_rotor = 0.0
    rotor_range = b.counter_rotor or (rotor, rotor)
    rotor_free = rotor_range[0] < rotor_range[1] and data.inert[b.rotor_entry]
    inertia_free = b.inertia[0] < b.inertia[1] and data.inert[b.start + 3]
    if added > 0:
        high_inertia, high_rotor = b.inertia[1], rotor_range[1] if rotor_free else rotor
        if rotor_free and inertia_free:
            on_rotor = min(added / 2, high_rotor - rotor)
        elif rotor_free:
            on_rotor = min(added, high_rotor - rotor)
        on_inertia = added - on_rotor
        if not inertia_free and on_inertia > 0 or inertia + on_inertia > high_inertia:
            reach = (high_inertia if inertia_free else inertia) + (
                high_rotor if rotor_free else rotor)
            key = f"{b.key}.inertia" if inertia_free or not rotor_free else (
                f"{b.key}.counter_rotor")
            raise InfeasibleError(
                f"a speed fluctuation of at most {bound:g} (balance.max_speed_fluctuation) "
                f"needs a flywheel of {needed.inertia:.6g} kg·m² more on the {crank}: its "
                f"inertia and counter-rotor {inertia + rotor + needed.inertia:.6g} kg·m² "
                f"together, beyond the {reach:.6g} that {key} allows; widen it",
                needed=((key, inertia + rotor + needed.inertia, reach, "kg·m²"),))
        physical[crank] = (m, e, f, inertia + on_inertia, rotor + on_rotor)
        x = data.vector_of(physical)
    after = _flywheel(data, data.linkage_of(x), bound, gravity).fluctuation_without
    return x, FlywheelSizing(bound=bound, before=before, balanced=needed.fluctuation_without,
                             after=after, added=added, crank=crank,
                             inertia=added - on_rotor, counter_rotor=on_rotor)


def _flywheel(data: NumericProblem, model: MechanismModel, bound: float,
              gravity: tuple[float, float]) -> Flywheel:
    """The least flywheel of ``model`` for ``bound`` at the problem's speed and samples."""
    assert data.speed is not None
    mech = mechanism_of(model)
    revolutions = mech.cycle_revolutions
    samples = data.samples // data.mechanism.cycle_revolutions
    energy = CrankEnergy.of(mech, sample_angles(samples, revolutions),
                            2 * math.pi * revolutions, gravity)
    return least_flywheel(energy, data.speed, bound)


__all__ = ["sized"]
