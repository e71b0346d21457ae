"""The mechanism interface and its one registry (:func:`mechanism_of`).

See :mod:`.base` for the interface; :mod:`.general` (any linkage), :mod:`.fourbar`,
:mod:`.slidercrank` and :mod:`.engine` implement it. Each mechanism is a folder of this
package, loaded when a spec or a model names its type (:data:`FOLDERS`): analysing a four-bar
does not load the engine. A folder's ``mechanism`` module names its class ``MECHANISM``; its
``spec`` module reads and writes its tables of a spec (:mod:`balancer.spec.codecs`).
"""

from __future__ import annotations

import importlib
from functools import lru_cache

from ..errors import SpecError
from ..model import MechanismModel as Model
from .base import Mechanism

#: The folder of each mechanism by the spec's ``mechanism.type``; adding a mechanism is its
#: folder and its line here.
FOLDERS: dict[str, str] = {
    "four-bar": "fourbar",
    "slider-crank": "slidercrank",
    "linkage": "general",
    "engine": "engine",
}
#: The spec's mechanism types, in the registry's order.
MECHANISM_TYPES = tuple(FOLDERS)


def folder_module(kind: str, module: str) -> str:
    """The dotted name of ``module`` in the folder of mechanism type ``kind``.

    Raises
    ------
    SpecError
        If ``kind`` is not a mechanism the package knows.
    """
    if kind not in FOLDERS:
        raise SpecError(f"must be one of {', '.join(MECHANISM_TYPES)}", key="mechanism.type",
                        value=kind)
    return f"{__name__}.{FOLDERS[kind]}.{module}"


def mechanism_class(kind: str) -> type[Mechanism]:
    """The :class:`~.base.Mechanism` class of mechanism type ``kind``, its folder loaded.

    Raises
    ------
    SpecError
        If ``kind`` is not a mechanism the package knows.
    """
    cls: type[Mechanism] = importlib.import_module(folder_module(kind, "mechanism")).MECHANISM
    return cls


def mechanism_of(model: Model | Mechanism) -> Mechanism:
    """The :class:`~.base.Mechanism` of a model (a FourBar, SliderCrank, Linkage or Engine).

    Built once per model (models are frozen and hashable); a mechanism is returned as it is.

    Raises
    ------
    SpecError
        If the model is not a mechanism the package knows, or a general linkage is not a valid
        one (mobility, reference pose; see :class:`balancer.linkage.structure.Structure`).
    """
    if isinstance(model, Mechanism):
        return model
    try:
        return _cached(model)
    except TypeError:  # unhashable: build it every time
        return _build(model)


@lru_cache(maxsize=64)
def _cached(model: Model) -> Mechanism:
    return _build(model)


def _build(model: Model) -> Mechanism:
    kind = getattr(model, "type", None)
    if not isinstance(kind, str) or kind not in FOLDERS:
        hint = ": a Design's is its .mechanism" if hasattr(model, "mechanism") else ""
        raise SpecError(f"must be a mechanism model (a FourBar, SliderCrank, Linkage or "
                        f"Engine{hint})", key="mechanism", value=type(model).__name__)
    mech = mechanism_class(kind)(model)
    mech.structure  # noqa: B018 - build (and so check) the equations now
    return mech
