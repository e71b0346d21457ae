"""Each mechanism's reader and writer of its tables of a spec, found through the registry.

A mechanism's folder holds its ``spec`` module (:meth:`balancer.mechanisms.base.Mechanism.
spec_module`): the reader and writer of its ``[mechanism]`` and ``[links]`` tables (and those
it adds: an engine's ``[[balance_shafts]]``, ``[gas]``), of ``[original]`` and of
``[balance]``. The spec reader and writer (:mod:`.reader`, :mod:`.writer`) ask nothing else of
a mechanism: adding one is its folder and its line in :data:`balancer.mechanisms.REGISTRY`.
"""

from __future__ import annotations

import importlib
from typing import Protocol, cast

from ..errors import SpecError
from ..mechanisms import REGISTRY
from ..model import MechanismModel as Model
from ..model.balance import BalanceProblem, RotorBalanceProblem
from .tables import Table

#: The spec's mechanism types (``[mechanism] type``), in the registry's order.
MECHANISM_TYPES = tuple(REGISTRY)


class MechanismSpec(Protocol):
    """What a mechanism's ``spec`` module gives (module-level functions)."""

    def read(self, root: Table, mech: Table) -> Model:
        """The model of ``[mechanism]`` (``mech``) and the spec's other tables (``root``)."""
        ...

    def lines(self, model: Model) -> list[str]:
        """``[mechanism]``, ``[links]`` (and its own tables) as TOML lines that read back equal."""
        ...

    def read_original(self, table: Table, model: Model) -> Model:
        """``model`` with the links of ``[original]`` (``table``)."""
        ...

    def original_lines(self, model: Model) -> list[str]:
        """``model``'s links as ``[original]`` tables."""
        ...

    def read_balance(self, table: Table, model: Model) -> BalanceProblem | RotorBalanceProblem:
        """The redesign problem of ``[balance]`` (``table``) for ``model``."""
        ...

    def balance_lines(self, problem: object) -> list[str]:
        """The redesign problem as TOML lines that :meth:`read_balance` reads back equal."""
        ...


def spec_of(kind: str) -> MechanismSpec:
    """The ``spec`` module of mechanism type ``kind`` (a key of the registry).

    Raises
    ------
    SpecError
        If ``kind`` is not a mechanism the package knows.
    """
    if kind not in REGISTRY:
        raise SpecError(f"must be one of {', '.join(MECHANISM_TYPES)}", key="mechanism.type",
                        value=kind)
    return cast("MechanismSpec", importlib.import_module(REGISTRY[kind].spec_module()))


__all__ = ["MECHANISM_TYPES", "MechanismSpec", "spec_of"]
