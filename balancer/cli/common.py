"""What every verb of the command line shares: output paths checked first, the spec loaded."""

from __future__ import annotations

import argparse
import os
import sys
import tomllib
from pathlib import Path
from typing import overload

from ..errors import OutputError, SpecError
from ..model import Design
from ..outputs import check_writable, figure_type
from ..plausibility import length_note, speed_note
from ..spec import load_design


@overload
def output_path(args: argparse.Namespace, value: str, option: str) -> Path: ...
@overload
def output_path(args: argparse.Namespace, value: str | None, option: str) -> Path | None: ...


def output_path(args: argparse.Namespace, value: str | None, option: str) -> Path | None:
    """An output path given as ``option``, checked before any work is done.

    Its folder must exist and take a file; it must not name an existing file (the input spec
    included) unless ``--force``.
    """
    if value is None:
        return None

    path = check_writable(value, option)
    if args.force:
        return path
    spec = Path(getattr(args, "spec", None) or os.devnull)
    same = path.exists() and spec.exists() and os.path.samefile(path, spec)
    if spec.name != os.devnull and (same or os.path.realpath(path) == os.path.realpath(spec)):
        raise OutputError("would overwrite the input spec; give another path, or --force",
                          key=option, value=value)
    if os.path.lexists(path):
        raise OutputError("the file exists; give another path, or --force to overwrite it",
                          key=option, value=value)
    return path


def figure_path(args: argparse.Namespace, value: str | None, option: str) -> Path | None:
    """An output path for a figure, checked before any work.

    It must be writable (:func:`output_path`), and its extension must name a figure type
    (:func:`balancer.outputs.figure_type`).
    """
    path = output_path(args, value, option)
    if path is not None:
        figure_type(path, option)
    return path


def as_option(exc: SpecError, key: str, option: str, value: object) -> SpecError:
    """``exc`` naming the command-line ``option`` that gave the spec ``key`` its ``value``."""
    if exc.key == key and value is not None:
        return SpecError(exc.detail, key=option, value=value)
    return exc


def load(args: argparse.Namespace) -> Design:
    """The design of ``args.spec``, with a note on stderr for a unit that looks wrong.

    The lengths as written are judged before the spec is validated (a linkage with a length in
    millimetres may not assemble: the note then comes before the error), the speed of its
    points after (:mod:`balancer.plausibility`). A note never changes the exit code.
    """
    try:
        note = length_note(tomllib.loads(Path(args.spec).read_text(encoding="utf-8-sig")))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        note = None  # load_design says what is wrong with the file
    if note is not None:
        print(f"balancer: note: {note}", file=sys.stderr)
    design = load_design(args.spec)
    if note is None:  # lengths in millimetres make every point fast: one note is enough
        note = speed_note(design)
        if note is not None:
            print(f"balancer: note: {note}", file=sys.stderr)
    return design


def wrote(path: str | os.PathLike[str]) -> None:
    """Say on stderr that ``path`` was written: stdout is the report (or the JSON document)."""
    print(f"wrote {path}", file=sys.stderr)


#: Simulation settings that a command-line option overrides (errors then name the option).
SIMULATE_OPTIONS = ("method", "drive", "duration", "rtol", "atol", "outputs")
