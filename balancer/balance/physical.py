"""The design vector as each link's physical values, put exactly into their bounds.

:meth:`PhysicalValues.physical` turns a design vector's inertial parameters (``m``, ``m·e``,
``m·f``, ``J``) into each link's mass, centre of mass, inertia and counter-rotor, each within
its bounds exactly (:meth:`PhysicalValues.clamp`); :meth:`PhysicalValues.vector_of` goes back,
:meth:`PhysicalValues.built` is the design vector as built (an engine's mass·radius sites as
their placed masses say them), and :meth:`PhysicalValues.linkage_of` builds the balanced
mechanism's model.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ..model import MechanismModel as Model
from ..model.links import inertial_parameters, physical_parameters
from .bounds import LinkBounds
from .problem_data import ProblemData


class PhysicalValues(ProblemData):
    """A :class:`~.problem.NumericProblem`'s design vectors as physical values, and back."""

    def physical(self, x: NDArray[np.float64]) -> dict[str, tuple[float, float, float, float,
                                                                   float]]:
        """Each link's ``(m, e, f, I, counter-rotor)`` of design vector ``x``, in its bounds.

        ``m``, ``e = m·e/m``, ``f = m·f/m``, ``I = J − m·(e² + f²)``; an inertia within
        rounding of the original's is the original's. Each value is then put into its bounds
        exactly (:meth:`clamp`): the conversion rounds, and a designer's spec must hold what
        the problem promised. How far that moved anything is the caller's to check
        (:meth:`clamp_distance`).
        """
        out = {}
        own_x = self.own(x)
        for b in self.links:
            rotor = float(x[b.rotor]) if b.rotor is not None else 0.0
            if not b.listed:  # held: as it is (an engine's links may have no mass)
                original = b.original
                out[b.name] = (original.mass, original.e, original.f, original.inertia,
                               original.counter_rotor)
                continue
            if self.absent(b, own_x) or (b.offset is not None and b.mass[0] == 0
                                         and not own_x[b.start] > 0):
                # no counterweight (none, or no mass where none is allowed: its mass put into
                # its bounds is 0, and a body of no mass has no centre): the link as it is
                original = b.original
                out[b.name] = (original.mass, original.e, original.f, original.inertia, rotor)
                continue
            if b.offset is not None:  # the counterweight in its bounds, added to the link
                own = physical_parameters(x[b.entries] - self.offset[b.entries])
                m, e, f, inertia, rotor = self.clamp(b, *own, rotor)
                if (m, e, f, inertia) == own:  # in its bounds: the link's values as they are
                    out[b.name] = (*physical_parameters(x[b.entries]), rotor)
                    continue
                # (Through the counterweight's own values only when a bound moved it: a
                # counterweight that nearly cancels the link's first moment loses digits of
                # the sum on the way.)
                total = np.add(inertial_parameters(m, e, f, inertia), b.offset)
                out[b.name] = (*physical_parameters(total), rotor)
                continue
            m, e, f, inertia = physical_parameters(x[b.entries])
            if abs(inertia - b.original.inertia) <= 1e-12 * b.inertia_ref:
                inertia = b.original.inertia  # only roundoff from J − m·s²
            out[b.name] = self.clamp(b, m, e, f, inertia, rotor)
        return out

    @staticmethod
    def clamp(b: LinkBounds, m: float, e: float, f: float, inertia: float,
              rotor: float) -> tuple[float, float, float, float, float]:
        """Physical values of one link put exactly into its bounds ``b``.

        Mass into its range; the centre of mass onto the disc (radially) or to its fixed
        place; the inertia into ``[max(I_low, m·ρ²), I_high]``, a counterweight's also under
        its spread (:attr:`LinkBounds.counterweight_reach`: at most ``m·(reach² − |c̄ − p|²)``);
        the counter-rotor into its range. A bound derived by arithmetic (a distance, ``m·ρ²``)
        is met with a margin of a few units in the last place, so that it holds whichever way a
        reader rounds it.
        """
        ulps = 8 * 2.0**-52
        m = min(max(m, b.mass[0]), b.mass[1])
        if b.com_fixed is not None:
            e, f = b.com_fixed.real, b.com_fixed.imag
        elif b.on_line:
            e, f = min(max(e, b.line_span[0]), b.line_span[1]), 0.0
        else:
            e, f = PhysicalValues._onto_disc(b.com_centre, b.radius, e, f)
        least = m * b.gyration**2 * (1 + ulps)
        most = b.inertia[1]
        if b.offset is not None:  # a counterweight's spread
            spread = m * (b.counterweight_reach**2 - abs(complex(e, f) - b.com_centre) ** 2)
            most = min(most, max(spread * (1 - ulps), least))
        if least > most:
            least = most
        inertia = min(max(inertia, b.inertia[0], least), most)
        if b.counter_rotor is not None:
            rotor = min(max(rotor, b.counter_rotor[0]), b.counter_rotor[1])
        return m, e, f, inertia, rotor

    @staticmethod
    def _onto_disc(centre: complex, radius: float, e: float, f: float) -> tuple[float, float]:
        """``(e, f)`` moved radially onto the disc ``|s̄ − centre| ≤ radius`` if outside it.

        Judged on the coordinates as stored: ``centre + d`` rounds to the spacing of the
        coordinates, which for a small disc far from the frame's origin (a ``com_about`` at the
        far joint) is far coarser than the radius's last digits, so the point is pulled in by
        that spacing until the stored coordinates are inside. The bound is met with 8 units in
        the last place of the radius to spare (a reader's subtraction ``e − c`` rounds relative
        to the distance, its ``hypot`` to a unit or so). A radius below the coordinates'
        spacing leaves the centre itself.
        """
        limit = radius * (1 - 8 * 2.0**-52)
        d = complex(e, f) - centre
        if abs(d) <= limit:
            return e, f
        target = limit
        for _ in range(8):  # one pull by twice the rounding suffices; more is a safeguard
            if target <= 0:
                break
            d *= target / abs(d)
            p = centre + d
            e, f = p.real, p.imag
            if abs(complex(e, f) - centre) <= limit:
                return e, f
            target -= 2 * float(np.spacing(max(abs(e), abs(f))))
        return centre.real, centre.imag

    def clamp_distance(self, x: NDArray[np.float64]) -> float:
        """How far :meth:`physical` moved ``x`` to put it in its bounds, relative.

        The largest change of an entry over its scale (:attr:`scales`).
        """
        return float(np.max(np.abs(self.built(x) - x) / self.scales))

    def built(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The design vector as the spec will say it: physical values exactly in their bounds.

        Each link's through :meth:`physical`; each chosen mass·radius site as its size (within
        its bound) and angle (:meth:`.sites.Sites.as_placed`), a kept one as it is.
        """
        out = self.vector_of(self.physical(x))
        if self.sites is not None:
            part = slice(self.sites.start, self.size)
            out[part] = self.sites.as_placed(x)[part]
        return out

    def vector_of(self, physical: Mapping[str, tuple[float, float, float, float, float]]
                  ) -> NDArray[np.float64]:
        """The design vector of physical values (as from :meth:`physical`)."""
        x = np.zeros(self.size)
        for b in self.links:
            m, e, f, inertia, rotor = physical[b.name]
            x[b.entries] = inertial_parameters(m, e, f, inertia)
            if b.rotor is not None:
                x[b.rotor] = rotor
        return x

    def linkage_of(self, x: NDArray[np.float64]) -> Model:
        """The mechanism's model with design vector ``x`` (loads kept from the original links).

        Physical values from :meth:`physical`, in their bounds exactly; an engine's chosen
        masses in place of those they replace (:meth:`.sites.Sites.model_of`).
        """
        if self.sites is not None and not any(b.listed for b in self.links):
            return self.sites.model_of(self.linkage, x)
        links = {}
        values = self.physical(x)
        for b in self.links:
            m, e, f, inertia, rotor = values[b.name]
            links[b.name] = replace(
                b.original, mass=m, e=e, f=f, inertia=inertia, counter_rotor=rotor
            )
        model = self.linkage.with_links(links)
        return model if self.sites is None else self.sites.model_of(model, x)
