"""Orders of a cycle: the frame's loads by multiple of the crank speed.

An engine or machine designer reads the shaking by **order** (DESIGN.md, "Orders"): the peak
amplitude ``A`` of each component ``A·cos(q·θ1 + φ)`` of the shaking force, the rocking couple,
the shaking moment and the driving torque, ``q`` = 0, 1, 2, … 8 over a cycle of one revolution
and 0, ½, 1, … 8 over a cycle of two (a four-stroke engine's 720°). A load in the plane
(force, rocking couple) is also split into its **forward** and **backward** whirl: writing it as
``x + i·y = Σ_q (F_q·e^{iqθ1} + B_q·e^{−iqθ1})``, ``forward = |F_q|`` turns with the crank
(what a counterweight on the crank cancels at order 1) and ``backward = |B_q|`` against it (what
only a counter-rotating shaft cancels). A purely reciprocating force ``A·cos(qθ1)·x̂`` has both
``A/2``; a force turning with the crank has no backward part.

Everything comes from one discrete Fourier transform of the cycle's equally spaced samples
(:func:`numpy.fft.fft`): for ``N`` samples over ``n`` revolutions the bin ``j`` is order
``q = j/n``; a real signal's amplitude is ``2·|X_j|/N`` (``|X_j|/N`` at ``j = N/2``), order 0 is
the signed mean; the complex signal's ``C_j = Z_j/N`` gives ``forward = |C_j|`` and
``backward = |C_{N−j}|`` (at ``j = N/2`` the two cannot be told apart and share ``|C_j|``
evenly; order 0: ``forward`` the mean's magnitude, ``backward`` 0). No order above half the
samples is given.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: The highest order of the table.
HIGHEST_ORDER = 8


@dataclass(frozen=True)
class Whirl:
    """One order of a load in the plane (force N, or couple N·m).

    Attributes
    ----------
    x, y
        Peak amplitudes of the ``x`` and ``y`` components (order 0: their signed means).
    forward, backward
        Magnitudes of the parts of ``x + i·y`` that turn with the crank and against it.
    """

    x: float
    y: float
    forward: float
    backward: float

    def as_dict(self) -> dict[str, float]:
        """``{"x", "y", "forward", "backward"}``."""
        return {"x": self.x, "y": self.y, "forward": self.forward, "backward": self.backward}


@dataclass(frozen=True)
class Order:
    """The frame's loads at one order of the crank speed.

    Attributes
    ----------
    order
        ``q``: the multiple of the crank speed (a half for a cycle of two revolutions).
    shaking_force
        N.
    rocking_couple
        The couple about ``x`` and ``y`` from planes along the crank's axis, N·m.
    shaking_moment, driving_torque
        Peak amplitudes (order 0: signed means), N·m.
    mount_torque
        An engine's: the torque about z on its mounts, the same way (``None``: not an engine).
    """

    order: float
    shaking_force: Whirl
    rocking_couple: Whirl
    shaking_moment: float
    driving_torque: float
    mount_torque: float | None = None

    def as_dict(self) -> dict[str, object]:
        """The entry of ``orders`` in ``analyze --json`` (DESIGN.md's names)."""
        out: dict[str, object] = {
            "order": self.order, "shaking_force": self.shaking_force.as_dict(),
            "rocking_couple": self.rocking_couple.as_dict(),
            "shaking_moment": self.shaking_moment, "driving_torque": self.driving_torque}
        if self.mount_torque is not None:
            out["mount_torque"] = self.mount_torque
        return out


def order_name(order: float) -> str:
    """An order as a designer writes it: 0, 1, 2, ½, 1½."""
    whole, half = divmod(round(2 * order), 2)
    return f"{whole}" if not half else "½" if not whole else f"{whole}½"


def order_bins(samples: int, revolutions: int = 1,
               highest: int = HIGHEST_ORDER) -> list[tuple[float, int]]:
    """The table's orders and their DFT bins: ``(q, j)`` with ``q = j/revolutions``.

    Every ``j`` from 0 to ``highest·revolutions``, none above ``samples/2`` (``samples`` the
    cycle's number of samples, over all its revolutions).
    """
    top = min(highest * revolutions, samples // 2)
    return [(j / revolutions, j) for j in range(top + 1)]  # (exact: halves at most)


def scalar_amplitudes(values: ArrayLike, bins: list[int]) -> NDArray[np.float64]:
    """Peak amplitudes of a real signal at DFT ``bins`` (bin 0: the signed mean)."""
    x = np.asarray(values, dtype=float)
    n = x.size
    spectrum = np.fft.fft(x)
    out = np.empty(len(bins))
    for i, j in enumerate(bins):
        if j == 0:
            out[i] = float(np.mean(x))
        elif 2 * j == n:
            out[i] = abs(spectrum[j]) / n
        else:
            out[i] = 2 * abs(spectrum[j]) / n
    return out


def whirls(values: ArrayLike, bins: list[int]) -> list[Whirl]:
    """Each bin's :class:`Whirl` of a load in the plane given as complex ``x + i·y``.

    From the one spectrum ``C`` of ``x + i·y``: ``x`` and ``y`` have ``(C_j + C̄_{N−j})/2``
    and ``(C_j − C̄_{N−j})/(2i)``, so their peak amplitudes are ``|C_j + C̄_{N−j}|`` and
    ``|C_j − C̄_{N−j}|`` (at ``j = N/2``, where both signals' coefficients are real: ``|Re C_j|``
    and ``|Im C_j|``; at ``j = 0`` the means ``Re C_0`` and ``Im C_0``).
    """
    z = np.asarray(values, dtype=complex)
    n = z.size
    spectrum = np.fft.fft(z) / n
    out = []
    for j in bins:
        c = complex(spectrum[j])
        if j == 0:
            x, y, forward, backward = c.real, c.imag, abs(c), 0.0
        elif 2 * j == n:
            x, y = abs(c.real), abs(c.imag)
            forward = backward = abs(c) / 2
        else:
            mirror = complex(spectrum[n - j]).conjugate()
            x, y = abs(c + mirror), abs(c - mirror)
            forward, backward = abs(c), abs(complex(spectrum[n - j]))
        out.append(Whirl(x=float(x), y=float(y), forward=float(forward),
                         backward=float(backward)))
    return out


def order_table(shaking_force: ArrayLike, rocking_couple: ArrayLike, shaking_moment: ArrayLike,
                driving_torque: ArrayLike, revolutions: int = 1,
                highest: int = HIGHEST_ORDER, mount_torque: ArrayLike | None = None
                ) -> tuple[Order, ...]:
    """The orders of a cycle's samples (each an array over the cycle's equally spaced angles).

    ``shaking_force`` and ``rocking_couple`` complex ``x + i·y`` (N, N·m); ``shaking_moment``
    and ``driving_torque`` real (N·m); ``revolutions`` the revolutions the samples span; an
    engine's ``mount_torque`` real (N·m), or ``None``.
    """
    force = np.asarray(shaking_force, dtype=complex)
    pairs = order_bins(force.size, revolutions, highest)
    bins = [j for _, j in pairs]
    forces = whirls(force, bins)
    couples = whirls(rocking_couple, bins)
    moments = scalar_amplitudes(shaking_moment, bins)
    torques = scalar_amplitudes(driving_torque, bins)
    mounts = None if mount_torque is None else scalar_amplitudes(mount_torque, bins)
    return tuple(
        Order(order=float(q), shaking_force=forces[i], rocking_couple=couples[i],
              shaking_moment=float(moments[i]), driving_torque=float(torques[i]),
              mount_torque=None if mounts is None else float(mounts[i]))
        for i, (q, _) in enumerate(pairs))
