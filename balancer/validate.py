"""The one validation layer: checks that the spec loader and the model objects share.

Every value a user can give — in a TOML spec or to a model object built in a notebook — passes
through these functions, which raise :class:`~balancer.errors.SpecError` naming the key and the
value. The model objects call them in ``__post_init__`` with their field names as keys; the
spec loader builds the objects inside :func:`under`, which puts the table's path in front of the
key (``mass`` becomes ``links.crank.mass``), so that both say the same thing in the same words.

Two kinds of limit are not about one value alone:

- **Magnitudes** (:func:`check_magnitudes`): the figures the tool computes are products of
  masses, lengths and squared speeds (forces ``m·l·ω²``, moments ``m·l²·ω²``) and their mean
  squares. Those must stay within double precision, so every such scale must be below
  :data:`SCALE_LIMIT` (its square, summed over ten million samples, is still finite). Lengths
  must be between :data:`LENGTH_RANGE` (their fourth powers, which the loop closure forms, stay
  normal numbers) and none below :data:`RELATIVE_LENGTH` of the longest (its square would be
  lost to rounding beside the longest's).
- **Sizes** (:func:`require_memory`): a count that the user controls (samples of a revolution,
  output times) is bounded by the memory its arrays would take, against the memory the machine
  has available.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from .errors import SpecError

#: Largest magnitude of a force (N), moment (N·m) or energy (J) scale the tool computes with.
SCALE_LIMIT = 1e150
#: Range of a length, m (fourth powers within the normal doubles, with room for products).
LENGTH_RANGE = (1e-50, 1e50)
#: Least ratio of a length to the longest of the linkage: √ε of double precision.
RELATIVE_LENGTH = math.sqrt(2.220446049250313e-16)
#: Share of the available memory that one request may take.
MEMORY_SHARE = 0.5


def number(value: Any, key: str) -> float:
    """A finite real number (not a bool), as a float.

    Raises
    ------
    SpecError
        If it is not a number, or is NaN or infinite.
    """
    if type(value) is float and math.isfinite(value):  # (the common case, at once)
        return value
    if isinstance(value, bool) or not isinstance(value, int | float):
        try:
            import numpy as np  # numpy scalars from a notebook are numbers too

            if isinstance(value, np.floating | np.integer) and not isinstance(value, np.bool_):
                value = value.item()
            else:
                raise TypeError
        except (ImportError, TypeError):
            raise SpecError("must be a number", key=key, value=value) from None
    try:
        x = float(value)
    except OverflowError:
        raise SpecError("must be a finite number", key=key, value=value) from None
    if not math.isfinite(x):
        raise SpecError("must be a finite number", key=key, value=value)
    return x


def positive(value: Any, key: str) -> float:
    """A finite number greater than zero."""
    x = number(value, key)
    if not x > 0:
        raise SpecError("must be positive", key=key, value=value)
    return x


def nonnegative(value: Any, key: str) -> float:
    """A finite number, zero or greater."""
    x = number(value, key)
    if x < 0:
        raise SpecError("must be zero or positive", key=key, value=value)
    return x + 0.0  # −0.0 → 0.0


def nonzero(value: Any, key: str, why: str = "") -> float:
    """A finite number other than zero."""
    x = number(value, key)
    if x == 0:
        raise SpecError("must be non-zero" + (f" ({why})" if why else ""), key=key, value=value)
    return x


def ratio(value: Any, key: str) -> int:
    """A gear ratio: a non-zero whole number (given as an integer or a whole float)."""
    x = number(value, key)
    if x == 0 or x != round(x):
        raise SpecError("must be a non-zero whole number", key=key, value=value)
    return int(x)


def integer(value: Any, key: str, *, minimum: int, maximum: int | None = None) -> int:
    """A whole number (not a bool) within ``[minimum, maximum]``."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise SpecError("must be an integer", key=key, value=value)
    if value < minimum:
        raise SpecError(f"must be at least {minimum}", key=key, value=value)
    if maximum is not None and value > maximum:
        raise SpecError(f"must be at most {maximum}", key=key, value=value)
    return int(value)


def choice(value: Any, key: str, choices: tuple[str, ...]) -> str:
    """One of the strings ``choices``."""
    if not isinstance(value, str):
        raise SpecError("must be a string", key=key, value=value)
    if value not in choices:
        options = ", ".join(f'"{c}"' for c in choices)
        raise SpecError(f"must be one of {options}", key=key, value=value)
    return value


def vector2(value: Any, key: str) -> tuple[float, float]:
    """A pair of finite numbers ``(x, y)``."""
    if not isinstance(value, (list, tuple, np.ndarray)) or len(value) != 2:
        raise SpecError("must be a list of two numbers [x, y]", key=key, value=value)
    return (number(value[0], f"{key}[0]"), number(value[1], f"{key}[1]"))


def length(value: Any, key: str) -> float:
    """A length within :data:`LENGTH_RANGE`, m."""
    x = positive(value, key)
    lo, hi = LENGTH_RANGE
    if not lo <= x <= hi:
        raise SpecError(f"must be between {lo:g} m and {hi:g} m (its fourth power must stay "
                        "within double precision)", key=key, value=value)
    return x


def relative_lengths(lengths: dict[str, float], prefix: str) -> None:
    """No length below :data:`RELATIVE_LENGTH` of the longest (keys ``prefix.<name>``)."""
    longest = max(abs(v) for v in lengths.values())
    for name, value in lengths.items():
        if value != 0 and abs(value) < RELATIVE_LENGTH * longest:
            raise SpecError(
                f"is below {RELATIVE_LENGTH:.2g} of the longest length ({longest:.6g} m): "
                "its square is lost to rounding beside the longest's",
                key=f"{prefix}.{name}", value=value,
            )


def item(array: str, index: int) -> str:
    """The key of an item of a spec's array in a message, numbered from 1: ``array[n]``.

    ``index`` counts from 0 (Python's); the message counts as the docs do — cylinder 1 is
    ``mechanism.cylinders[1]``, the first spring ``springs[1]`` — so that a designer finds
    the item by counting the tables in the spec.
    """
    return f"{array}[{index + 1}]"


@contextmanager
def under(prefix: str) -> Iterator[None]:
    """Put ``prefix`` in front of the key of a :class:`SpecError` raised inside."""
    try:
        yield
    except SpecError as exc:
        raise exc.under(prefix) from None


def check_magnitudes(terms: list[list[tuple[str, float]]], what: str, unit: str) -> None:
    """Raise if a scale built from the inputs leaves double precision.

    Parameters
    ----------
    terms
        The contributions to one scale (a force, a moment, an energy), each the product of its
        factors ``(key, value)``, keyed by the input they come from (``m·ω²`` is
        ``[("links.crank.mass", 2.1), ("operation.speed", 10.0), ("operation.speed", 10.0)]``);
        SI units. Products are formed as sums of logarithms, so nothing overflows here.
    what, unit
        The scale's name and unit, for the message.

    Raises
    ------
    SpecError
        When the sum exceeds :data:`SCALE_LIMIT`: naming, in the largest contribution, the
        factor farthest from unity (the one that is absurd).
    """
    logs = []
    for factors in terms:
        values = [abs(value) for _, value in factors]
        if any(value == 0 for value in values):
            logs.append(-math.inf)
        else:
            logs.append(math.fsum(math.log10(value) for value in values))
    top = max(logs, default=-math.inf)
    if top == -math.inf:
        return
    total = math.fsum(10.0 ** (x - top) for x in logs)  # the sum, over 10**top
    order = top + math.log10(total)
    if order <= math.log10(SCALE_LIMIT):
        return
    key, value = max(terms[logs.index(top)], key=lambda kv: abs(math.log10(abs(kv[1]))))
    raise SpecError(
        f"makes {what} of order 1e{order:.0f} {unit}, beyond what double precision can "
        f"compute with (at most {SCALE_LIMIT:g} {unit})", key=key, value=value,
    )


#: How long an answer of :func:`available_memory` is kept, s: a sweep reads specs by the
#: thousand, and the machine's memory does not change between two of them.
MEMORY_READ_EVERY = 1.0
_MEMORY_READ: list[tuple[float, int]] = []


def available_memory() -> int:
    """Bytes of memory available to a new allocation on this machine (best estimate).

    Read again at most every :data:`MEMORY_READ_EVERY` seconds.
    """
    now = time.monotonic()
    if _MEMORY_READ and now - _MEMORY_READ[0][0] < MEMORY_READ_EVERY:
        return _MEMORY_READ[0][1]
    value = _read_available_memory()
    _MEMORY_READ[:] = [(now, value)]
    return value


def _read_available_memory() -> int:
    """:func:`available_memory`, read now."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return 8 * 2**30


def require_memory(count: int, bytes_each: float, key: str, what: str) -> None:
    """Raise if ``count`` items of ``bytes_each`` would take more than the memory to spare.

    The limit is :data:`MEMORY_SHARE` of :func:`available_memory`.

    Raises
    ------
    SpecError
        Naming ``key``, the value and the largest count this machine can take.
    """
    budget = MEMORY_SHARE * available_memory()
    need = count * bytes_each
    if need <= budget:
        return
    limit = int(budget // bytes_each)
    raise SpecError(
        f"{count} {what} would take about {_bytes(need)} of memory, more than the "
        f"{_bytes(budget)} this machine can spare (at most {limit} here)",
        key=key, value=count,
    )


def _bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if n < 1000 or unit == "PB":
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} PB"  # pragma: no cover


def store(obj: object, name: str, value: object) -> None:
    """Store a checked (normalised) value on a frozen dataclass."""
    object.__setattr__(obj, name, value)


def numbers(values: object, key: str) -> tuple[float, ...]:
    """A non-empty list of finite numbers, as floats; a :class:`SpecError` naming ``key``."""
    if isinstance(values, str | bytes) or not hasattr(values, "__iter__"):
        raise SpecError("must be a non-empty list of numbers", key=key, value=values)
    out = tuple(number(x, key) for x in values)
    if not out:
        raise SpecError("must be a non-empty list of numbers", key=key, value=list(values))
    return out
