"""A whole design: the mechanism, its operating condition, simulation settings, redesign problem.

Also :func:`check_scales`, the refusal of a design whose forces, moments or energies leave double
precision at its speeds and gravity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar, Literal

from .. import validate as v
from ..errors import SpecError
from .mechanisms import MechanismModel

if TYPE_CHECKING:  # (the balancing's tables load with a spec that has them)
    from .balance import BalanceProblem, RotorBalanceProblem
    from .motions import MotionSpec, Workspace
    from .plan import PlanSpec

Drive = Literal["free", "constant-speed"]

#: Largest initial crank angle, rad: its rounding (2e-11 rad) stays below the integrator's
#: relative tolerance floor times the angle.
THETA1_MAX = 1e5
#: Ways the crank can be driven in a simulation.
DRIVES: tuple[str, ...] = ("free", "constant-speed")
#: Least relative tolerance of a simulation: 100 ε, below which SciPy's integrators raise it.
RTOL_MIN = 100 * 2.220446049250313e-16
#: Least absolute tolerance: errors over it are squared, which must not overflow (1e-150²).
ATOL_MIN = 1e-150


@dataclass(frozen=True, kw_only=True)
class Operation:
    """The operating condition a cycle analysis and a balancing refer to.

    Attributes
    ----------
    speed
        Constant crank speed, rad/s (counter-clockwise positive).
    samples
        Number of equally spaced crank angles over one revolution, starting at θ1 = 0.
    gravity
        Gravitational acceleration ``(gx, gy)`` the cycle analysis includes, m/s² (``(0, 0)``:
        none): the frame then carries the links' weights too.
    speed_fluctuation
        The largest speed fluctuation ``(ω_max − ω_min)/ω_mean`` allowed, for which the analysis
        gives the least flywheel (:mod:`balancer.speed_fluctuation`); ``None``: none asked for.
    """

    speed: float
    samples: int = 360
    gravity: tuple[float, float] = (0.0, 0.0)
    speed_fluctuation: float | None = None

    #: Memory a cycle analysis or a balancing takes per sampled angle, bytes (the regressors'
    #: complex (N, 14) arrays and the motion's, with room for temporaries).
    BYTES_PER_SAMPLE: ClassVar[int] = 4096

    def __post_init__(self) -> None:
        """Check the values (keys within ``[operation]``)."""
        v.store(self, "speed", v.nonzero(self.speed, "speed", "the crank must turn"))
        samples = v.integer(self.samples, "samples", minimum=8)
        v.require_memory(samples, self.BYTES_PER_SAMPLE, "samples", "samples of a revolution")
        v.store(self, "samples", samples)
        v.store(self, "gravity", v.vector2(self.gravity, "gravity"))
        if self.speed_fluctuation is not None:
            delta = v.positive(self.speed_fluctuation, "speed_fluctuation")
            if not delta < 2:
                raise SpecError("must be below 2: (ω_max − ω_min)/ω_mean",
                                key="speed_fluctuation", value=delta)
            v.store(self, "speed_fluctuation", delta)


@dataclass(frozen=True, kw_only=True)
class SimulationSettings:
    """How ``simulate`` and ``verify`` run the forward dynamics.

    Attributes
    ----------
    duration
        Simulated time, s.
    theta1
        Initial crank angle, rad; ``None``: the mechanism's start (a general linkage's
        reference pose, θ1 = 0 for the four-bar and slider-crank).
    omega1
        Initial crank speed, rad/s; when ``drive`` is ``"constant-speed"``, the constant speed
        (where it is zero, a design's simulation takes the operating speed ``[operation] speed``:
        :func:`balancer.simulation.simulate_design`).
    gravity
        Gravitational acceleration ``(gx, gy)``, m/s² (``(0, 0)``: none).
    drive
        ``"free"``: the crank moves under the loads alone; ``"constant-speed"``: a motor on the
        ground holds the crank at ``omega1`` (or at the operating speed, see ``omega1``).
    method
        Formulation of the equations of motion (see :mod:`balancer.formulations`); ``None``:
        the mechanism's default.
    rtol, atol
        Relative and absolute tolerances of the integrator.
    outputs
        Number of equally spaced output times, including both ends.
    given
        The keys the spec gave (the others are these defaults): ``verify`` sizes its runs to
        the operating speed where the spec gives no ``duration`` and no initial speed, and the
        spec written back states what was given (or differs from its default).
    """

    duration: float = 5.0
    theta1: float | None = None
    omega1: float = 0.0
    gravity: tuple[float, float] = (0.0, 0.0)
    drive: Drive = "free"
    method: str | None = None
    rtol: float = 1e-10
    atol: float = 1e-12
    outputs: int = 501
    given: frozenset[str] = field(default=frozenset(), compare=False, repr=False)

    #: Memory a simulation takes per output time, bytes (state, evaluation, CSV text).
    BYTES_PER_OUTPUT: ClassVar[int] = 4096

    def __post_init__(self) -> None:
        """Check the values (keys within ``[simulation]``)."""
        v.store(self, "duration", v.positive(self.duration, "duration"))
        if self.theta1 is not None:
            v.store(self, "theta1", v.number(self.theta1, "theta1"))
            if abs(self.theta1) > THETA1_MAX:
                raise SpecError(f"must be within ±{THETA1_MAX:g} rad: beyond, the integration's "
                                "steps of the crank angle lose their digits to its size "
                                "(give it modulo 2π)", key="theta1", value=self.theta1)
        v.store(self, "omega1", v.number(self.omega1, "omega1"))
        v.store(self, "gravity", v.vector2(self.gravity, "gravity"))
        v.store(self, "drive", v.choice(self.drive, "drive", DRIVES))
        if self.method is not None:
            # which formulations apply depends on the mechanism: simulate checks the name
            if not isinstance(self.method, str) or not self.method:
                raise SpecError("must be the name of a formulation", key="method",
                                value=self.method)
        rtol = v.number(self.rtol, "rtol")
        if not RTOL_MIN <= rtol < 1:
            raise SpecError(f"must be at least {RTOL_MIN:.3g} (100 ε: the integrator's floor) "
                            "and below 1", key="rtol", value=self.rtol)
        v.store(self, "rtol", rtol)
        atol = v.positive(self.atol, "atol")
        if atol < ATOL_MIN:
            raise SpecError(f"must be at least {ATOL_MIN:g} (the integrator squares errors "
                            "over it)", key="atol", value=self.atol)
        v.store(self, "atol", atol)
        outputs = v.integer(self.outputs, "outputs", minimum=2)
        v.require_memory(outputs, self.BYTES_PER_OUTPUT, "outputs", "output times")
        v.store(self, "outputs", outputs)


@dataclass(frozen=True, kw_only=True)
class Design:
    """A complete design spec: the mechanism and what to do with it.

    Attributes
    ----------
    mechanism
        The linkage and its links.
    operation
        The operating speed for cycle analysis and balancing (``None`` if the spec has none).
    simulation
        Settings for forward dynamics.
    balance
        The redesign problem (``None`` if the spec has none); see :mod:`balancer.balance.problem`.
    original
        The unbalanced design this one was derived from, if any (written by ``optimize``).
    title
        A free-text name for reports.
    workspace
        A linkage's configuration space (``[workspace]``), if the spec gives it.
    motions
        Its named motions (``[[motion]]``), in the spec's order.
    plan
        The time law to plan (``[plan]``), if the spec gives one.
    """

    mechanism: MechanismModel
    operation: Operation | None = None
    simulation: SimulationSettings = field(default_factory=SimulationSettings)
    balance: BalanceProblem | RotorBalanceProblem | None = None
    original: MechanismModel | None = None
    title: str = ""
    workspace: Workspace | None = None
    motions: tuple[MotionSpec, ...] = ()
    plan: PlanSpec | None = None

    def __post_init__(self) -> None:
        """Check the parts' types and that the figures stay within double precision.

        Keys are the spec's, from its root.
        """
        if not isinstance(self.mechanism, MechanismModel):
            raise SpecError("must be a FourBar, a SliderCrank, a Linkage or an Engine",
                            key="mechanism", value=type(self.mechanism).__name__)
        for name, cls in (("operation", Operation), ("simulation", SimulationSettings)):
            value = getattr(self, name)
            if value is not None and not isinstance(value, cls):
                raise SpecError(f"must be an {cls.__name__}", key=name,
                                value=type(value).__name__)
        if self.original is not None and type(self.original) is not type(self.mechanism):
            raise SpecError("must be the same kind of mechanism as the design",
                            key="original", value=type(self.original).__name__)
        if not isinstance(self.title, str):
            raise SpecError("must be a string", key="title", value=self.title)
        self._check_motions()
        speeds = {"simulation.omega1": self.simulation.omega1}
        gravity = {"simulation.gravity": self.simulation.gravity}
        if self.operation is not None:
            speeds["operation.speed"] = self.operation.speed
            gravity["operation.gravity"] = self.operation.gravity
        for mech in (self.mechanism, self.original):
            if mech is not None:
                check_scales(mech, speeds, gravity)
        if self.balance is not None:
            self.balance.check_scales(speeds)


    def _check_motions(self) -> None:
        """The workspace names the inputs, each motion's name is its own, and its rows fit."""
        inputs = getattr(self.mechanism, "inputs", ())
        if self.workspace is not None:
            for r in self.workspace.ranges:
                if r.name not in inputs:
                    raise SpecError(f"names no input ({', '.join(inputs) or 'none'})",
                                    key=f"workspace.{r.name}")
            bodies = getattr(self.mechanism, "bodies", ())
            points = {p for b in bodies for p in b.points}
            for r in self.workspace.joints:
                if r.name not in points:
                    raise SpecError(f"names no point of the linkage ({', '.join(sorted(points))})",
                                    key=f"workspace.joints.{r.name}")
                count = sum(r.name in b.points for b in bodies)
                if count != 2:
                    raise SpecError(f"must name a point that joins two links (it is on {count})",
                                    key=f"workspace.joints.{r.name}")
        balance = self.balance
        weights = getattr(balance, "motion_weights", ())
        names = [m.name for m in self.motions]
        for name, _ in weights:
            if name not in names:
                raise SpecError(f"names no motion of the spec ({', '.join(names) or 'none'})",
                                key=f"balance.motions.{name}")
        given = dict(weights)
        if weights and self.motions and not any(given.get(n, 1.0) > 0 for n in names):
            raise SpecError("every motion weighs 0: one at least must count",
                            key="balance.motions")
        plan = self.plan
        if plan is not None:  # (motions and plans loaded where a spec has them)
            from .motions import REVOLUTION
        if plan is not None and plan.motion not in (None, REVOLUTION, *names):
            raise SpecError(f"names no motion of the spec ({', '.join(names) or 'none'})",
                            key="plan.motion", value=plan.motion)
        own = [m.name for m in self.motions if m.pace is None]
        if plan is not None and plan.name is not None and plan.name in own:
            raise SpecError("is a motion of the spec with a path of its own: the planned "
                            "motion needs another name", key="plan.name", value=plan.name)
        seen: set[str] = set()
        for i, motion in enumerate(self.motions):
            key = v.item("motion", i)
            if motion.name in seen:
                raise SpecError("is the name of another motion", key=f"{key}.name",
                                value=motion.name)
            seen.add(motion.name)
            if motion.point is None and inputs and len(motion.path[0]) != len(inputs):
                raise SpecError(f"each waypoint must give one angle per input "
                                f"({', '.join(inputs)})", key=f"{key}.path",
                                value=list(motion.path[0]))

    def motion(self, name: str | None) -> MotionSpec:
        """The motion called ``name`` (``None``: the first); :class:`SpecError` if none."""
        if not self.motions:
            raise SpecError("the spec has no [[motion]]", key="motion")
        if name is None:
            return self.motions[0]
        for motion in self.motions:
            if motion.name == name:
                return motion
        raise SpecError(f"names no motion of the spec "
                        f"({', '.join(m.name for m in self.motions)})", key="--motion",
                        value=name)


def check_scales(mechanism: MechanismModel, speeds: dict[str, float],
                 gravity: dict[str, tuple[float, float]] | None = None) -> None:
    """Raise :class:`SpecError` if a force, moment or energy of the motion leaves double precision.

    The scales (:func:`balancer.validate.check_magnitudes`): a reach ``R`` (the model's
    ``sizes`` and the centres of mass' distances from their links' origins, summed); forces
    ``m·R·ω²``, ``m·|g|``, the applied forces, the model's ``gas_forces`` and its springs'
    ``k·R`` and ``k·|l0|``; moments ``R`` times those, ``I·ω²``, ``J_c·ω²`` and the applied
    moments; energies ``I·ω²``, ``J_c·ω²``, ``m·R²·ω²``, ``k·R²`` and ``k·l0²``. Each
    input that enters a scale is a term of its own, so that the one at fault is named.
    ``speeds`` and ``gravity`` are keyed by their spec keys (the largest of each counts).
    """
    links = dict(zip(mechanism.link_names, mechanism.links, strict=True))
    reach_terms = dict(mechanism.sizes)
    for name, link in links.items():
        reach_terms[f"links.{name}.com"] = math.hypot(link.e, link.f)
    reach_key = max(reach_terms, key=reach_terms.__getitem__)
    r = [(reach_key, math.fsum(reach_terms.values()))]  # the reach R, m
    speed_key = max(speeds, key=lambda k: abs(speeds[k]))
    w2 = [(speed_key, speeds[speed_key])] * 2  # ω², as two factors
    gravity = gravity or {"gravity": (0.0, 0.0)}
    g_key = max(gravity, key=lambda k: math.hypot(*gravity[k]))
    g = gravity[g_key]
    g_abs = [(g_key, math.hypot(*g))]
    forces, moments, energies = [], [], []
    for name, link in links.items():
        mass = [(f"links.{name}.mass", link.mass)]
        inertia = [(f"links.{name}.inertia", link.inertia)]
        rotor = [(f"links.{name}.counter_rotor", link.counter_rotor)]
        force = [(f"links.{name}.force", math.hypot(*link.force))]
        forces += [mass + r + w2, mass + g_abs, force]
        moments += [mass + r + r + w2, mass + g_abs + r, force + r, inertia + w2, rotor + w2,
                    [(f"links.{name}.moment", link.moment)]]
        energies += [inertia + w2, rotor + w2, mass + r + r + w2]
    for key, gas_force in mechanism.gas_forces:
        if not gas_force.is_zero:
            gas = [(key, max(abs(x) for x in gas_force.values))]
            forces.append(gas)
            moments.append(gas + r)
    for i, spring in enumerate(mechanism.springs):
        # Its force k·(R + |l0|) at most, moment R times that, energy k·(R + |l0|)²/2: the
        # reach's and the free length's terms apart, each named by its own key.
        stiffness = [(f"{v.item('springs', i)}.stiffness", spring.stiffness)]
        free = [(f"{v.item('springs', i)}.free_length", spring.free_length)]
        for stretch in (r, free):
            forces.append(stiffness + stretch)
            moments.append(stiffness + stretch + r)
            energies.append(stiffness + stretch + stretch)
    v.check_magnitudes(forces, "the forces", "N")
    v.check_magnitudes(moments, "the moments", "N·m")
    v.check_magnitudes(energies, "the kinetic energy", "J")
