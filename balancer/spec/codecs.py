"""Each mechanism's reader and writer of its tables of a spec, found through the registry.

A mechanism's folder holds its ``spec`` module (:func:`balancer.mechanisms.folder_module`):
the reader and writer of its ``[mechanism]`` and ``[links]`` tables (and those it adds: an
engine's ``[[balance_shafts]]``, ``[gas]``) and of ``[original]``, and the name of the module
that reads and writes its ``[balance]`` (loaded only for a spec that has one). The spec reader
and writer (:mod:`.reader`, :mod:`.writer`) ask nothing else of a mechanism: adding one is its
folder and its line in :data:`balancer.mechanisms.FOLDERS`.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Protocol, cast

from ..mechanisms import MECHANISM_TYPES, folder_module
from ..model import MechanismModel as Model
from .tables import Table

if TYPE_CHECKING:
    from ..model.balance import BalanceProblem, RotorBalanceProblem


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

    #: The dotted name of the module that reads and writes its ``[balance]``
    #: (:class:`BalanceSpec`): the linkages' share :mod:`balancer.spec.balance`. Loaded only
    #: for a spec that has the table.
    BALANCE: str


class BalanceSpec(Protocol):
    """What the reader and writer of a mechanism's ``[balance]`` give (module-level functions)."""

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
    return cast("MechanismSpec", importlib.import_module(folder_module(kind, "spec")))


def balance_spec_of(kind: str) -> BalanceSpec:
    """The reader and writer of ``[balance]`` of mechanism type ``kind`` (its ``BALANCE``).

    Raises
    ------
    SpecError
        If ``kind`` is not a mechanism the package knows.
    """
    return cast("BalanceSpec", importlib.import_module(spec_of(kind).BALANCE))


__all__ = ["MECHANISM_TYPES", "BalanceSpec", "MechanismSpec", "balance_spec_of", "spec_of"]
