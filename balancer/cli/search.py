"""``balancer search``: an engine's crank arrangements and firing orders, ranked."""

from __future__ import annotations

import argparse

from ..api.arrangements import search
from ..report import dumps_json
from ..report.arrangements import search_json, search_text
from .common import load


def run(args: argparse.Namespace) -> int:
    """Run ``balancer search``; the exit code."""
    design = load(args)
    found = search(design, top=args.top, balance=args.balance, step=args.step)
    print(dumps_json(search_json(found, spec=args.spec)) if args.json
          else search_text(found, design, spec=args.spec))
    return 0
