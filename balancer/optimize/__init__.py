"""Transitional: the optimisers moved to :mod:`balancer.balance`; this name goes with issue 12."""

import sys

from ..balance import convex, nlp, optimizer, result
from ..balance.optimizer import *  # noqa: F403
from ..balance.optimizer import Optimizer, optimize  # noqa: F401

for _name, _module in (("convex", convex), ("nlp", nlp), ("result", result)):
    sys.modules[f"{__name__}.{_name}"] = _module
del optimizer
