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
as ``optimize`` balances it (:mod:`balancer.balance.sites`); its keys — a crank radius
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

=============  ===================================================================================
``points``     the varied keys on a grid or sampled (:class:`Vary`), or perturbed (:class:`Perturb`)
``keys``       dotted spec keys: the number a key names, a spec with keys set, a key's unit
``rows``       a point's row: the design analysed and balanced; a batch of rows, one task
``tables``     the Parquet parts, their manifest, the table assembled from them; reading it back
``cluster``    the batches on Dask, and a Ctrl-C that closes the cluster
``run``        :func:`sweep`: from the spec to the table, resumed where an interrupted run stopped
=============  ===================================================================================
"""

from __future__ import annotations

from .cluster import BATCH, batch_size
from .keys import KEY_UNITS, check_key, key_unit, number_keys, spec_values, with_values
from .points import MAX_POINTS, METHODS, Perturb, Vary, design_points, perturbed_points
from .rows import COLUMNS, analyse_point, evaluate_point, run_batch
from .run import SweepInterrupted, SweepResult, sweep
from .tables import atlas_figure, read_table

__all__ = [
    "BATCH",
    "COLUMNS",
    "KEY_UNITS",
    "MAX_POINTS",
    "METHODS",
    "Perturb",
    "SweepInterrupted",
    "SweepResult",
    "Vary",
    "analyse_point",
    "atlas_figure",
    "batch_size",
    "check_key",
    "design_points",
    "evaluate_point",
    "key_unit",
    "number_keys",
    "perturbed_points",
    "read_table",
    "run_batch",
    "spec_values",
    "sweep",
    "with_values",
]
