"""Files the tool writes: whole or not at all, and a failure that names the path.

Every file (a spec, a CSV, a figure, an animation) is written to a temporary file in the target's
folder and renamed into place (:func:`write_atomic`, :func:`write_with`): a reader never sees a
half-written file, and an error leaves the old file, if any, as it was. A file that cannot be
written raises :class:`~balancer.errors.OutputError` (exit code 2) naming the path and the
reason. :func:`check_writable` lets a command find a bad output path before it computes.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from .errors import OutputError


def _folder(target: Path) -> Path:
    return target.parent if str(target.parent) else Path(".")


def _reason(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def check_writable(path: str | os.PathLike[str], option: str | None = None) -> Path:
    """The output path, if a file can be written there; else :class:`OutputError`.

    The folder must exist and take a new file (probed by creating and removing one, which is
    what counts: permissions, read-only file systems, quotas); the path must not be a folder.
    """
    target = Path(path)
    if not str(path):
        raise OutputError("an output path must not be empty", key=option, value=str(path))
    folder = _folder(target)
    if not folder.is_dir():
        raise OutputError("the folder to write into does not exist", key=option,
                          value=str(path))
    if target.is_dir():
        raise OutputError("is a folder, not a file", key=option, value=str(path))
    import tempfile  # here: a command that writes nothing does not load it

    try:
        fd, probe = tempfile.mkstemp(prefix=f".{target.name}.", dir=folder)
    except OSError as exc:
        raise OutputError(f"cannot write into {folder} ({_reason(exc)})", key=option,
                          value=str(path)) from None
    os.close(fd)
    os.unlink(probe)
    return target


def write_with(path: str | os.PathLike[str], writer: Callable[[str], None],
               suffix: str = "") -> Path:
    """Let ``writer(temporary_path)`` write the file, then move it to ``path``.

    The temporary file is in the same folder (so the rename is atomic) and gets the usual
    permissions (the umask's), not :func:`tempfile.mkstemp`'s private ones.

    Raises
    ------
    OutputError
        If the file cannot be written (naming the path and the reason).
    """
    import tempfile

    target = Path(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix,
                                   dir=_folder(target))
    except OSError as exc:
        raise OutputError(f"cannot write the file ({_reason(exc)})", source=str(target)) from None
    os.close(fd)
    try:
        writer(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, target)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise OutputError(f"cannot write the file ({_reason(exc)})", source=str(target)) from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return target


def write_atomic(path: str | os.PathLike[str], data: str | bytes) -> Path:
    """Write text (UTF-8) or bytes to ``path``, whole or not at all (see :func:`write_with`)."""
    payload = data.encode("utf-8") if isinstance(data, str) else data

    def write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            fh.write(payload)

    return write_with(path, write)
