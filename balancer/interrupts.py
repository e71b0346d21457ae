"""Ctrl-C (SIGINT): an interrupted command ends with exit code 130, whenever the signal comes.

Python turns SIGINT into :class:`KeyboardInterrupt` in the main thread, but not always to the
end: a process started with SIGINT ignored (a command started in the background of a script
inherits that) never sees it, and a library may catch the exception where it is raised
(CasADi ends IPOPT's run with the status ``NonIpopt_Exception_Thrown`` and returns normally).
So the command line installs its own handler for the whole command (:func:`handling`): it
counts every SIGINT before it raises :class:`KeyboardInterrupt`, and :func:`received` then
tells whatever became of the exception. Around a call into a library that may catch it,
:func:`checked` raises it again after the call. :func:`shielded` holds the exception back while
a command cleans up after an interrupt (a Dask cluster shutting down), counting further
signals only; :func:`blocked` keeps SIGINT from the threads and processes started within it
(a local Dask cluster's workers, which the command stops itself).

Only the main thread handles signals; elsewhere every function here does nothing.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

#: SIGINTs counted since :func:`handling` began, and the depth of :func:`shielded` blocks.
_state = {"count": 0, "shield": 0}


def _handler(signum: int, frame: object) -> None:
    """Count the signal; raise :class:`KeyboardInterrupt` unless shielded."""
    _state["count"] += 1
    if not _state["shield"]:
        raise KeyboardInterrupt


def _in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextlib.contextmanager
def handling() -> Iterator[None]:
    """Handle SIGINT with the counting handler for the block (a command's whole run).

    It replaces whatever handler there was — also an inherited ``SIG_IGN``: a command asked to
    stop stops — and restores it at the end. Within the block the count starts from zero and
    nothing is shielded; after it, an enclosing block's shield is back and its count includes
    the block's.
    """
    if not _in_main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, _handler)
    saved = dict(_state)
    _state.update(count=0, shield=0)
    try:
        yield
    finally:
        # The enclosing state first: a signal in between is then the enclosing block's.
        _state.update(count=saved["count"] + _state["count"], shield=saved["shield"])
        signal.signal(signal.SIGINT, previous)


def received() -> bool:
    """Whether a SIGINT came since :func:`handling` began."""
    return _state["count"] > 0


@contextlib.contextmanager
def checked() -> Iterator[None]:
    """Raise :class:`KeyboardInterrupt` after the block if a SIGINT came during it.

    For a call into a library that catches the exception itself. Outside :func:`handling`,
    where Python's own handler is installed, the counting handler replaces it for the block;
    a handler of the caller's own (or ``SIG_IGN``) is left alone.
    """
    if not _in_main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGINT)
    ours = previous is signal.default_int_handler
    if ours:
        signal.signal(signal.SIGINT, _handler)
    before = _state["count"]
    try:
        yield
    finally:
        if ours:
            signal.signal(signal.SIGINT, previous)
    if _state["count"] != before and not _state["shield"]:
        raise KeyboardInterrupt


@contextlib.contextmanager
def shielded() -> Iterator[None]:
    """Count SIGINTs without raising :class:`KeyboardInterrupt` during the block.

    For the clean-up after an interrupt, which a second Ctrl-C must not cut short (it would
    leave a cluster's worker processes behind).
    """
    _state["shield"] += 1
    try:
        yield
    finally:
        _state["shield"] -= 1


@contextlib.contextmanager
def blocked() -> Iterator[None]:
    """Block SIGINT in this thread for the block.

    Threads and processes started within it inherit the mask, so that a Ctrl-C at the terminal
    (sent to the whole process group) never reaches them: a local Dask cluster's worker
    processes, which the command stops itself. A SIGINT sent meanwhile reaches this process
    when the block ends (or at once, through a thread started before it).
    """
    if not _in_main_thread() or not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def closing() -> bool:
    """Block SIGINT for the rest of the process; whether one came (counted, or pending).

    For the last moments of a command, after its result is out: a SIGINT then can no longer
    kill the interpreter as it shuts down (exit status −2 instead of 130), and one that came
    still decides the exit code.
    """
    if _in_main_thread() and hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        if signal.SIGINT in signal.sigpending():
            return True
    return received()
