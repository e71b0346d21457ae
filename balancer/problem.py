"""Transitional: the redesign problem moved to :mod:`balancer.balance.problem`."""

import sys

from .balance import problem as _problem

sys.modules[__name__] = _problem
