"""``balancer example``: the example specs shipped with the package."""

from __future__ import annotations

import argparse
import sys

from .. import examples
from ..errors import SpecError
from ..outputs import write_atomic
from .common import output_path, wrote


def run(args: argparse.Namespace) -> int:
    """Run ``balancer example``; the exit code."""
    if args.name is None:
        if args.out is not None:
            raise SpecError("give the NAME of the example to write", key="--out",
                            value=args.out)
        width = max(map(len, examples.names()))
        for name in examples.names():
            print(f"{name:<{width}}  {examples.title(name)}")
        return 0
    path = output_path(args, args.out, "--out")
    text = examples.text(args.name)
    if path is None:
        sys.stdout.write(text)
        return 0

    write_atomic(path, text)
    wrote(path)
    return 0
