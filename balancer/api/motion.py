"""Forward dynamics of a design, and the proof by simulation that it is balanced."""

from __future__ import annotations

from collections.abc import Callable

from ..formulations import Method
from ..mechanisms import mechanism_of
from ..model import Design, Drive
from ..simulation import Trajectory, simulate_design
from ..verification import Verification
from ..verification import verify as run_verification


def simulate(design: Design, *, method: Method | None = None, drive: Drive | None = None,
             duration: float | None = None, rtol: float | None = None,
             atol: float | None = None, outputs: int | None = None,
             progress: Callable[[float, float], None] | None = None) -> Trajectory:
    """Forward dynamics from the spec's ``[simulation]``, each keyword overriding it.

    ``method`` a formulation of the mechanism (:func:`balancer.formulations.formulation_names`);
    ``drive`` ``"free"`` or ``"constant-speed"``; ``duration`` s; ``progress`` called as
    ``progress(done, total)`` in simulated seconds. See
    :func:`balancer.simulation.simulate_design`.
    """
    mechanism_of(design.mechanism).require_one_input("a simulation")
    return simulate_design(design, method=method, drive=drive, duration=duration, rtol=rtol,
                           atol=atol, outputs=outputs, progress=progress)


def verify(design: Design, *, method: Method | None = None, duration: float | None = None,
           progress: Callable[[float, float], None] | None = None) -> Verification:
    """Proof by simulation (driven and free) that a design is balanced.

    See :func:`balancer.verification.verify`.
    """
    mechanism_of(design.mechanism).require_one_input("a verification")
    return run_verification(design, method=method, duration=duration, progress=progress)
