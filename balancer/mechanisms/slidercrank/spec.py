"""The slider-crank's tables of a spec.

``[mechanism]`` (branch, lengths with the guide's offset), its links' tables, and the slider's
gas force (``[links.slider] gas_force``).

Reached through the registry (:func:`balancer.mechanisms.folder_module`) by the
spec reader and writer (:mod:`balancer.spec`); ``[balance]`` is the linkages' own.
"""

from __future__ import annotations

import math

from ... import tomltext as toml
from ... import validate as v
from ...errors import SpecError
from ...model import GasForce
from ...model import MechanismModel as Model
from ...spec import schema
from ...spec.chains import chain_lines, read_chain
from ...spec.links import links_lines, read_links
from ...spec.tables import Table
from .model import SliderCrank

#: Its link that does not turn (centre of mass in global axes; it carries the gas force).
SLIDERS = ("slider",)


def _read_gas_force(table: Table) -> GasForce:
    """``gas_force = 1500.0`` or ``gas_force = {crank_angle = [...], force = [...], period}``."""
    key = table.key("gas_force")
    if not table.has("gas_force"):
        return GasForce()
    raw = table.raw("gas_force")
    if not isinstance(raw, dict):
        return GasForce.constant(v.number(raw, key))
    sub = Table(raw, key)
    sub.expect(schema.known("links.<link>.gas_force", schema.SLIDER_CRANK))
    for name in ("crank_angle", "force"):
        if not sub.has(name):
            raise sub._missing(name)
        if not isinstance(sub.data[name], list):
            raise SpecError("must be a non-empty list of numbers", key=sub.key(name),
                            value=sub.data[name])
    with v.under(key):
        gas = GasForce(angles=sub.raw("crank_angle"), values=sub.raw("force"),
                       period=sub.value("period", 2 * math.pi))
    sub.finish()
    return gas


def _gas_lines(gas: GasForce) -> list[str]:
    if gas.is_zero:
        return []
    if len(gas.values) == 1:
        return [f"gas_force = {toml.number(gas.values[0])}  # N along the guide"]
    angles = ", ".join(toml.number(a) for a in gas.angles)
    values = ", ".join(toml.number(v) for v in gas.values)
    return [f"gas_force = {{ crank_angle = [{angles}], force = [{values}], "
            f"period = {toml.number(gas.period)} }}  # rad, N"]


class _SliderGas:
    """Reads the slider's gas force as the links' tables are read (``extra`` of the readers)."""

    def __init__(self) -> None:
        self.gas = GasForce()

    def __call__(self, name: str, table: Table) -> None:
        if name in SLIDERS:
            self.gas = _read_gas_force(table)


def read(root: Table, mech: Table) -> SliderCrank:
    """The slider-crank of ``[mechanism]`` and ``[links]``, with its gas force."""
    gas = _SliderGas()
    fields = read_chain(root, mech, SliderCrank, sliders=SLIDERS, extra=gas)
    return SliderCrank(gas_force=gas.gas, **fields)


def lines(model: Model) -> list[str]:
    """Its ``[mechanism]`` and ``[links]`` tables, as :func:`read` reads them."""
    assert isinstance(model, SliderCrank)
    return chain_lines(model, sliders=SLIDERS,
                       extra=lambda name: _gas_lines(model.gas_force) if name in SLIDERS
                       else [])


def read_original(table: Table, model: Model) -> Model:
    """``[original]``: the same slider-crank with the links given there.

    A gas force written there is read and left: the mechanism's is ``[links.slider]``'s.
    """
    return model.with_links(read_links(table, model.link_names, SliderCrank.type,
                                       sliders=SLIDERS, extra=_SliderGas()))


def original_lines(model: Model) -> list[str]:
    """``[original.<link>]`` tables of ``model``."""
    return links_lines(model, "original", sliders=SLIDERS)


#: Its ``[balance]``: the linkages' own, read and written by this module (loaded only for a
#: spec that has the table).
BALANCE = "balancer.spec.balance"

__all__ = ["BALANCE", "lines", "original_lines", "read", "read_original"]
