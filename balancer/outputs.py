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


#: Figure formats by file extension (matplotlib's Agg, SVG and PDF backends).
FIGURE_TYPES: dict[str, str] = {".png": "png", ".svg": "svg", ".pdf": "pdf"}

#: Animation formats by file extension (GIF by Pillow, MP4 by ffmpeg: :func:`ffmpeg`).
ANIMATION_TYPES: dict[str, str] = {".gif": "gif", ".mp4": "mp4"}

def figure_type(path: str | os.PathLike[str], option: str | None = None,
                types: dict[str, str] = FIGURE_TYPES) -> str:
    """The file type that ``path``'s extension names, or :class:`OutputError` (exit 2)."""
    suffix = Path(path).suffix.lower()
    if suffix not in types:
        known = ", ".join(types)
        raise OutputError(f"the file type comes from the extension: use one of {known}",
                          key=option, value=str(path))
    return types[suffix]

def ffmpeg() -> str | None:
    """The ffmpeg program that writes MP4 animations, or ``None`` if there is none.

    matplotlib's ``animation.ffmpeg_path`` setting (``ffmpeg`` on ``PATH`` by default), else
    the one the ``imageio-ffmpeg`` package ships (``pip install 'balancer[video]'``).
    """
    import shutil

    import matplotlib

    found = shutil.which(matplotlib.rcParams["animation.ffmpeg_path"])
    if found:
        return found
    try:
        import imageio_ffmpeg
    except ImportError:
        return None
    try:
        return imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError:  # the package without its binary for this platform
        return None

def animation_type(path: str | os.PathLike[str], option: str | None = None) -> str:
    """The animation type that ``path``'s extension names, if it can be written here.

    Raises
    ------
    OutputError
        (exit 2) For an extension other than :data:`ANIMATION_TYPES`', or ``.mp4`` where there
        is no ffmpeg (:func:`ffmpeg`).
    """
    kind = figure_type(path, option, ANIMATION_TYPES)
    if kind == "mp4" and ffmpeg() is None:
        raise OutputError("an MP4 animation needs ffmpeg, which is not installed: install it "
                          "(or pip install 'balancer[video]'), or write a .gif", key=option,
                          value=str(path))
    return kind
