"""A sweep's run: from the spec to the table, resumed where an interrupted run stopped.

:func:`sweep` checks the spec and the keys, cuts the points into batches, runs them in this
process or on Dask (:mod:`.cluster`), writes each as a part (:mod:`.tables`) and assembles the
table; :class:`SweepResult` is what it did, :class:`SweepInterrupted` what a Ctrl-C kept.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import interrupts
from ..errors import OutputError, SpecError
from ..mechanisms import mechanism_of
from ..model.balance import missing_balance
from ..spec import design_from_dict
from .cluster import batch_size, run_on_dask
from .keys import check_key, with_values
from .points import Perturb, Vary, design_points, perturbed_points
from .rows import run_batch
from .tables import (
    assemble,
    finished_batches,
    manifest_of,
    parts_dir,
    recorded_batch,
    write_part,
)

if TYPE_CHECKING:
    from distributed import Client


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
    """Run a sweep and write its table (see :mod:`balancer.sweeps`).

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
    parts = parts_dir(out)
    try:
        data = tomllib.loads(Path(spec).read_text(encoding="utf-8-sig"))
    except OSError as exc:
        raise SpecError(f"cannot read the spec ({exc.strerror})", value=str(spec)) from None
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"not valid TOML: {exc}", value=str(spec)) from None

    design = design_from_dict(data, source=str(spec))  # the spec itself must be valid
    several = len(mechanism_of(design.mechanism).linkage.inputs) > 1
    if not perturbs and design.balance is None:
        missing = missing_balance(design.mechanism)
        raise SpecError(f"{missing.detail}; a sweep balances each point as the spec's [balance] "
                        "asks (or give --perturb to analyse perturbed designs)",
                        key="balance", source=str(spec))
    if several and not design.motions:
        raise SpecError("a linkage with several inputs is swept along its motions: the spec "
                        "has no [[motion]]", key="motion", source=str(spec))
    if design.operation is None and not several:
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
        batch = (recorded_batch(parts) if resume else None) or batch_size(
            len(points), 0 if in_process else (workers or os.cpu_count() or 1))
    if batch < 1:
        raise SpecError("must be at least 1", key="--batch", value=batch)
    manifest = manifest_of(data, points, batch)
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
        done = finished_batches(parts)
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
        write_part(parts / f"batch-{i:06d}.parquet", rows, keys)
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
            used = run_on_dask(data, batches, todo, record, workers, scheduler, analyse_only)
    except KeyboardInterrupt:
        with interrupts.shielded():  # a second Ctrl-C must not leave the parts half told
            kept = sum(len(batches[i]) for i in finished_batches(parts))
            if not kept:
                shutil.rmtree(parts, ignore_errors=True)
        raise SweepInterrupted(kept, len(points), parts if kept else None) from None
    except BaseException:
        if finished == 0:  # nothing computed to keep (a scheduler out of reach, …)
            shutil.rmtree(parts, ignore_errors=True)
        raise
    assemble(parts, out, keys, len(points), len(batches))
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
