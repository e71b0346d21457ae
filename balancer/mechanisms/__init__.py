"""The mechanism interface and its one registry (:func:`mechanism_of`).

See :mod:`.base` for the interface; :mod:`.general` (any linkage), :mod:`.fourbar` and
:mod:`.slidercrank` implement it.
"""

from __future__ import annotations

from functools import lru_cache

#: The mechanism classes by model type: (module, class).
REGISTRY: dict[str, tuple[str, str]] = {
    "four-bar": ("balancer.mechanisms.fourbar", "FourBarMechanism"),
    "slider-crank": ("balancer.mechanisms.slidercrank", "SliderCrankMechanism"),
    "linkage": ("balancer.mechanisms.general", "LinkageMechanism"),
}


def mechanism_of(model):
    """The :class:`~.base.Mechanism` of a model (a FourBar, SliderCrank or Linkage).

    Built once per model (models are frozen and hashable); a mechanism is returned as it is.

    Raises
    ------
    SpecError
        If the model is not a mechanism the package knows, or a general linkage is not a valid
        one (mobility, reference pose; see :class:`balancer.linkage.structure.Structure`).
    """
    from .base import Mechanism

    if isinstance(model, Mechanism):
        return model
    try:
        return _cached(model)
    except TypeError:  # unhashable: build it every time
        return _build(model)


#: Every formulation of the equations of motion of a registered mechanism (``--method``): the
#: registry's names, kept here so that the command line lists them without importing the
#: mechanisms (a test checks them against the mechanisms' own tables).
FORMULATION_NAMES: tuple[str, ...] = (
    "opened-loop", "complex-masses", "mass-matrix", "lie-group", "multibody", "crank-angle")


def formulation_names() -> tuple[str, ...]:
    """Every formulation of the equations of motion of any registered mechanism (``--method``)."""
    return FORMULATION_NAMES


@lru_cache(maxsize=64)
def _cached(model):
    return _build(model)


def _build(model):
    import importlib

    from ..errors import SpecError

    kind = getattr(model, "type", None)
    if kind not in REGISTRY:
        raise SpecError("must be a mechanism (a FourBar, SliderCrank or Linkage)",
                        key="mechanism", value=type(model).__name__)
    module, cls = REGISTRY[kind]
    mech = getattr(importlib.import_module(module), cls)(model)
    mech.structure  # noqa: B018 - build (and so check) the equations now
    return mech
