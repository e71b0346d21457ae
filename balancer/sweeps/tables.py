"""A sweep's Parquet table: its parts and manifest, their assembly, and reading it back.

Each finished batch is written at once, atomically, as its own part in ``<out>.parts/`` beside a
manifest of the sweep (a digest of its spec, points and batch size): an interrupted sweep
resumes from the parts it finished, and only the same sweep may (:func:`manifest_of`). Once all
are there, :func:`assemble` writes the table, every point exactly once and in order (checked),
and removes the parts.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import OutputError
from ..outputs import write_with
from ..plots import sweep_figure
from .keys import key_unit
from .points import Perturb
from .rows import COLUMNS

if TYPE_CHECKING:
    import pyarrow as pa
    from matplotlib.figure import Figure


def parts_dir(out: Path) -> Path:
    """The folder of the parts of the sweep whose table is ``out``: ``<out>.parts``."""
    return out.with_name(out.name + ".parts")


def manifest_of(data: dict[str, Any], points: list[dict[str, float]], batch: int
                ) -> dict[str, Any]:
    """What a resumed sweep must share with the interrupted one: its spec, points and batch."""
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


def write_part(path: Path, rows: list[dict[str, Any]], keys: Sequence[str]) -> None:
    """A batch's rows as a Parquet file, written whole or not at all."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pylist(rows, schema=_schema(keys))
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)


def recorded_batch(parts: Path) -> int | None:
    """The points per task of the interrupted sweep in ``parts``, if it says."""
    try:
        value = json.loads((parts / "manifest.json").read_text()).get("batch")
    except (OSError, ValueError, AttributeError):
        return None
    return value if isinstance(value, int) and value >= 1 else None


def finished_batches(parts: Path) -> set[int]:
    """The batches whose parts are written in ``parts``."""
    return {int(p.stem.split("-")[1]) for p in parts.glob("batch-*.parquet")}


def assemble(parts: Path, out: Path, keys: Sequence[str], points: int, batches: int) -> None:
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
