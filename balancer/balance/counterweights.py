"""What to build: the counterweight that turns each original link into the balanced one.

A balanced design gives each link new inertial parameters: mass ``m``, centre of mass
``s̄ = e + i·f`` in the link's frame, inertia ``I`` about the centre of mass. Kept as it is and
with one rigid body added, the original link becomes the balanced one exactly when the added
body has (all in the link's frame, first moments and inertias about the frame's origin adding
as they do for any union of bodies)

    m_c = m − m₀,   m_c·c̄ = m·s̄ − m₀·s̄₀,   I_c + m_c·|c̄|² = (I + m·|s̄|²) − (I₀ + m₀·|s̄₀|²),

so ``c̄`` is the counterweight's centre and ``I_c`` its inertia about it. It is a body that can
be added when ``m_c > 0`` and ``I_c ≥ 0``; with ``m_c < 0`` it is material to remove (its
inertia about its centre then ``−I_c``); a change of first moment or inertia with no change of
mass is no single body: the link must be rebuilt. A steel disc of mass ``m_c`` and inertia
``I_c = m_c·R²/2`` about its axis has radius ``R = √(2·I_c/m_c)`` and thickness
``m_c/(ρ·π·R²)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..model import Link
from ..model import MechanismModel as Model

#: Density of steel, kg/m³ (the disc that realises a counterweight).
STEEL_DENSITY = 7850.0
#: A disc thicker than this many diameters is no disc (the body is as good as a point mass,
#: of any compact shape): none is proposed.
MAX_ASPECT = 10.0
#: A change of mass, first moment or inertia within this share of the link's own (its mass, its
#: mass times its reach, its inertia about the frame's origin) is rounding: nothing to add. A
#: solver meets its bounds and force balance to about 1e-10 of those scales; the figures it
#: leaves are not a body to build.
UNCHANGED = 1e-9


@dataclass(frozen=True)
class Counterweight:
    """The body to add to (``kind = "add"``) or remove from (``"remove"``) a link.

    Attributes
    ----------
    link
        The link's name.
    mass
        kg; negative for material removed; 0 where the mass does not change.
    e, f
        Its centre in the link's frame, m (0 where the mass does not change: no centre).
    inertia
        About its own centre, kg·m² (negative for material removed: the removed body's is
        ``−inertia``). Where the mass does not change, the change of the link's inertia about
        its frame's origin.
    kind
        ``"none"`` (the link is unchanged to :data:`UNCHANGED`), ``"add"``, ``"remove"``, or
        ``"rebuild"`` (no single body added or removed does it: a first moment or inertia
        changed with the mass kept, or an added body would need a negative inertia).
    first_moment
        Its mass times its centre, ``m·(e + i·f)`` in the link's frame, kg·m: the change of the
        link's first moment (which a change of first moment with the mass kept still has).
    disc_radius, disc_thickness
        The steel disc (:data:`STEEL_DENSITY`) of that mass and inertia, m; ``None`` unless
        ``kind`` is ``"add"`` with an inertia that a disc no thicker than :data:`MAX_ASPECT`
        diameters has.
    exact
        Whether the original link plus this body (mass, first moment, inertia, signed: a
        negative mass or inertia is taken away) is the balanced link. Always, except for a
        first moment changed with the mass kept (no centre carries it).
    rebuilt
        For ``kind = "rebuild"``: the balanced link's own ``(mass, e, f, inertia)`` (kg, m, m,
        kg·m² about its centre of mass), what the workshop builds instead.
    inertia_change
        The change of the link's inertia about its frame's origin, kg·m².
    """

    link: str
    mass: float
    e: float
    f: float
    inertia: float
    kind: str
    first_moment: complex = 0j
    disc_radius: float | None = None
    disc_thickness: float | None = None
    exact: bool = True
    rebuilt: tuple[float, float, float, float] | None = None
    inertia_change: float = 0.0

    @property
    def has_centre(self) -> bool:
        """Whether the body has a centre (a mass): :attr:`e`, :attr:`f` mean something."""
        return self.kind != "none" and self.mass != 0

    def as_dict(self) -> dict[str, object]:
        """The JSON form (``mass``, ``e``, ``f``, ``inertia`` are fixed names).

        What to build, as the text report gives it: the body to add or remove (``e`` and
        ``f`` ``null`` where the mass is 0: nothing has a centre there), or for ``"rebuild"``
        the new link itself (its mass, centre of mass and inertia about it: a body, every
        figure physical). ``change``: the link's change of mass (kg), of first moment in its
        frame (kg·m) and of inertia about its frame's origin (kg·m²), for every kind.
        """
        disc = None
        if self.disc_radius is not None:
            disc = {"radius": self.disc_radius, "thickness": self.disc_thickness,
                    "material": "steel", "density": STEEL_DENSITY}
        if self.rebuilt is not None:
            mass, e, f, inertia = self.rebuilt
            body: dict[str, object] = {"mass": mass, "e": e, "f": f, "inertia": inertia}
        else:
            centre = self.has_centre
            body = {"mass": self.mass, "e": self.e if centre else None,
                    "f": self.f if centre else None, "inertia": self.inertia}
        return {**body, "first_moment": [self.first_moment.real, self.first_moment.imag],
                "kind": self.kind, "exact": self.exact, "disc": disc,
                "change": {"mass": self.mass,
                           "first_moment": [self.first_moment.real, self.first_moment.imag],
                           "inertia": self.inertia_change}}


def link_scales(original: Link, balanced: Link) -> tuple[float, float, float]:
    """The scales of a link's figures before and after: mass (kg), reach (m), inertia (kg·m²).

    The larger mass; the reach, the farther centre of mass or the larger radius of gyration
    about the frame's origin; the larger inertia about the frame's origin. A change within
    :data:`UNCHANGED` of them is rounding.
    """
    m0, m1 = original.mass, balanced.mass
    j0 = original.inertia + m0 * (original.e**2 + original.f**2)
    j1 = balanced.inertia + m1 * (balanced.e**2 + balanced.f**2)
    mass = max(m0, m1)
    reach = max(math.hypot(original.e, original.f), math.hypot(balanced.e, balanced.f),
                math.sqrt(max(j0, j1) / mass) if mass else 0.0)
    return mass, reach, max(j0, j1)


def counterweight(name: str, original: Link, balanced: Link) -> Counterweight:
    """The counterweight that makes link ``original`` into ``balanced``.

    Both are links with ``mass`` (kg), ``e``, ``f`` (m, the centre of mass in the link's frame)
    and ``inertia`` (kg·m², about the centre of mass). See the module docstring.
    """
    m0, m1 = original.mass, balanced.mass
    s0, s1 = complex(original.e, original.f), complex(balanced.e, balanced.f)
    j0 = original.inertia + m0 * abs(s0) ** 2  # about the frame's origin
    j1 = balanced.inertia + m1 * abs(s1) ** 2
    dm, ds, dj = m1 - m0, m1 * s1 - m0 * s0, j1 - j0
    mass_scale, reach, _ = link_scales(original, balanced)
    mass_same = abs(dm) <= UNCHANGED * mass_scale
    moment_same = abs(ds) <= UNCHANGED * mass_scale * reach
    inertia_same = abs(dj) <= UNCHANGED * max(j0, j1)
    rebuilt = (m1, s1.real, s1.imag, balanced.inertia)
    if mass_same and moment_same and inertia_same:
        return Counterweight(name, 0.0, 0.0, 0.0, 0.0, "none")
    if mass_same:  # a first moment or an inertia moved with no mass to carry it
        # (With the first moment kept, a massless "body" of inertia dj still adds up.)
        return Counterweight(name, 0.0, 0.0, 0.0, dj, "rebuild", first_moment=ds,
                             exact=moment_same, rebuilt=rebuilt, inertia_change=dj)
    centre = ds / dm
    inertia = dj - dm * abs(centre) ** 2
    if dm > 0 and inertia >= -UNCHANGED * max(j0, j1):
        inertia = max(inertia, 0.0)
        radius = thickness = None
        if inertia > 0:
            radius = math.sqrt(2 * inertia / dm)
            thickness = dm / (STEEL_DENSITY * math.pi * radius**2)
            if thickness > MAX_ASPECT * 2 * radius:  # a point mass, not a disc
                radius = thickness = None
        return Counterweight(name, dm, centre.real, centre.imag, inertia, "add", ds, radius,
                             thickness, inertia_change=dj)
    if dm < 0 and inertia <= UNCHANGED * max(j0, j1):
        return Counterweight(name, dm, centre.real, centre.imag, min(inertia, 0.0), "remove", ds,
                             inertia_change=dj)
    return Counterweight(name, dm, centre.real, centre.imag, inertia, "rebuild", ds,
                         rebuilt=rebuilt, inertia_change=dj)


def counterweights(original: Model, balanced: Model) -> dict[str, Counterweight]:
    """Each moving link's counterweight, from the original mechanism model to the balanced one.

    The models are any mechanism's (``link_names`` and ``link(name)``), with the same links.
    """
    return {name: counterweight(name, original.link(name), balanced.link(name))
            for name in balanced.link_names}


def added_mass(weights: dict[str, Counterweight]) -> float:
    """The total mass added, kg (material removed counts negative)."""
    return math.fsum(w.mass for w in weights.values())
