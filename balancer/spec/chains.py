"""The spec's tables of a chain of named links with named lengths.

The four-bar's and the slider-crank's ``[mechanism]`` (``branch``, ``[mechanism.lengths]``) and
``[links.<name>]``.

Each mechanism's own reader (``mechanisms/<name>/spec.py``) calls these with its class and adds
what is its alone (a slider's gas force).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from .. import tomltext as toml
from ..model import ChainModel, Link
from . import schema
from .links import links_lines, read_links
from .tables import Table


def read_chain(root: Table, mech: Table, cls: type[ChainModel], *,
               sliders: Sequence[str] = (),
               extra: Callable[[str, Table], None] | None = None) -> dict[str, Any]:
    """The fields of a chain mechanism's model.

    ``lengths`` and ``branch`` as written (the model checks them, and that it assembles) and
    each link.
    """
    mech.expect(schema.known("mechanism", cls.type))
    branch = mech.string("branch", choices=("+", "-"), default="+")
    lengths_table = mech.table("lengths")
    assert lengths_table is not None
    lengths_table.expect(schema.known("mechanism.lengths", cls.type))
    lengths: list[Any] = []
    for name in cls.length_names:
        if name == "offset":
            lengths.append(lengths_table.value(name, 0.0))
        elif not lengths_table.has(name):
            raise lengths_table._missing(name)
        else:
            lengths.append(lengths_table.raw(name))
    lengths_table.finish()
    mech.finish()
    links_table = root.table("links")
    assert links_table is not None
    links: dict[str, Link] = read_links(links_table, cls.chain_links, cls.type,
                                        sliders=sliders, extra=extra)
    return {"lengths": tuple(lengths), "branch": branch, **links}


def chain_lines(model: ChainModel, *, sliders: Sequence[str] = (),
                extra: Callable[[str], list[str]] | None = None) -> list[str]:
    """``[mechanism]`` and ``[links]`` of a chain mechanism, as :func:`read_chain` reads them."""
    out = ["[mechanism]", f'type = "{model.type}"', f'branch = "{model.branch}"', "",
           "[mechanism.lengths]  # m"]
    out += [f"{name} = {toml.number(length)}"
            for name, length in zip(model.length_names, model.lengths, strict=True)]
    return out + links_lines(model, "links", sliders=sliders, extra=extra)
