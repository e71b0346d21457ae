"""The general linkage as a :class:`~balancer.mechanisms.base.Mechanism`: the general core."""

from __future__ import annotations

from ...model import Linkage
from ..base import Mechanism


class LinkageMechanism(Mechanism):
    """Any planar linkage with one degree of freedom (``type = "linkage"``)."""

    model: Linkage



#: The class the registry builds for this folder (:data:`balancer.mechanisms.FOLDERS`).
MECHANISM = LinkageMechanism
