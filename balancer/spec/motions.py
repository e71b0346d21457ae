"""The spec's motions read: ``[workspace]``, ``[[motion]]`` (and their CSV files), ``[plan]``.

Loaded by :func:`balancer.spec.reader.design_from_dict` where a spec has one of those tables, so
that reading a spec without them does not load the motions' model.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

from .. import validate as v
from ..errors import SpecError
from ..model.motions import REVOLUTION, InputRange, MotionSpec, Workspace
from ..model.plan import InputLimits, PlanSpec, PlanWeights
from . import schema
from .tables import Table


def read_workspace(root: Table) -> Workspace | None:
    """``[workspace]``: each input's range about the reference pose, joints' ranges, samples."""
    table = root.table("workspace", required=False)
    if table is None:
        return None
    table.known = tuple(table.data)
    joints: list[InputRange] = []
    sub = table.table("joints", required=False)
    if sub is not None:
        sub.known = tuple(sub.data)
        joints = [_input_range(sub, name) for name in sub.data]
        sub.finish()
    ranges = [_input_range(table, name) for name in table.data
              if name not in ("samples", "joints")]
    with v.under("workspace"):
        workspace = Workspace(ranges=tuple(ranges), joints=tuple(joints),
                              samples=table.value("samples", 40))
    table.finish()
    return workspace


def _input_range(table: Table, name: str) -> InputRange:
    raw = table.raw(name)
    if isinstance(raw, str | bytes) or not hasattr(raw, "__len__") or len(raw) != 2:
        raise SpecError("must be [low, high], two numbers", key=table.key(name), value=raw)
    low, high = (v.number(x, table.key(name)) for x in raw)
    return InputRange(name=name, low=low, high=high)


def read_plan(root: Table) -> PlanSpec | None:
    """``[plan]`` and its ``[plan.objective]``, or ``None`` where the spec has none."""
    table = root.table("plan", required=False)
    if table is None:
        return None
    terms = [k.name for k in _section("plan.objective").keys]
    sub = table.table("objective", required=False)
    weights = {name: 1.0 if name == "shaking_moment" else 0.0 for name in terms}
    if sub is not None:
        weights = {name: sub.value(name, weights[name]) for name in terms}
    with v.under("plan.objective"):
        objective = PlanWeights(**weights)
    if sub is not None:
        sub.finish()
    limits = {k.name: _input_limits(table, k.name) for k in _section("plan").keys
              if k.name.startswith("max_")}
    with v.under("plan"):
        plan = PlanSpec(motion=table.value("motion", None), name=table.value("name", None),
                        duration=table.value("duration", None),
                        measure=table.value("measure", "rms"), objective=objective,
                        intervals=table.value("intervals", None), **limits)
    table.finish()
    return plan


def _section(path: str) -> schema.Section:
    """The schema's section of a table the reader reads."""
    found = schema.section(path)
    assert found is not None, path
    return found


def _input_limits(table: Table, key: str) -> InputLimits:
    """A limit of ``[plan]``: one number for every input, or a table of numbers by input."""
    if not table.has(key):
        return InputLimits()
    raw = table.raw(key)
    if isinstance(raw, dict):
        sub = table.table(key)
        sub.known = tuple(sub.data)
        each = tuple((name, v.positive(sub.raw(name), sub.key(name))) for name in sub.data)
        sub.finish()
        return InputLimits(each=each)
    return InputLimits(every=v.positive(raw, table.key(key)))


def read_motions(root: Table, inputs: tuple[str, ...], folder: Path,
                  speed: float | None) -> tuple[MotionSpec, ...]:
    """Each ``[[motion]]``: its waypoints (or CSV file) and time law, or a planned pace.

    A planned motion runs along another motion or the revolution (``speed``, rad/s, the
    operating speed's).
    """
    out: list[MotionSpec] = []
    planned: list[tuple[int, Table]] = []
    for table in root.tables("motion"):
        if not table.has("name"):
            raise table._missing("name")
        if table.has("along") or table.has("pace"):
            planned.append((len(out), table))  # (its path is another's: read below)
            continue
        if table.has("file"):
            for name in ("times", "path"):
                if table.has(name):
                    raise SpecError("a motion read from a file takes its times and path from "
                                    "it", key=table.key(name), value=table.raw(name))
            point = table.value("point", None)
            columns = ("x", "y") if isinstance(point, str) else inputs
            times, path = _motion_file(table, columns, folder)
        else:
            for name in ("times", "path"):
                if not table.has(name):
                    raise table._missing(name)
            times, path = table.raw("times"), table.raw("path")
            point = table.value("point", None)
        if point is not None and not isinstance(point, str):
            raise SpecError("must be the name of a point", key=table.key("point"), value=point)
        name = table.text("name", default="")  # (its error names its own full key)
        law = table.value("law", "spline" if table.has("file") else "cubic")
        with v.under(table.path):
            out.append(MotionSpec(
                name=name, times=times, path=path, point=point, law=law,
                acc_time=table.value("acc_time", None), samples=table.value("samples", 400)))
        table.finish()
    for at, table in reversed(planned):
        out.insert(at, _planned_motion(table, out, inputs, speed))
    return tuple(out)


def _planned_motion(table: Table, motions: list[MotionSpec], inputs: tuple[str, ...],
                    speed: float | None) -> MotionSpec:
    """A planned motion: another motion's path (``along``) run at a ``pace``."""
    for name in ("along", "pace"):
        if not table.has(name):
            raise table._missing(name)
    for name in ("times", "path", "point", "file", "law", "acc_time"):
        if table.has(name):
            raise SpecError("a planned motion runs the path of the motion it is along",
                            key=table.key(name), value=table.raw(name))
    along = table.raw("along")
    name = table.text("name", default="")
    samples = table.value("samples", 400)
    if along == REVOLUTION:
        if len(inputs) != 1 or speed is None:
            raise SpecError("a revolution is a one-input linkage's, at its [operation] speed",
                            key=table.key("along"), value=along)
        period = 2.0 * math.pi / abs(speed)
        with v.under(table.path):
            motion = MotionSpec(name=name, times=(0.0, period),
                                path=((0.0,), (math.copysign(2.0 * math.pi, speed),)),
                                law="spline", samples=samples, along=REVOLUTION,
                                pace=table.raw("pace"))
    else:
        path = next((m for m in motions if m.name == along), None)
        if path is None:
            known = ", ".join([m.name for m in motions] + ([REVOLUTION] if len(inputs) == 1
                                                          else []))
            raise SpecError(f"must name a motion of the spec with a path of its own ({known})",
                            key=table.key("along"), value=along)
        with v.under(table.path):
            motion = MotionSpec(name=name, times=path.times, path=path.path, point=path.point,
                                law=path.law, acc_time=path.acc_time, samples=samples,
                                along=along, pace=table.raw("pace"))
    table.finish()
    return motion


def _motion_file(table: Table, inputs: tuple[str, ...], folder: Path
                 ) -> tuple[tuple[float, ...], tuple[tuple[float, ...], ...]]:
    """A motion's times and path from its CSV ``file``.

    Its header ``t`` and ``inputs``: the linkage's inputs (their changes from the reference
    pose), or ``x,y`` for a point's path (m).
    """
    key = table.key("file")
    name = table.raw("file")
    if not isinstance(name, str) or not name:
        raise SpecError("must be the path of a CSV file", key=key, value=name)
    path = Path(name) if Path(name).is_absolute() else folder / name
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(f"cannot be read ({exc.__class__.__name__}: "
                        f"{getattr(exc, 'strerror', None) or exc})", key=key, value=name) from None
    try:
        rows = [r for r in csv.reader(io.StringIO(text)) if any(c.strip() for c in r)]
    except csv.Error as exc:
        raise SpecError(f"is not a CSV table ({exc})", key=key, value=name) from None
    header = [c.strip() for c in rows[0]] if rows else []
    if header != ["t", *inputs]:
        what = ("the time, then the point's x and y" if inputs == ("x", "y")
                else "the time, then each input in the linkage's order")
        raise SpecError(f"its header must be t,{','.join(inputs)} ({what}); it is "
                        f"{','.join(header) or 'empty'}", key=key, value=name)
    times: list[float] = []
    values: list[tuple[float, ...]] = []
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise SpecError(f"line {line} has {len(row)} values, not {len(header)}", key=key,
                            value=name)
        try:
            numbers = [float(c) for c in row]
        except ValueError:
            raise SpecError(f"line {line} is not numbers: {','.join(row)}", key=key,
                            value=name) from None
        if not all(math.isfinite(x) for x in numbers):
            raise SpecError(f"line {line} is not finite: {','.join(row)}", key=key, value=name)
        if times and not numbers[0] > times[-1]:
            raise SpecError(f"line {line}'s time {numbers[0]:g} s does not increase",
                            key=key, value=name)
        times.append(numbers[0])
        values.append(tuple(numbers[1:]))
    return tuple(times), tuple(values)


