"""Design-space sweeps: the certified balanced optimum at every point, on a Dask cluster.

A sweep varies dotted spec keys (``mechanism.lengths.coupler``) over ranges — on a grid, or at
``samples`` points of a Latin hypercube or a Sobol' sequence (SciPy's ``qmc``) — and at each
point builds the design, analyses it and solves its redesign problem with the convex backend
(:func:`balancer.balance.optimizer.optimize`: the certified global optimum, exactly what a
single ``balancer optimize --backend convex`` run gives). Each point becomes one row:

- the varied keys (one column each, named as given), ``point`` (its index);
- ``status``: ``optimal`` (or the optimiser's other statuses), ``infeasible`` (no design within
  the bounds meets force balance), ``bad-geometry`` (the design does not assemble, or its crank
  does not turn fully), ``failed`` (the solver failed);
- ``shaking_moment_before``, ``shaking_moment_after`` (RMS, N·m), ``shaking_force_before``,
  ``shaking_force_after`` (RMS, N), ``rocking_couple_before``, ``rocking_couple_after`` (RMS,
  N·m; zero for a mechanism in one plane): the inertial figures of the design and of its
  optimum at the operating speed (``after`` empty unless solved); ``lower_bound`` (N·m, the
  certificate: ``√J`` of the objective), ``added_mass`` (kg; an engine's chosen masses at its
  counterweights' radius, empty where none is given), ``message``.

An engine's spec (``[balance.counterweights]``, ``[[balance.shafts]]``) is balanced at each point
as ``optimize`` balances it (:mod:`balancer.balance.rotors`); its keys — a crank radius
``mechanism.lengths.crank``, a bank angle ``mechanism.cylinders.1.bank_deg``, a plane
``balance.counterweights.planes.0`` — vary like any other.

**On Dask.** The points are cut into batches (each task solves many points, and imports and
builds once per worker); the batches run on ``dask.distributed`` — a ``LocalCluster`` on this
machine's cores by default, or the scheduler at ``scheduler`` — and each finished batch is
written at once, atomically, as its own Parquet part in ``<out>.parts/`` beside a manifest of
the sweep. A worker that dies has its tasks rerun by the scheduler (a batch's part is written
whole or not at all, and a rerun writes the same part again), an interrupted sweep resumes
from the parts it finished (``resume``), and the final table, assembled from the parts once
all are there, has every point exactly once, in order (checked), after which the parts go.

**Interrupted** (Ctrl-C, SIGINT): :func:`sweep` raises :class:`SweepInterrupted`, which says how
many points are kept and where. The local cluster's worker processes never see the signal
(:func:`balancer.interrupts.blocked`; a Ctrl-C at a terminal reaches the whole process group):
the sweep cancels their tasks and closes the cluster itself, quietly, before it raises.
"""

from __future__ import annotations

import contextlib
import copy
import hashlib
import itertools
import json
import math
import os
import shutil
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from . import interrupts
from .balance.optimizer import optimize
from .balance.result import InfeasibleError
from .cycle import cycle_analysis, one_thread
from .errors import AssemblyError, LockupError, OutputError, SolverError, SpecError
from .model import Design
from .model.balance import missing_balance
from .outputs import write_with
from .plots import sweep_figure
from .spec import design_from_dict

if TYPE_CHECKING:
    import pyarrow as pa
    from distributed import Client, LocalCluster
    from matplotlib.figure import Figure

#: Sampling methods of the varied keys.
METHODS = ("grid", "lhs", "sobol")
#: Most points per task (a task's fixed costs — transfer, scheduling — spread over this many
#: solves).
BATCH = 25
#: Fewest tasks per worker a sweep is cut into where it has few points: each worker busy to the
#: end (the last tasks of a worker are not left to it alone).
TASKS_PER_WORKER = 8


def batch_size(points: int, workers: int) -> int:
    """Points per task of a sweep of ``points`` on ``workers`` (0: in this process).

    :data:`BATCH`, or fewer where that would give a worker fewer than
    :data:`TASKS_PER_WORKER` tasks.
    """
    if workers <= 0:
        return BATCH
    return max(1, min(BATCH, math.ceil(points / (workers * TASKS_PER_WORKER))))
#: Most points one sweep takes (a million certified optima: hours on a laptop, and the table's
#: points are held in memory while it runs); a larger design space is several sweeps.
MAX_POINTS = 1_000_000
#: The table's fixed columns after the varied keys, in order.
COLUMNS = ("point", "status", "shaking_moment_before", "shaking_moment_after",
           "shaking_force_before", "shaking_force_after", "rocking_couple_before",
           "rocking_couple_after", "lower_bound", "added_mass", "message")


@dataclass(frozen=True)
class Perturb:
    """One perturbed key: the spec's value plus a normal deviate of deviation ``sigma``."""

    key: str
    sigma: float

    @classmethod
    def parse(cls, text: str) -> Perturb:
        """From ``KEY=SIGMA`` (SIGMA in the key's own unit)."""
        key, sep, rest = text.partition("=")
        try:
            sigma = float(rest)
        except ValueError:
            sigma = math.nan
        if not sep or not key or not (math.isfinite(sigma) and sigma > 0):
            raise SpecError("must be KEY=SIGMA with SIGMA > 0, e.g. links.crank.mass=0.01",
                            key="--perturb", value=text)
        return cls(key=key.strip(), sigma=sigma)


def perturbed_points(data: dict[str, Any], perturbs: Sequence[Perturb], samples: int | None,
                     seed: int = 0) -> list[dict[str, float]]:
    """``samples`` draws of the perturbed keys around the spec's values (seeded)."""
    import numpy as np

    _check_samples(samples, "--perturb")
    assert samples is not None  # (checked)
    keys = [p.key for p in perturbs]
    if len(set(keys)) != len(keys):
        raise SpecError("a key is perturbed twice", key="--perturb", value=", ".join(keys))
    base = [_value(data, p.key) for p in perturbs]
    rng = np.random.default_rng(seed)
    draws = rng.standard_normal((samples, len(perturbs)))
    return [{p.key: b + p.sigma * float(d) for p, b, d in zip(perturbs, base, row, strict=True)}
            for row in draws]


def _check_samples(samples: int | None, what: str) -> None:
    """``--samples`` given, and within :data:`MAX_POINTS`."""
    if not samples or samples < 1:
        raise SpecError(f"{what} needs --samples N", key="--samples", value=samples)
    if samples > MAX_POINTS:
        raise SpecError(f"must be at most {MAX_POINTS:,} (several sweeps for more)",
                        key="--samples", value=samples)


def _value(data: dict[str, Any], key: str) -> float:
    """The number a dotted key names in a parsed spec."""
    node, index = _locate(data, key)
    return float(node[index])


def spec_values(spec: str | os.PathLike[str], keys: Sequence[str]) -> dict[str, float]:
    """The spec's own value of each dotted key: where its design lies among a sweep's points."""
    import tomllib

    data = tomllib.loads(Path(spec).read_text(encoding="utf-8-sig"))
    return {key: _value(data, key) for key in keys}


#: The unit of a spec key by its last name (list indices skipped): SI, as the spec takes them.
KEY_UNITS = {"mass": "kg", "inertia": "kg·m²", "counter_rotor": "kg·m²",
             "e": "m", "f": "m", "s": "m", "at": "m", "com_radius": "m", "min_gyration": "m",
             "radius": "m", "gyration": "m", "free_length": "m", "sigma": "rad",
             "theta1": "rad", "speed": "rad/s", "omega1": "rad/s", "force": "N",
             "moment": "N·m", "stiffness": "N/m", "gravity": "m/s²", "duration": "s",
             "z": "m", "planes": "m", "mr": "kg·m", "max_mr": "kg·m", "bank_deg": "°",
             "phase_deg": "°", "crankcase": "Pa"}


def key_unit(key: str) -> str:
    """The unit of the number a dotted spec key names (``""`` if it has none, or is unknown).

    Every entry of ``mechanism.lengths`` and ``mechanism.points`` is a length (m); otherwise
    :data:`KEY_UNITS` by the key's last name (``links.crank.com.s`` m, ``links.crank.mass``
    kg, ``balance.crank.mass.1`` kg, ``links.crank.force.0`` N).
    """
    parts = key.split(".")
    if parts[:2] in (["mechanism", "lengths"], ["mechanism", "points"]):
        return "m"
    names = [part for part in parts if not part.isdigit()]
    return KEY_UNITS.get(names[-1], "") if names else ""


def read_table(path: str | os.PathLike[str]) -> dict[str, list[Any]]:
    """A sweep's Parquet table, by column (Python lists; a missing value is ``None``)."""
    import pyarrow.parquet as pq

    return pq.read_table(path).to_pydict()


def atlas_figure(path: str | os.PathLike[str], keys: Sequence[str] | None, *,
                 original: dict[str, float] | None = None,
                 perturbs: Sequence[Perturb] = (), headline: str = "shaking_moment") -> Figure:
    """The figure of a sweep's table (:func:`balancer.plots.sweep_figure`), keys with units.

    ``keys``: the varied keys, ``None`` for a perturbation sweep (``perturbs`` then named in
    its title); ``original``: the spec's own values, marked; ``headline``: the figure shown
    (:attr:`SweepResult.headline`).
    """
    named = list(keys) if keys is not None else [p.key for p in perturbs]
    return sweep_figure(read_table(path), keys, original=original, perturbs=perturbs,
                        units={key: key_unit(key) for key in named}, headline=headline)


def analyse_point(data: dict[str, Any], values: dict[str, float], index: int
                  ) -> dict[str, Any]:
    """One row of a perturbation sweep: the perturbed design's own figures (no redesign)."""
    row = _empty_row(values, index)
    try:
        design = design_from_dict(with_values(data, values))
        if design.operation is None:
            raise SpecError("missing required key", key="operation.speed")
        row.update(_own_figures(design), status="analysed")
    except (AssemblyError, LockupError, SpecError) as exc:
        row.update(status="bad-geometry", message=str(exc))
    return row


@dataclass(frozen=True)
class Vary:
    """One varied key: ``key`` from ``low`` to ``high`` (``count`` values on a grid)."""

    key: str
    low: float
    high: float
    count: int

    @classmethod
    def parse(cls, text: str) -> Vary:
        """From ``KEY=LOW:HIGH:N`` (``N`` may be left out when sampling: ``KEY=LOW:HIGH``)."""
        key, sep, rest = text.partition("=")
        parts = rest.split(":")
        if not sep or not key or len(parts) not in (2, 3):
            raise SpecError("must be KEY=LOW:HIGH:N, e.g. mechanism.lengths.coupler=2.5:3.5:11",
                            key="--vary", value=text)
        try:
            low, high = float(parts[0]), float(parts[1])
            count = int(parts[2]) if len(parts) == 3 else 0
        except ValueError:
            raise SpecError("LOW and HIGH must be numbers, N a whole number", key="--vary",
                            value=text) from None
        if not (math.isfinite(low) and math.isfinite(high)) or low > high:
            raise SpecError("needs finite LOW ≤ HIGH", key="--vary", value=text)
        if len(parts) == 3 and count < 1:
            raise SpecError("N must be at least 1", key="--vary", value=text)
        return cls(key=key.strip(), low=low, high=high, count=count)


def design_points(varies: Sequence[Vary], method: str = "grid", samples: int | None = None,
                  seed: int = 0) -> list[dict[str, float]]:
    """The sweep's points: each a ``{key: value}``, in the table's order.

    ``grid``: every combination of each key's ``count`` evenly spaced values (the last key
    varying fastest). ``lhs``, ``sobol``: ``samples`` points of a Latin hypercube or a scrambled
    Sobol' sequence (seeded) scaled to the ranges.
    """
    if method not in METHODS:
        raise SpecError(f"must be one of {', '.join(METHODS)}", key="--method", value=method)
    if not varies:
        raise SpecError("nothing to vary: give --vary KEY=LOW:HIGH:N", key="--vary")
    keys = [v.key for v in varies]
    if len(set(keys)) != len(keys):
        raise SpecError("a key is varied twice", key="--vary", value=", ".join(keys))
    if method == "grid":
        for v in varies:
            if v.count < 1:
                raise SpecError("a grid needs N for every key (KEY=LOW:HIGH:N)", key="--vary",
                                value=v.key)
        total = math.prod(v.count for v in varies)
        if total > MAX_POINTS:
            raise SpecError(f"makes {total:.3g} points, more than the {MAX_POINTS:,} one sweep "
                            "takes: use fewer values per key, or several sweeps",
                            key="--vary", value=", ".join(f"{v.key}:{v.count}" for v in varies))
        axes = [[v.low] if v.count == 1 else
                [v.low + (v.high - v.low) * i / (v.count - 1) for i in range(v.count)]
                for v in varies]
        return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*axes)]
    _check_samples(samples, f"--method {method}")
    from scipy.stats import qmc

    sampler = (qmc.LatinHypercube(d=len(varies), seed=seed) if method == "lhs"
               else qmc.Sobol(d=len(varies), scramble=True, seed=seed))
    unit = sampler.random(samples)
    return [{v.key: v.low + (v.high - v.low) * float(u[i]) for i, v in enumerate(varies)}
            for u in unit]


def _locate(data: dict[str, Any], key: str) -> tuple[Any, Any]:
    """The container and index of the number a dotted key names.

    A list's entry is named by its index; :class:`SpecError` names the key if it names none.
    """
    node: Any = data
    parts = key.split(".")
    for i, part in enumerate(parts):
        if isinstance(node, list) and part.isdigit() and int(part) < len(node):
            index: Any = int(part)
        elif isinstance(node, dict) and part in node:
            index = part
        else:
            raise SpecError("no such number in the spec", key=key)
        if i == len(parts) - 1:
            if isinstance(node[index], bool) or not isinstance(node[index], int | float):
                raise SpecError("names no number in the spec", key=key)
            return node, index
        node = node[index]
    raise SpecError("no such number in the spec", key=key)  # an empty key


def number_keys(data: Any, prefix: str = "") -> list[str]:
    """Every dotted key that names a number in a parsed spec (a list's entries by index)."""
    items: Iterable[tuple[str, Any]]
    if isinstance(data, dict):
        items = data.items()
    elif isinstance(data, list):
        items = ((str(i), x) for i, x in enumerate(data))
    else:
        return [prefix] if isinstance(data, int | float) and not isinstance(data, bool) \
            else []
    return [key for name, value in items
            for key in number_keys(value, f"{prefix}.{name}" if prefix else str(name))]


def check_key(data: dict[str, Any], key: str, option: str) -> None:
    """Raise :class:`SpecError` naming ``option`` if ``key`` names no number of the spec.

    The message suggests the spec's closest keys (a typo such as ``links.crank.mas``).
    """
    try:
        _locate(data, key)
    except SpecError:
        import difflib  # only for a key that is wrong

        close = difflib.get_close_matches(key, number_keys(data), n=3, cutoff=0.6)
        hint = ("; did you mean " + " or ".join(f"'{c}'" for c in close) + "?") if close \
            else "; give the dotted key of a number of the spec, e.g. links.crank.mass"
        raise SpecError(f"names no number of the spec{hint}", key=option, value=key) from None


def with_values(data: dict[str, Any], values: dict[str, float]) -> dict[str, Any]:
    """A copy of a parsed spec with each dotted key set.

    The key must name a number in the spec (``mechanism.lengths.coupler``,
    ``mechanism.points.B.1``, ``links.crank.mass``).
    """
    for key in values:
        _locate(data, key)  # (names a number: SpecError naming the key if not)
    out = _copy_along(data, [key.split(".") for key in values])
    for key, value in values.items():
        node, index = _locate(out, key)
        node[index] = float(value)
    return out


def _copy_along(node: Any, paths: list[list[str]]) -> Any:
    """``node`` with every container on ``paths`` copied, the rest shared with ``node``.

    What :func:`with_values` changes is then the copy's alone (a point's spec costs a few
    containers, not a deep copy of the whole document).
    """
    if not paths or not isinstance(node, dict | list):
        return node
    heads: dict[str, list[list[str]]] = {}
    for path in paths:
        if path:
            heads.setdefault(path[0], []).append(path[1:])
    out = copy.copy(node)
    for head, rest in heads.items():
        index: Any = int(head) if isinstance(node, list) else head
        out[index] = _copy_along(node[index], [r for r in rest if r])
    return out


def _empty_row(values: dict[str, float], index: int) -> dict[str, Any]:
    """A row with the point's values and every figure still empty."""
    return {**values, "point": index, "status": "", "message": "",
            **{name: None for name in COLUMNS[2:-1]}}


def _own_figures(design: Design) -> dict[str, float]:
    """The design's own inertial figures at the operating speed (the ``before`` columns)."""
    assert design.operation is not None  # (the sweep has checked the spec's)
    summary = cycle_analysis(design.mechanism, design.operation.speed,
                             design.operation.samples, loads=False).summary
    return {"shaking_moment_before": summary.shaking_moment.rms,
            "shaking_force_before": summary.shaking_force.rms,
            "rocking_couple_before": summary.rocking_couple.rms}


def evaluate_point(data: dict[str, Any], values: dict[str, float], index: int
                   ) -> dict[str, Any]:
    """One row of the table: the design at ``values``, analysed and balanced."""
    row = _empty_row(values, index)
    try:
        design = design_from_dict(with_values(data, values))
        result = optimize(design, "convex")
    except (AssemblyError, LockupError, SpecError) as exc:
        # It does not assemble, its crank does not turn fully, or a value makes the spec
        # invalid (a negative length, …).
        row.update(status="bad-geometry", message=str(exc))
        return row
    except SolverError as exc:  # InfeasibleError among them: the design's own figures
        row.update(status="infeasible" if isinstance(exc, InfeasibleError) else "failed",
                   message=str(exc))
        try:
            row.update(_own_figures(design))
        except Exception:  # noqa: BLE001 - the row keeps its status; figures stay empty
            pass
        return row
    before, after = result.before.summary, result.after.summary
    row.update(status=str(result.status), message=result.message,
               shaking_moment_before=before.shaking_moment.rms,
               shaking_moment_after=after.shaking_moment.rms,
               shaking_force_before=before.shaking_force.rms,
               shaking_force_after=after.shaking_force.rms,
               rocking_couple_before=before.rocking_couple.rms,
               rocking_couple_after=after.rocking_couple.rms,
               lower_bound=result.rms_lower_bound if result.rms_form else None,
               added_mass=result.added_mass)
    return row


def run_batch(data: dict[str, Any], batch: list[tuple[int, dict[str, float]]],
              analyse_only: bool = False) -> list[dict[str, Any]]:
    """Evaluate a batch of points (a Dask task): their rows, in order.

    ``analyse_only``: the designs' own figures (a perturbation sweep), no redesign. A long
    cycle's chunks run on the task's own thread (:func:`~balancer.cycle.one_thread`): the
    machine's other cores are the other workers'.
    """
    evaluate = analyse_point if analyse_only else evaluate_point
    with one_thread():  # (a long cycle's chunks: on this worker's thread alone)
        return [evaluate(data, values, index) for index, values in batch]


# ----------------------------------------------------------------------------------------------
# The table and its parts


def _parts_dir(out: Path) -> Path:
    return out.with_name(out.name + ".parts")


def _manifest(data: dict[str, Any], points: list[dict[str, float]], batch: int
              ) -> dict[str, Any]:
    text = json.dumps({"spec": data, "points": points, "batch": batch}, sort_keys=True,
                      default=str)
    return {"version": 1, "points": len(points), "batch": batch,
            "digest": hashlib.sha256(text.encode()).hexdigest()}


def _schema(keys: Sequence[str]) -> pa.Schema:
    import pyarrow as pa

    fields = [pa.field(k, pa.float64()) for k in keys]
    fields += [pa.field("point", pa.int64()), pa.field("status", pa.string())]
    fields += [pa.field(name, pa.float64()) for name in COLUMNS[2:-1]]
    fields.append(pa.field("message", pa.string()))
    return pa.schema(fields)


def _write_part(path: Path, rows: list[dict[str, Any]], keys: Sequence[str]) -> None:
    """A batch's rows as a Parquet file, written whole or not at all."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pylist(rows, schema=_schema(keys))
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by SIGINT (Ctrl-C): what it kept for ``resume``.

    Parameters
    ----------
    kept
        Points whose rows are kept (this run's and those of the runs before it).
    points
        Points of the whole sweep.
    parts
        The folder that keeps them (``None``: nothing kept, and no folder left).
    """

    def __init__(self, kept: int, points: int, parts: Path | None) -> None:
        self.kept, self.points, self.parts = kept, points, parts
        super().__init__(self.summary)

    @property
    def summary(self) -> str:
        """One line for the person who pressed Ctrl-C."""
        if self.parts is None:
            return f"no point of {self.points} was finished; nothing kept"
        return (f"{self.kept} of {self.points} points kept in {self.parts}; run the same "
                "command with --resume to finish")

    def __str__(self) -> str:
        return self.summary


@dataclass(frozen=True)
class SweepResult:
    """What a sweep did: the table's path, its rows' statuses, and how long it took.

    Attributes
    ----------
    out
        The table written.
    points
        Its rows: every point of the sweep.
    statuses
        Rows by status.
    seconds
        Wall time of this run, s.
    workers
        Dask workers used (0: in this process).
    resumed
        Batches finished by the interrupted runs before this one (``resume``).
    computed
        Points computed by this run: ``points`` less those of the ``resumed`` batches.
    residual_force
        A perturbation sweep's residual RMS shaking force (``mean``, ``p95``, ``max``, N).
    headline
        The figure its balancing is about (``shaking_moment``, an engine's ``rocking_couple``:
        the atlas shows it).
    notes
        What the person who ran it should know (``--resume`` with nothing to resume).
    """

    out: Path
    points: int
    statuses: dict[str, int]
    seconds: float
    workers: int
    resumed: int
    computed: int
    residual_force: dict[str, float | str] | None = None
    headline: str = "shaking_moment"
    notes: tuple[str, ...] = ()

    @property
    def rate(self) -> float | None:
        """Points computed per second of this run (``None``: no time, or none computed)."""
        return self.computed / self.seconds if self.seconds > 0 and self.computed else None

    def as_dict(self) -> dict[str, Any]:
        """The ``sweep --json`` summary."""
        return {"out": str(self.out), "points": self.points, "statuses": self.statuses,
                "seconds": self.seconds, "workers": self.workers,
                "resumed_batches": self.resumed,
                "points_per_second": self.rate,
                **({"residual_shaking_force": self.residual_force}
                   if self.residual_force is not None else {})}


def sweep(spec: str | os.PathLike[str], varies: Sequence[Vary], out: str | os.PathLike[str],
          *, perturbs: Sequence[Perturb] = (), method: str = "grid",
          samples: int | None = None, seed: int = 0,
          workers: int | None = None, scheduler: str | None = None, resume: bool = False,
          force: bool = False, batch: int | None = None,
          progress: Callable[[int, int], None] | None = None,
          on_batch: Callable[[int, Any], None] | None = None) -> SweepResult:
    """Run a sweep and write its table (see the module docstring).

    Parameters
    ----------
    spec
        The design spec (TOML) every point starts from.
    varies, method, samples, seed
        The points (:func:`design_points`).
    perturbs
        Instead of ``varies``: ``samples`` draws of manufacturing deviations around the spec's
        values (:func:`perturbed_points`); each row then holds the perturbed design's own
        figures (status ``analysed``, the ``before`` columns): the distribution of the residual
        shaking force of a balanced design.
    out
        The Parquet table to write.
    workers
        Worker processes of the local cluster (default: this machine's cores); ``0`` runs the
        batches in this process, without Dask.
    scheduler
        Address of a running Dask scheduler (``tcp://host:8786``) instead of a local cluster.
    resume
        Continue the interrupted sweep whose parts are beside ``out``; where there is none (it
        was interrupted before any point finished, or never ran), run it from the start with a
        note (:attr:`SweepResult.notes`): the same command line always completes a sweep.
    force
        Overwrite an existing table (never an interrupted sweep's parts: resume or remove).
    batch
        Points per task (default: :func:`batch_size` for the workers; resumed, the
        interrupted sweep's).
    progress
        Called as ``progress(points done, points)``.
    on_batch
        Called as ``on_batch(batches done, client)`` after each batch is written (tests use it
        to stop a worker or interrupt the sweep).

    Raises
    ------
    SweepInterrupted
        On SIGINT (a :class:`KeyboardInterrupt`), once the cluster is closed: what is kept.
    """
    import tomllib

    start = time.perf_counter()
    out = Path(out)
    parts = _parts_dir(out)
    try:
        data = tomllib.loads(Path(spec).read_text(encoding="utf-8-sig"))
    except OSError as exc:
        raise SpecError(f"cannot read the spec ({exc.strerror})", value=str(spec)) from None
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"not valid TOML: {exc}", value=str(spec)) from None

    design = design_from_dict(data, source=str(spec))  # the spec itself must be valid
    if not perturbs and design.balance is None:
        missing = missing_balance(design.mechanism)
        raise SpecError(f"{missing.detail}; a sweep balances each point as the spec's [balance] "
                        "asks (or give --perturb to analyse perturbed designs)",
                        key="balance", source=str(spec))
    if design.operation is None:
        raise SpecError("missing required key: the figures are taken at the operating speed",
                        key="operation.speed", source=str(spec))
    if perturbs and varies:
        raise SpecError("give --vary or --perturb, not both", key="--perturb")
    for given in perturbs or varies:
        check_key(data, given.key, "--perturb" if perturbs else "--vary")
    points = (perturbed_points(data, perturbs, samples, seed) if perturbs
              else design_points(varies, method, samples, seed))
    for key in points[0]:
        with_values(data, {key: points[0][key]})  # every key names a number of the spec
    if batch is None:
        in_process = workers == 0 and scheduler is None
        batch = (_recorded_batch(parts) if resume else None) or batch_size(
            len(points), 0 if in_process else (workers or os.cpu_count() or 1))
    if batch < 1:
        raise SpecError("must be at least 1", key="--batch", value=batch)
    manifest = _manifest(data, points, batch)
    keys = [v.key for v in varies] or [p.key for p in perturbs]
    analyse_only = bool(perturbs)
    if out.exists() and not force:
        raise OutputError("exists; give --force to overwrite it", key="--out", value=str(out))
    done: set[int] = set()
    notes: list[str] = []
    if parts.exists():
        if not resume:
            raise OutputError(f"an interrupted sweep's results are in {parts}: --resume to "
                              "continue it, or remove that folder", key="--out", value=str(out))
        try:
            old = json.loads((parts / "manifest.json").read_text())
        except (OSError, ValueError):
            old = None
        if old != manifest:
            raise OutputError(f"the interrupted sweep in {parts} was run with another spec, "
                              "other keys or other points; remove that folder to start anew",
                              key="--resume")
        done = _finished(parts)
    else:
        if resume:  # (a job restarted by its scheduler runs the same command line)
            notes.append(f"no interrupted sweep to resume ({parts} does not exist): ran it "
                         "from the start")
        parts.mkdir()
        (parts / "manifest.json").write_text(json.dumps(manifest))
    batches = [list(enumerate(points))[i:i + batch] for i in range(0, len(points), batch)]
    todo = [i for i in range(len(batches)) if i not in done]
    count = sum(len(batches[i]) for i in done)
    if progress is not None:
        progress(count, len(points))
    used = 0
    finished = len(done)

    def record(i: int, rows: list[dict[str, Any]], client: Client | None) -> None:
        nonlocal count, finished
        _write_part(parts / f"batch-{i:06d}.parquet", rows, keys)
        count += len(rows)
        finished += 1
        if progress is not None:
            progress(count, len(points))
        if on_batch is not None:
            on_batch(finished, client)

    try:
        if workers == 0 and scheduler is None:
            for i in todo:
                record(i, run_batch(data, batches[i], analyse_only), None)
        elif todo:
            used = _run_on_dask(data, batches, todo, record, workers, scheduler, analyse_only)
    except KeyboardInterrupt:
        with interrupts.shielded():  # a second Ctrl-C must not leave the parts half told
            kept = sum(len(batches[i]) for i in _finished(parts))
            if not kept:
                shutil.rmtree(parts, ignore_errors=True)
        raise SweepInterrupted(kept, len(points), parts if kept else None) from None
    except BaseException:
        if finished == 0:  # nothing computed to keep (a scheduler out of reach, …)
            shutil.rmtree(parts, ignore_errors=True)
        raise
    _assemble(parts, out, keys, len(points), len(batches))
    statuses: dict[str, int] = {}
    import pyarrow.parquet as pq

    for status in pq.read_table(out, columns=["status"]).column("status").to_pylist():
        statuses[status] = statuses.get(status, 0) + 1
    residual: dict[str, float | str] | None = None
    if perturbs:
        import numpy as np

        shaking = np.array([v for v in pq.read_table(out, columns=["shaking_force_before"])
                            .column(0).to_pylist() if v is not None])
        if shaking.size:
            residual = {"mean": float(shaking.mean()),
                        "p95": float(np.percentile(shaking, 95)),
                        "max": float(shaking.max()), "unit": "N (RMS over a revolution)"}
    return SweepResult(out=out, points=len(points), statuses=statuses,
                       seconds=time.perf_counter() - start, workers=used, resumed=len(done),
                       computed=len(points) - sum(len(batches[i]) for i in done),
                       residual_force=residual,
                       headline=(design.balance.headline if design.balance is not None
                                 else "shaking_moment"), notes=tuple(notes))


def _recorded_batch(parts: Path) -> int | None:
    """The points per task of the interrupted sweep in ``parts``, if it says."""
    try:
        value = json.loads((parts / "manifest.json").read_text()).get("batch")
    except (OSError, ValueError, AttributeError):
        return None
    return value if isinstance(value, int) and value >= 1 else None


def _finished(parts: Path) -> set[int]:
    """The batches whose parts are written in ``parts``."""
    return {int(p.stem.split("-")[1]) for p in parts.glob("batch-*.parquet")}


#: What Dask sets in its workers' environment that a sweep's local workers go without: glibc
#: then gives freed memory back at every 64 KiB, and the numpy route's temporaries (arrays of
#: a cycle's samples by the design's entries, about 100 KiB) are mapped afresh each time —
#: a point costs 1.3–1.5 times what it costs in this process.
_WITHOUT = ("MALLOC_TRIM_THRESHOLD_",)


def _worker_environment() -> dict[str, Any]:
    """Dask's configuration for a sweep's local workers: its own, without :data:`_WITHOUT`.

    (Its limits of BLAS and OpenMP threads to one per worker stay.)
    """
    import dask

    environ = dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {}
    return {"distributed.nanny.pre-spawn-environ":
            {k: v for k, v in environ.items() if k not in _WITHOUT}}


def _run_on_dask(data: dict[str, Any], batches: list[list[tuple[int, dict[str, float]]]],
                 todo: list[int],
                 record: Callable[[int, list[dict[str, Any]], Client | None], None],
                 workers: int | None, scheduler: str | None, analyse_only: bool) -> int:
    """Run the batches ``todo`` on a cluster; ``record`` each as it finishes. Its workers.

    Interrupted, it cancels the tasks and closes the client and its local cluster before the
    :class:`KeyboardInterrupt` goes on, with Dask's logs silenced (its workers' tasks cut short
    would log errors a person who pressed Ctrl-C has no use for).
    """
    import logging

    import dask
    from distributed import Client, LocalCluster, as_completed

    cluster: LocalCluster | None = None
    client: Client | None = None
    futures: dict[Any, int] = {}
    try:
        if scheduler is None:
            n = workers or os.cpu_count() or 1
            # multiprocessing's resource tracker, started with the first worker, unblocks
            # SIGINT in the thread that starts it: started here first, it leaves the block be.
            from multiprocessing import resource_tracker

            resource_tracker.ensure_running()
            with interrupts.blocked(), dask.config.set(_worker_environment()):
                # (its threads and worker processes: no SIGINT, ever)
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR)
                client = Client(cluster)
        else:
            try:
                client = Client(scheduler, timeout=10)
            except OSError as exc:
                raise SpecError(f"cannot reach the Dask scheduler ({exc})", key="--scheduler",
                                value=scheduler) from None
        used = len(client.scheduler_info()["workers"])
        scattered = client.scatter(data, broadcast=True)
        futures = {client.submit(run_batch, scattered, batches[i], analyse_only, pure=False,
                                 key=f"balancer-sweep-batch-{i}-{time.time_ns()}"): i
                   for i in todo}
        for future in as_completed(futures):
            record(futures[future], future.result(), client)
        return used
    except KeyboardInterrupt:
        # Whatever the closing meets (a scheduler gone too), the interrupt is what to report.
        with (interrupts.shielded(), _silenced("distributed", "tornado", "asyncio"),
              contextlib.suppress(Exception)):
            _close(client, cluster, list(futures))
        raise
    finally:
        with interrupts.shielded():
            _close(client, cluster, [])


def _close(client: Client | None, cluster: LocalCluster | None, futures: list[Any]) -> None:
    """Cancel ``futures`` and close the client and the cluster (each once)."""
    if client is not None and client.status not in ("closed", "closing"):
        if futures:
            client.cancel(futures)
        client.close()
    if cluster is not None and cluster.status.name not in ("closed", "closing"):
        cluster.close()


@contextlib.contextmanager
def _silenced(*names: str) -> Iterator[None]:
    """The loggers ``names`` and those under them silent (above CRITICAL) for the block."""
    import logging

    # Dask's logging config sets levels on children too (tornado.application: ERROR), which a
    # parent's level does not override: every logger under the names is silenced.
    existing = [name for name, lg in logging.root.manager.loggerDict.items()
                if isinstance(lg, logging.Logger)
                and any(name.startswith(f"{parent}.") for parent in names)]
    loggers = [logging.getLogger(name) for name in (*names, *existing)]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for lg, level in zip(loggers, levels, strict=True):
            lg.setLevel(level)


def _assemble(parts: Path, out: Path, keys: Sequence[str], points: int, batches: int) -> None:
    """The parts as one table, every point once and in order; then the parts removed."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    files = sorted(parts.glob("batch-*.parquet"))
    if len(files) != batches:
        raise OutputError(f"the sweep is incomplete: {len(files)} of {batches} batches in "
                          f"{parts}; --resume to finish it", key="--out", value=str(out))
    table = pa.concat_tables([pq.read_table(f, schema=_schema(keys)) for f in files])
    table = table.sort_by("point")
    index = table.column("point").to_pylist()
    if index != list(range(points)):
        raise OutputError(f"the parts in {parts} do not hold every point exactly once",
                          key="--out", value=str(out))

    write_with(out, lambda tmp: pq.write_table(table, tmp), suffix=".parquet")
    shutil.rmtree(parts)
