"""A sweep's batches on Dask: a local cluster or a scheduler's, and a Ctrl-C that closes it.

The points are cut into batches (:func:`batch_size`: each task solves many points, and imports
and builds once per worker) that run on ``dask.distributed`` — a ``LocalCluster`` on this
machine's cores, or the scheduler at an address. The local cluster's worker processes never see
SIGINT (:func:`balancer.interrupts.blocked`): interrupted, :func:`run_on_dask` cancels their
tasks and closes the cluster itself, quietly. Dask is imported by the functions that use it.
"""

from __future__ import annotations

import contextlib
import math
import os
import time
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

from .. import interrupts
from ..errors import SpecError
from .rows import run_batch

if TYPE_CHECKING:
    from distributed import Client, LocalCluster

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


def run_on_dask(data: dict[str, Any], batches: list[list[tuple[int, dict[str, float]]]],
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
