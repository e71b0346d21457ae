"""A rotor geared to a link: what it costs the link and what the frame feels, written once.

A rotor is a disc on an axis fixed in the frame, geared to a link so that it turns at ``k``
times the link's angular velocity (``ω_r = k·ω``, ``k`` a non-zero ratio); its inertia about its
axis is ``J``. A counter-rotor (DESIGN.md) is ``k = −1``, coaxial with its link's ground pivot.
From the rotor's kinetic energy ``½·J·k²·ω²`` and angular momentum ``J·k·ω``:

- the link drives it: the power it takes from the link, ``J·k²·ω·α``, is that of a couple
  ``−J·k²·α`` on the link (:func:`link_couple`; its inertia seen by the link is ``J·k²``);
- the frame carries the rest of the rotor's change of momentum, ``−J·k·α`` in all
  (:func:`moment`): the gear train's reaction on the frame is ``J·k·(k − 1)·α``
  (:func:`ground_couple`; ``+2·J·α`` for a counter-rotor, whose link takes ``−J·α``).

The functions take numbers, arrays or CasADi symbols alike (the inertia may be a design entry).
"""

from __future__ import annotations

from ..model.links import Link
from .vectors import Num

#: The ratio of a counter-rotor: against its link, at its speed.
COUNTER = -1.0


def energy(inertia: Num, omega: Num, ratio: float = COUNTER) -> Num:
    """Kinetic energy ``½·J·k²·ω²`` of a rotor geared to a link turning at ``omega``, J."""
    return 0.5 * inertia * ratio * ratio * omega * omega


def momentum(inertia: Num, omega: Num, ratio: float = COUNTER) -> Num:
    """Angular momentum ``J·k·ω`` of the rotor about its axis, kg·m²/s."""
    return inertia * ratio * omega


def link_inertia(inertia: Num, ratio: float = COUNTER) -> Num:
    """The inertia the rotor adds to its link's, ``J·k²``, kg·m²."""
    return inertia * ratio * ratio


def link_couple(inertia: Num, alpha: Num, ratio: float = COUNTER) -> Num:
    """Couple of the rotor's gearing on its link, ``−J·k²·α``, N·m."""
    return -link_inertia(inertia, ratio) * alpha


def ground_couple(inertia: Num, alpha: Num, ratio: float = COUNTER) -> Num:
    """Couple of the rotor's gear train on the frame, ``J·k·(k − 1)·α``, N·m."""
    return inertia * ratio * (ratio - 1.0) * alpha


def moment(inertia: Num, alpha: Num, ratio: float = COUNTER) -> Num:
    """What the rotor adds to the shaking moment through its link and the frame, ``−J·k·α``."""
    return -inertia * ratio * alpha


def dynamic_link(link: Link) -> Link:
    """The link as the equations of motion see it: its counter-rotor's inertia added to ``I``.

    (:func:`link_inertia`: a counter-rotor's ``J·k²`` is ``J``.)
    """
    if link.counter_rotor == 0.0:
        return link
    return Link(
        mass=link.mass,
        inertia=link.inertia + link_inertia(link.counter_rotor),
        e=link.e,
        f=link.f,
        force=link.force,
        moment=link.moment,
        z=link.z,
    )
