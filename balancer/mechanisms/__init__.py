"""The mechanism interface and its one registry (:func:`mechanism_of`).

See :mod:`.base` for the interface; :mod:`.general` (any linkage), :mod:`.fourbar` and
:mod:`.slidercrank` implement it.
"""

from __future__ import annotations

from functools import lru_cache

from ..errors import SpecError
from ..model import Linkage
from ..model import MechanismModel as Model
from .base import Mechanism
from .engine.mechanism import EngineMechanism
from .engine.model import Engine
from .fourbar.mechanism import FourBarMechanism
from .fourbar.model import FourBar
from .general.mechanism import LinkageMechanism
from .slidercrank.mechanism import SliderCrankMechanism
from .slidercrank.model import SliderCrank

#: The mechanism classes by the spec's ``mechanism.type``.
REGISTRY: dict[str, type[Mechanism]] = {
    FourBar.type: FourBarMechanism,
    SliderCrank.type: SliderCrankMechanism,
    Linkage.type: LinkageMechanism,
    Engine.type: EngineMechanism,
}


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
    if kind not in REGISTRY:
        hint = ": a Design's is its .mechanism" if hasattr(model, "mechanism") else ""
        raise SpecError(f"must be a mechanism model (a FourBar, SliderCrank, Linkage or "
                        f"Engine{hint})", key="mechanism", value=type(model).__name__)
    mech = REGISTRY[kind](model)
    mech.structure  # noqa: B018 - build (and so check) the equations now
    return mech
