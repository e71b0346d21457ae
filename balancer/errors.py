"""The package's own exceptions.

Every error a user can cause or meet is one of these. The command-line interface turns them into
a one-line message and an exit code (:attr:`BalancerError.exit_code`): 2 for bad input (the spec
or the arguments), 1 for a computation that fails (a solver, a simulation that locks). Tests match
on the class, never on a message string alone.
"""

from __future__ import annotations

from typing import Any


class BalancerError(Exception):
    """Base class of every error the package raises on purpose."""

    exit_code: int = 1


class SpecError(BalancerError, ValueError):
    """A design spec or an argument is wrong: missing, mistyped, out of range or contradictory.

    Parameters
    ----------
    message
        What is wrong, in one line.
    key
        The dotted spec key (``links.crank.mass``) or argument name (``--duration``) at fault.
    value
        The offending value, when there is one.
    source
        The file the spec came from, when there is one.
    """

    exit_code = 2

    def __init__(
        self,
        message: str,
        *,
        key: str | None = None,
        value: object = None,
        source: str | None = None,
    ) -> None:
        self.key = key
        self.value = value
        self.source = source
        self.detail = message
        super().__init__(self._compose())

    def _compose(self) -> str:
        where = []
        if self.source:
            where.append(str(self.source))
        if self.key:
            where.append(self.key)
        head = ": ".join(where)
        text = self.detail
        if self.key is not None and self.value is not None:
            text = f"{text} (got {_as_written(self.value)!r})"
        return f"{head}: {text}" if head else text

    def with_source(self, source: str) -> SpecError:
        """Return a copy of this error that names the file it came from."""
        return type(self)(self.detail, key=self.key, value=self.value, source=source)

    def under(self, prefix: str) -> SpecError:
        """Return a copy whose key is ``prefix.key`` (an object's field within a spec table)."""
        if not prefix:
            return self
        key = prefix if not self.key else (
            f"{prefix}{self.key}" if self.key.startswith("[") else f"{prefix}.{self.key}")
        return type(self)(self.detail, key=key, value=self.value, source=self.source)


class AssemblyError(SpecError):
    """A linkage cannot be assembled: at any crank angle, or at the one asked for.

    It is bad input (exit code 2) when the spec itself asks for an impossible linkage or crank
    angle; a motion that runs into a position where the linkage locks is a
    :class:`LockupError` instead.
    """


class OutputError(SpecError):
    """An output file that cannot be written, or would overwrite the input spec (exit code 2).

    The input spec is overwritten only with ``--force``.
    """


class SolverError(BalancerError):
    """A numerical solver failed or reported the problem infeasible (exit code 1)."""

    exit_code = 1


class LockupError(BalancerError):
    """A simulated motion reached a position where the linkage locks or branches (exit code 1).

    Attributes
    ----------
    time
        The time at which the event happened, s.
    theta1
        The crank angle there, rad.
    """

    exit_code = 1
    #: The trajectory up to the event (a :class:`balancer.simulation.Trajectory`, a layer
    #: above: so typed no closer), set by :func:`balancer.simulation.simulate`.
    partial: Any

    def __init__(self, message: str, *, time: float, theta1: float) -> None:
        self.time = time
        self.theta1 = theta1
        super().__init__(message)


def _as_written(value: object) -> object:
    """A value as a spec writes it: tuples (the model's arrays) as lists, TOML's arrays."""
    if isinstance(value, tuple):
        return [_as_written(v) for v in value]
    if isinstance(value, list):
        return [_as_written(v) for v in value]
    return value

