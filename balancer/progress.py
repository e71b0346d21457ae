"""Progress of long work, for a person watching a terminal (tqdm, on stderr).

A :class:`Progress` is a callable ``progress(done, total)`` that the long computations accept
(:func:`balancer.simulation.simulate` with simulated seconds,
:func:`balancer.verification.verify` with the simulated seconds of all its runs). It draws a
bar only when its stream is a terminal and
the command was not asked for a machine-readable document (``--json``), and only once the work
has lasted :data:`DELAY` seconds: a quick command, a pipe, a log file or a JSON reader sees
nothing. tqdm is imported only when a bar is first drawn.
"""

from __future__ import annotations

import sys
from typing import IO, TYPE_CHECKING

if TYPE_CHECKING:
    from tqdm import tqdm

#: Seconds of work before a bar appears.
DELAY = 1.0


def is_terminal(stream: IO[str] | None) -> bool:
    """Whether ``stream`` is an interactive terminal (a closed or odd stream is not)."""
    try:
        return bool(stream is not None and stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


class Progress:
    """A progress bar on a terminal, or nothing.

    Parameters
    ----------
    label
        What is being done (``"simulating"``), printed before the bar.
    unit
        Unit of ``done`` and ``total`` (``"s"`` of simulated time).
    enabled
        ``False`` for a command that prints JSON: no bar whatever the stream.
    stream
        Where the bar goes (default ``sys.stderr``); it must be a terminal.
    delay
        Seconds from the first report before the bar appears (default :data:`DELAY`).
    refresh
        Least seconds between two redraws.

    Use it as a context manager (the bar is cleared at the end), calling it as
    ``progress(done, total)``; :attr:`active` says whether a bar may be drawn at all.
    """

    def __init__(self, label: str, *, unit: str = "s", enabled: bool = True,
                 stream: IO[str] | None = None, delay: float | None = None,
                 refresh: float = 0.1) -> None:
        self.label = label
        self.unit = unit
        self.stream = sys.stderr if stream is None else stream
        self.delay = DELAY if delay is None else delay
        self.refresh = refresh
        self.active = enabled and is_terminal(self.stream)
        self._bar: tqdm | None = None

    def __call__(self, done: float, total: float) -> None:
        """Report ``done`` of ``total`` (in :attr:`unit`)."""
        if not self.active:
            return
        if self._bar is None:
            from tqdm import tqdm

            self._bar = tqdm(
                total=total, initial=done, file=self.stream, desc=self.label,
                delay=self.delay, mininterval=self.refresh, leave=False, disable=False,
                ncols=80,
                bar_format=("{desc}: {percentage:5.1f} %|{bar}| {n:.4g} of {total:.4g} "
                            f"{self.unit} " "[{elapsed}<{remaining}]"))
        bar = self._bar
        if total != bar.total:
            bar.total = total
        bar.update(done - bar.n)

    def close(self) -> None:
        """Clear the bar, if one was drawn."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
