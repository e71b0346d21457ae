"""The four-bar's tables of a spec: ``[mechanism]`` (branch, lengths) and its links' tables.

Reached through the registry (:func:`balancer.mechanisms.folder_module`) by the
spec reader and writer (:mod:`balancer.spec`); ``[balance]`` is the linkages' own.
"""

from __future__ import annotations

from ...model import MechanismModel as Model
from ...spec.chains import chain_lines, read_chain
from ...spec.links import links_lines, read_links
from ...spec.tables import Table
from .model import FourBar


def read(root: Table, mech: Table) -> FourBar:
    """The four-bar of ``[mechanism]`` and ``[links]``."""
    return FourBar(**read_chain(root, mech, FourBar))


def lines(model: Model) -> list[str]:
    """Its ``[mechanism]`` and ``[links]`` tables, as :func:`read` reads them."""
    assert isinstance(model, FourBar)
    return chain_lines(model)


def read_original(table: Table, model: Model) -> Model:
    """``[original]``: the same four-bar with the links given there."""
    return model.with_links(read_links(table, model.link_names, FourBar.type))


def original_lines(model: Model) -> list[str]:
    """``[original.<link>]`` tables of ``model``."""
    return links_lines(model, "original")


#: Its ``[balance]``: the linkages' own, read and written by this module (loaded only for a
#: spec that has the table).
BALANCE = "balancer.spec.balance"

__all__ = ["BALANCE", "lines", "original_lines", "read", "read_original"]
