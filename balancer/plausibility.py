"""Plausibility of a design's sizes and speed: a note for a designer who slipped a unit.

Nothing here is an error — a design may be huge or fast — but some numbers are almost always a
unit written wrong: a length of more than :data:`MAX_LENGTH` (millimetres written as metres),
or a point of the mechanism that would move faster than sound at the operating speed
(:data:`MAX_TIP_SPEED`: revolutions per minute written as radians per second, or millimetres
as metres). :func:`length_note` reads the spec as written, so that its note comes even when
the spec then fails to load (a linkage with one length in millimetres does not assemble);
:func:`speed_note` needs the loaded design's motion. Each returns one line naming the key, or
``None``; the command line prints it on stderr and its exit code does not change.
"""

from __future__ import annotations

import math
from typing import Any, TypeGuard

from . import validate as v
from .cycle import sample_angles
from .errors import BalancerError
from .linkage.vectors import V
from .mechanisms import mechanism_of
from .mechanisms.base import Mechanism
from .model import Design
from .model import MechanismModel as Model
from .rounding import speed_text

#: Longest length that is plausibly meant, m: no planar linkage this tool balances is longer.
MAX_LENGTH = 100.0
#: Fastest plausible speed of a point of the mechanism, m/s: the speed of sound in air.
MAX_TIP_SPEED = 340.0
#: Lengths named in a note at most (the rest are counted).
NAMED = 3


def _number(x: Any) -> TypeGuard[float]:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def _pair(x: Any) -> bool:
    return isinstance(x, list) and len(x) == 2 and all(map(_number, x))


def _lengths(data: dict[str, Any]) -> list[tuple[str, float, str]]:
    """The spec's lengths as written: ``(key, size in m, what the size is)``."""
    out: list[tuple[str, float, str]] = []
    mechanism = data.get("mechanism")
    mechanism = mechanism if isinstance(mechanism, dict) else {}
    for table, words in (("lengths", ""), ("points", "from the origin")):
        entries = mechanism.get(table)
        for name, value in (entries.items() if isinstance(entries, dict) else ()):
            key = f"mechanism.{table}.{name}"
            if _number(value):
                out.append((key, abs(value), f"{key} = {value:g} m"))
            elif _pair(value):
                size = math.hypot(*value)
                out.append((key, size, f"{key} = [{value[0]:g}, {value[1]:g}] m ({size:.4g} m "
                                       f"{words})"))
    links = data.get("links")
    for name, link in (links.items() if isinstance(links, dict) else ()):
        com = link.get("com") if isinstance(link, dict) else None
        if not isinstance(com, dict):
            continue
        key = f"links.{name}.com"
        if _pair(com.get("at")):  # a point, in global coordinates
            size = math.hypot(*com["at"])
            out.append((key, size, f"{key}.at ({size:.4g} m from the origin)"))
            continue
        parts: list[Any] = [com.get(k) for k in ("e", "f") if k in com] or [com.get("s")]
        if all(map(_number, parts)):
            size = math.hypot(*parts)
            out.append((key, size, f"{key} ({size:.4g} m from its link's first point)"))
    springs = data.get("springs")
    for i, spring in enumerate(springs if isinstance(springs, list) else ()):
        value = spring.get("free_length") if isinstance(spring, dict) else None
        if _number(value):
            key = f"{v.item('springs', i)}.free_length"
            out.append((key, abs(value), f"{key} = {value:g} m"))
    return out


def length_note(data: dict[str, Any]) -> str | None:
    """A note on the lengths longer than :data:`MAX_LENGTH` in a parsed spec, or ``None``.

    Parameters
    ----------
    data
        The spec as parsed from TOML, before it is validated: lengths (m), points (m), the
        links' centres of mass (m) and the springs' free lengths (m) as written.
    """
    long = [text for _, size, text in _lengths(data) if size > MAX_LENGTH]
    if not long:
        return None
    named = ", ".join(long[:NAMED]) + (f" and {len(long) - NAMED} more" if len(long) > NAMED
                                       else "")
    verb = "is" if len(long) == 1 else "are"
    return (f"{named} {verb} longer than {MAX_LENGTH:g} m: lengths are in metres (mm written "
            "as m?)")


def tip_speed(mechanism: Model | Mechanism, samples: int = 72) -> float | None:
    """The largest speed of a point or centre of mass with the crank at 1 rad/s, m/s.

    Over ``samples`` crank angles of a revolution, or of the ranges where the linkage
    assembles less a twentieth of each at either end (where the crank cannot drive it, the
    links' rates grow without bound): each point of each link and each link's centre of mass,
    as the motion moves it (a geared link's at its own speed about its own pivot); ``None``
    where its motion cannot be found.
    """
    import numpy as np

    try:
        mech = mechanism_of(mechanism)
        s = mech.structure
        reach = mech.assembly_range()
        angles = (sample_angles(samples) if reach.full else np.concatenate(
            [np.linspace(a + (b - a) / 20, b - (b - a) / 20, samples) for a, b in reach.intervals]))
        with np.errstate(all="ignore"):
            mo = mech.motion(angles, 1.0)
            speeds = []
            for k, body in enumerate(mech.linkage.moving):
                link = mech.linkage.link(body.name)
                for local in (*(s.local[(k, p)] for p in body.points), V(link.e, link.f)):
                    v = mo.point_velocity(k, local)
                    speeds.append(np.ravel(np.hypot(np.asarray(v.x, float),
                                                    np.asarray(v.y, float))))
            every = np.concatenate(speeds)
            fastest = float(np.max(every[np.isfinite(every)], initial=0.0))
    except (BalancerError, ValueError, KeyError, StopIteration, FloatingPointError):
        return None
    return fastest if math.isfinite(fastest) else None


def speed_note(design: Design) -> str | None:
    """A note if a point would move faster than :data:`MAX_TIP_SPEED`, or ``None``.

    The tip speed is ``|ω|·v``: ω the operating speed ``[operation] speed`` (rad/s), v the
    :func:`tip_speed` (m/s at 1 rad/s). ``None`` too for a design without an operating speed.
    """
    if design.operation is None:
        return None
    speed = abs(design.operation.speed)
    fastest = tip_speed(design.mechanism)
    if fastest is None or not speed * fastest > MAX_TIP_SPEED:
        return None
    return (f"operation.speed = {speed_text(design.operation.speed)} moves a point at "
            f"{speed * fastest:.4g} m/s, faster than sound "
            f"({MAX_TIP_SPEED:g} m/s): the speed is in rad/s (rpm written as rad/s?) and "
            "lengths in metres (mm written as m?)")
