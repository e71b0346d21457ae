"""How the layers that print name a mechanism's figures: its wording, columns and outputs.

A mechanism gives the core what it computes (:class:`~balancer.mechanisms.base.Mechanism`)
and, apart from that, one :class:`Presentation`: what a report calls the source of its
force-balance conditions, whether a trajectory's states are keyed by link name, which ground
guides a table names as a force at a point, whether an analysis reports the torque on the
mounts, what a drawing calls its sliding blocks. The reports, plots, CSV columns and the
trajectory's JSON read it; the kinematics, dynamics and balancing never do.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Presentation:
    """A mechanism's wording and output choices.

    Attributes
    ----------
    force_balance_source
        Where its force-balance conditions come from, as a report's sentence names them
        ("… hold to 1e-16 of the links' first moments").
    named_states
        Whether ``simulate --json`` gives the link states keyed by link name (a general
        linkage) or as lists of links 1–3 (the four-bar and slider-crank, fixed by DESIGN.md).
    mount_torque
        Whether the cycle analysis gives the torque about z on the mounts (an engine's
        ``mount_torque``: the shaking moment plus the driving torque).
    balanced_on_shafts
        Whether balancing adds masses on shafts geared to the crank (an engine's counterweights
        and balance shafts) rather than bodies to its links, as an animation draws them.
    block_name
        What a drawing calls its sliding blocks.
    guide_force_names
        Sliders on ground guides whose force on the guide tables name as a force at a point
        (``R{name}x``, ``R{name}y``) rather than by its normal force ``N_{link}``.
    support_words, supports_key
        What a report calls the supports that share a ground point's reaction
        (:attr:`~balancer.mechanisms.base.Mechanism.supports`), and their JSON key.
    """

    force_balance_source: str = "the conditions found from the linkage"
    named_states: bool = True
    mount_torque: bool = False
    balanced_on_shafts: bool = False
    block_name: str = "sliding blocks"
    guide_force_names: Mapping[str, str] = field(default_factory=dict)
    support_words: str = "support"
    supports_key: str = "supports"
