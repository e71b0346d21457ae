"""Shared fixtures: the paper's example linkage and random linkages of every Grashof type."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from hypothesis import settings

from balancer.mechanisms.fourbar.assembly import assembly_range
from balancer.mechanisms.fourbar.model import FourBar
from balancer.model import Link

# Property tests draw the same examples on every machine and run (reproducible, like the seeded
# random tests); HYPOTHESIS_PROFILE=explore draws new ones and keeps what fails (a fuzz campaign),
# HYPOTHESIS_EXAMPLES of them per test (default Hypothesis's 100).
settings.register_profile("reproducible", derandomize=True, database=None)
settings.register_profile("explore", max_examples=int(os.environ.get("HYPOTHESIS_EXAMPLES", 100)))
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "reproducible"))

#: Meijaard & van der Wijk (2020), Eq. 56.
PAPER_LENGTHS = (1.0, 3.0, 2.0, 3.2)


def paper_links(loads: bool = True) -> dict[str, Link]:
    def link(m, i, s, sigma, force, moment):
        base = Link(mass=m, inertia=i, e=0.0, f=0.0)
        base = base.with_com_polar(s, sigma)
        if loads:
            from dataclasses import replace

            base = replace(base, force=force, moment=moment)
        return base

    return {
        "crank": link(2.1, 1.1, 0.6, 0.3, (1.1, 1.2), 0.37),
        "coupler": link(3.0, 3.1, 1.45, 0.4, (1.3, -1.4), 0.28),
        "rocker": link(2.2, 2.1, 1.66, -0.4, (1.5, 1.6), 0.19),
    }


def paper_linkage(loads: bool = True) -> FourBar:
    return FourBar(lengths=PAPER_LENGTHS, branch="+", **paper_links(loads))


@pytest.fixture
def paper() -> FourBar:
    return paper_linkage()


def random_link(rng: np.random.Generator, length: float, *, loads: bool, rotor: bool) -> Link:
    m = rng.uniform(0.2, 5.0)
    e = rng.uniform(-0.5, 1.5) * length
    f = rng.uniform(-0.5, 0.5) * length
    inertia = m * (rng.uniform(0.05, 0.5) * length) ** 2
    return Link(
        mass=m,
        inertia=inertia,
        e=e,
        f=f,
        force=tuple(rng.uniform(-5, 5, 2)) if loads else (0.0, 0.0),
        moment=rng.uniform(-2, 2) if loads else 0.0,
        counter_rotor=rng.uniform(0, 2) if rotor else 0.0,
    )


def random_linkage(
    rng: np.random.Generator, *, loads: bool = True, rotors: bool = True, full_turn: bool = False
) -> FourBar:
    """A random four-bar that assembles (optionally one whose crank turns fully)."""
    while True:
        lengths = tuple(float(x) for x in rng.uniform(0.3, 3.0, 4))
        rng_ = assembly_range(lengths)
        if rng_.empty or (full_turn and not rng_.full):
            continue
        break
    l1, l2, l3, _ = lengths
    return FourBar(
        lengths=lengths,
        branch=str(rng.choice(["+", "-"])),
        crank=random_link(rng, l1, loads=loads, rotor=rotors),
        coupler=random_link(rng, l2, loads=loads, rotor=False),
        rocker=random_link(rng, l3, loads=loads, rotor=rotors),
    )


def random_angles(rng: np.random.Generator, linkage: FourBar, n: int, margin: float = 0.02):
    """``n`` crank angles inside the assembly range, away from its ends by ``margin`` rad."""
    rng_ = assembly_range(linkage.lengths)
    if rng_.full:
        return rng.uniform(-math.pi, math.pi, n)
    out = []
    widths = [b - a for a, b in rng_.intervals]
    while len(out) < n:
        k = rng.choice(len(widths), p=np.array(widths) / sum(widths))
        a, b = rng_.intervals[k]
        if b - a > 3 * margin:
            out.append(rng.uniform(a + margin, b - margin))
    return np.array(out)


#: Lengths of one linkage of each Grashof class (crank, coupler, rocker, frame).
CLASS_EXAMPLES = {
    "crank-rocker": (1.0, 3.0, 2.0, 3.2),
    "double-crank": (3.2, 2.0, 3.0, 1.0),
    "rocker-crank": (2.0, 3.2, 1.0, 3.0),
    "double-rocker": (3.0, 1.0, 3.2, 2.0),
    "triple-rocker": (2.0, 2.4, 1.5, 3.1),
    "change-point": (1.0, 2.0, 1.0, 2.0),
}

