"""Seeded random design specs of general planar linkages (``type = "linkage"``) for fuzzing.

Everything is a pure function of ``(seed, index)``: :func:`make_case` returns one
:class:`LinkageCase` — the spec's TOML bytes, what the input alone implies (``expect``) and,
for bad input, the spec keys one of which the one-line error must name.

Valid specs are built from a *construction*: the points as functions of the crank angle,
solved dyad by dyad in closed form (RRR circles, RRP circle and line, RPR a line through a
point) or by a rigid offset on a link. The construction is sampled over a full turn,
independently of the tool, to classify the linkage:

``valid``
    assembles at every crank angle with transmission quality (the sine of the transmission
    angle of every dyad) above :data:`GOOD`, so the crank turns fully and never nears a dead
    point; the reference pose is regular.
``no-full-turn``
    regular at the reference pose but some crank angle does not assemble: the crank cannot
    turn a full revolution (cycle analysis, balancing and verify are bad input, exit 2).
``edge``
    anything in between (near-singular poses, absurd scales): any of 0, 1, 2 is acceptable,
    only defects of form (tracebacks, NaN in output, hangs) count.
``error``
    a hostile mutation of a valid spec: exit 2 whose message names one of ``keys``.

Families: four-bars, slider-cranks (a one-point piston on a ground guide, at any angle and
offset), Watt I and II, Stephenson II and III six-bars, quick-return mechanisms (a block
sliding on a moving slotted lever, with or without a ram on a ground guide; crank-shaper and
Whitworth), Scotch yokes (two prismatic pairs in series: a numerically solved group), and the
shipped examples with perturbed points and masses; optional springs, loads, counter-rotors,
gravity, ``[simulation]`` and ``[balance]`` sections; all under a random similarity
transformation (scale, rotation, translation).

Usage::

    .venv/bin/python -m tests.fuzz.linkages --seed 2026 --index 17     # print one case
"""

from __future__ import annotations

import argparse
import cmath
import copy
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .generate import Inline, Raw, _key, _value

SPEC = "spec.toml"
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
EXAMPLE_NAMES = ("watt_sixbar", "stephenson_sixbar", "quick_return", "jansen_leg")
GROUND = "ground"

#: Least transmission quality (sine of a dyad's transmission angle, or the analogue for a
#: prismatic dyad) over the turn for a linkage to count as valid.
GOOD = 0.10
#: Least quality at the reference pose for a linkage to count as regular there.
REGULAR = 0.20
#: Crank angles sampled to classify a construction.
TURN = np.linspace(0.0, 2.0 * np.pi, 2881)


# ----------------------------------------------------------------------------------------------
# The case


_ITEM = re.compile(r"\b(sliders|springs)\[(\d+)\]")


def message_key(key: str) -> str:
    """A generator's key (items of arrays of tables counted from 0, as the spec's lists are
    indexed) as a message names it: each ``sliders[i]``, ``springs[i]`` counted from 1, as
    the docs count them (``balancer.validate.item``, issue 40: ``springs[1]`` is the first
    spring). A value's list elements keep their index (``direction[0]``); the generator's
    keys have none."""
    return _ITEM.sub(lambda m: f"{m.group(1)}[{int(m.group(2)) + 1}]", key)


@dataclass(frozen=True)
class LinkageCase:
    """One spec and what the input alone implies.

    ``expect`` is ``valid``, ``no-full-turn``, ``edge`` or ``error``; ``keys`` the spec keys
    one of which an exit-2 message must name (``()``: only the file); ``family`` the
    generator (``valid/watt2``, ``error/unknown-point``, ...); ``info`` facts the campaign
    checks outputs against (link names, ground points, reference angles, ...).
    """

    seed: int
    index: int
    family: str
    expect: str
    spec: bytes
    keys: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    heavy: bool = False
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return f"lk-{self.seed}-{self.index:05d}"

    @property
    def has_balance(self) -> bool:
        return bool(self.info.get("has_balance"))

    def expected_rc(self, verb: str) -> frozenset[int]:
        """Exit codes the input alone allows for ``verb``."""
        if self.expect == "error":
            return frozenset({2})
        if self.expect == "edge":
            return frozenset({0, 1, 2})
        needs_operation = verb in ("analyze", "verify", "optimize")
        if needs_operation and not self.info.get("has_operation", True):
            return frozenset({2})
        if self.expect == "no-full-turn":
            if verb == "simulate":  # a theta1 outside the assembly range is bad input
                return frozenset({0, 1} if self.info.get("theta1") is None else {0, 1, 2})
            return frozenset({2})
        # valid
        if verb == "optimize":
            return frozenset({0, 1})  # the solver may fail or find force balance infeasible
        return frozenset({0})

    def expected_keys(self, verb: str) -> tuple[str, ...]:
        """Keys one of which an exit-2 message should name for ``verb``, as messages name
        them (:func:`message_key`)."""
        if self.expect in ("error", "edge"):
            return tuple(map(message_key, self.keys))
        if verb in ("analyze", "verify", "optimize") and not self.info.get("has_operation", True):
            return ("operation.speed",)
        if self.expect == "no-full-turn":
            return ("mechanism", "simulation.theta1") if verb == "simulate" else ("mechanism",)
        return ()


# ----------------------------------------------------------------------------------------------
# TOML text (arrays of tables as [[...]] sections)


def to_toml(doc: dict[str, Any]) -> str:
    """TOML text of a spec dict: tables as sections, lists of tables as ``[[...]]``."""
    lines: list[str] = []

    def is_aot(v: Any) -> bool:
        return (isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)
                and not any(isinstance(x, Inline) for x in v))

    def section(d: dict[str, Any], path: tuple[str, ...], header: str | None) -> None:
        scalars = [(k, v) for k, v in d.items()
                   if not ((isinstance(v, dict) and not isinstance(v, Inline) and k != "com")
                           or is_aot(v))]
        if header is not None:
            lines.append("")
            lines.append(header)
        for k, v in scalars:
            lines.append(f"{_key(k)} = {_value(v)}")
        for k, v in d.items():
            if isinstance(v, dict) and not isinstance(v, Inline) and k != "com":
                sub = (*path, k)
                section(v, sub, "[" + ".".join(_key(p) for p in sub) + "]")
        for k, v in d.items():
            if is_aot(v):
                sub = (*path, k)
                for item in v:
                    section(item, sub, "[[" + ".".join(_key(p) for p in sub) + "]]")

    section(doc, (), None)
    return "\n".join(lines).lstrip("\n") + "\n"


# ----------------------------------------------------------------------------------------------
# Constructions: points as functions of the crank angle


class Construction:
    """Points of a linkage as functions of the crank angle, step by step.

    Each step adds one point from points before it; :meth:`evaluate` returns the points (complex
    arrays over the angles) and the least quality of any step (NaN where a step does not
    assemble).
    """

    def __init__(self) -> None:
        self.steps: list[tuple] = []

    def fixed(self, name: str, z: complex) -> None:
        self.steps.append(("fixed", name, complex(z)))

    def crank(self, name: str, pivot: str, r: float) -> None:
        self.steps.append(("crank", name, pivot, float(r)))

    def rigid(self, name: str, p: str, q: str, u: float, v: float) -> None:
        """``name = p + (u + i v)·(q − p)/|q − p|``: a point fixed in the frame p→q."""
        self.steps.append(("rigid", name, p, q, float(u), float(v)))

    def along(self, name: str, p: str, q: str, length: float, angle: float = 0.0) -> None:
        """``name = p + length·e^{i angle}·(q − p)/|q − p|``: a point on a link through p, q."""
        self.steps.append(("rigid", name, p, q, length * math.cos(angle),
                           length * math.sin(angle)))

    def rrr(self, name: str, p: str, q: str, a: float, b: float, sign: float) -> None:
        """``|name − p| = a``, ``|name − q| = b``, on the side ``sign`` of p→q."""
        self.steps.append(("rrr", name, p, q, float(a), float(b), float(sign)))

    def rrp(self, name: str, p: str, a: float, origin: complex, direction: complex,
            sign: float) -> None:
        """``|name − p| = a`` with ``name`` on the fixed line ``origin + t·direction``."""
        d = complex(direction) / abs(direction)
        self.steps.append(("rrp", name, p, float(a), complex(origin), d, float(sign)))

    def rpr(self, name: str, pivot: str, through: str, length: float, offset: float,
            scale: float) -> None:
        """A lever about ``pivot`` whose slot (offset ``offset`` from its axis) passes through
        ``through``; ``name`` is on the lever's axis at ``length`` from the pivot."""
        self.steps.append(("rpr", name, pivot, through, float(length), float(offset),
                           float(scale)))

    def yoke(self, name: str, pin: str, start: complex, pin_ref_x: float) -> None:
        """A point that moves with the x-coordinate of ``pin`` (a Scotch yoke): at ``start``
        when the pin's x is ``pin_ref_x``."""
        self.steps.append(("yoke", name, pin, complex(start), float(pin_ref_x)))

    def evaluate(self, theta: np.ndarray, ref: dict[str, complex] | None = None
                 ) -> tuple[dict[str, np.ndarray], np.ndarray]:
        theta = np.asarray(theta, dtype=float)
        pts: dict[str, np.ndarray] = {}
        quality = np.full(theta.shape, np.inf)
        with np.errstate(all="ignore"):
            for step in self.steps:
                kind, name = step[0], step[1]
                q = None
                if kind == "fixed":
                    z = np.full(theta.shape, step[2], dtype=complex)
                elif kind == "crank":
                    z = pts[step[2]] + step[3] * np.exp(1j * theta)
                elif kind == "rigid":
                    p, qq = pts[step[2]], pts[step[3]]
                    d = qq - p
                    z = p + complex(step[4], step[5]) * d / np.abs(d)
                elif kind == "rrr":
                    p, qq, a, b, sign = pts[step[2]], pts[step[3]], step[4], step[5], step[6]
                    d = qq - p
                    dist = np.abs(d)
                    x = (a * a - b * b + dist * dist) / (2 * dist)
                    h2 = a * a - x * x
                    h = np.sqrt(np.maximum(h2, 0.0))
                    z = p + (x + 1j * sign * h) * d / dist
                    q = np.where(h2 > 0, dist * h / (a * b), np.nan)
                elif kind == "rrp":
                    p, a, origin, d, sign = pts[step[2]], step[3], step[4], step[5], step[6]
                    w = (p - origin) * np.conj(d)
                    perp2 = a * a - w.imag**2
                    along = np.sqrt(np.maximum(perp2, 0.0))
                    z = origin + (w.real + sign * along) * d
                    q = np.where(perp2 > 0, along / a, np.nan)
                elif kind == "rpr":
                    pivot, through, length, offset, scale = (pts[step[2]], pts[step[3]],
                                                              step[4], step[5], step[6])
                    rel = through - pivot
                    dist = np.abs(rel)
                    inside = dist**2 - offset**2
                    alpha = np.angle(rel) - np.arcsin(np.clip(offset / dist, -1, 1))
                    z = pivot + length * np.exp(1j * alpha)
                    q = np.where(inside > 0, np.sqrt(np.maximum(inside, 0)) / scale, np.nan)
                    q = np.minimum(q, 1.0)
                elif kind == "yoke":
                    pin, start, ref_x = pts[step[2]], step[3], step[4]
                    z = start + (pin.real - ref_x)
                else:  # pragma: no cover
                    raise ValueError(kind)
                pts[name] = z
                if q is not None:  # NaN (no assembly) wins over any quality
                    quality = np.where(np.isnan(q) | np.isnan(quality), np.nan,
                                       np.minimum(quality, q))
        return pts, quality


def classify(con: Construction, theta_ref: float) -> tuple[str, float, float]:
    """``valid``, ``no-full-turn`` or ``edge``; the least quality over the turn and at the
    reference pose."""
    _, q = con.evaluate(np.append(TURN, theta_ref))
    q_turn, q_ref = q[:-1], float(q[-1])
    if not q_ref > 0:
        return "broken", math.nan, q_ref  # no assembly at the reference angle
    if not q_ref > REGULAR:
        return "edge", float(np.nanmin(q_turn)) if np.any(~np.isnan(q_turn)) else math.nan, q_ref
    if np.any(np.isnan(q_turn)):
        return "no-full-turn", math.nan, q_ref
    least = float(np.min(q_turn))
    return ("valid" if least > GOOD else "edge"), least, q_ref


def reference_points(con: Construction, theta_ref: float) -> dict[str, complex]:
    pts, _ = con.evaluate(np.array([theta_ref]))
    return {k: complex(v[0]) for k, v in pts.items()}


def _fit_dyad(rng, dists: np.ndarray, loose: bool = False) -> tuple[float, float]:
    """Lengths ``a``, ``b`` of an RRR dyad spanning every distance in ``dists``."""
    lo, hi = float(np.min(dists)), float(np.max(dists))
    if loose:
        s = hi * rng.uniform(0.7, 1.3)
        diff = lo * rng.uniform(0.0, 1.6)
    else:
        s = hi * rng.uniform(1.12, 1.7)
        diff = lo * rng.uniform(0.0, 0.85)
    a, b = (s + diff) / 2, (s - diff) / 2
    if rng.random() < 0.5:
        a, b = b, a
    return a, max(b, 1e-3 * s)


# ----------------------------------------------------------------------------------------------
# Families. Each returns (construction, reference angle, links, ground points, sliders, input)
# in a canonical frame (the crank pivot at the origin); lengths of order 1.


@dataclass
class Topology:
    con: Construction
    theta_ref: float
    links: dict[str, list[str]]
    ground: list[str]
    sliders: list[dict[str, Any]] = field(default_factory=list)  # direction: callable(pts)
    input: str = "crank"
    family: str = ""


def _sign(rng) -> float:
    return 1.0 if rng.random() < 0.5 else -1.0


def _order(rng, a: str, b: str, p: float = 0.5) -> list[str]:
    return [a, b] if rng.random() >= p else [b, a]


def _fourbar_core(rng, con: Construction, loose: bool, prefix: str = "A"
                  ) -> tuple[str, str, str, str]:
    a0, a1, a2, a3 = (f"{prefix}0", f"{prefix}1", f"{prefix}2", f"{prefix}3")
    r = 1.0
    if rng.random() < 0.2 and not loose:  # double crank: the frame shortest
        f = rng.uniform(0.3, 0.8)
    else:
        f = rng.uniform(1.4, 4.0)
    psi = rng.uniform(-0.6, 0.6) if rng.random() < 0.5 else 0.0
    con.fixed(a0, 0j)
    con.fixed(a3, f * cmath.exp(1j * psi))
    con.crank(a1, a0, r)
    pts, _ = con.evaluate(TURN)
    a, b = _fit_dyad(rng, np.abs(pts[a1] - pts[a3]), loose)
    con.rrr(a2, a1, a3, a, b, _sign(rng))
    return a0, a1, a2, a3


def fam_fourbar(rng, loose=False) -> Topology:
    con = Construction()
    a0, a1, a2, a3 = _fourbar_core(rng, con, loose)
    links = {"crank": [a0, a1], "coupler": [a1, a2], "rocker": _order(rng, a3, a2, 0.3)}
    if rng.random() < 0.4:
        con.rigid("P", a1, a2, rng.uniform(0.0, 1.5), rng.uniform(-1.0, 1.0))
        links["coupler"].append("P")
    return Topology(con, rng.uniform(-math.pi, math.pi), links, [a0, a3], family="fourbar")


def fam_slider_crank(rng, loose=False) -> Topology:
    con = Construction()
    r = 1.0
    offset = rng.uniform(-1.0, 1.0) if rng.random() < 0.5 else 0.0
    rod = (r + abs(offset)) * (rng.uniform(0.6, 1.4) if loose else rng.uniform(1.25, 4.0))
    con.fixed("A0", 0j)
    con.crank("A1", "A0", r)
    con.rrp("P", "A1", rod, 1j * offset, 1.0, _sign(rng))
    links = {"crank": ["A0", "A1"], "rod": ["A1", "P"], "piston": ["P"]}
    if rng.random() < 0.3:
        con.rigid("M", "A1", "P", rng.uniform(0.2, 0.8), rng.uniform(-0.3, 0.3))
        links["rod"].append("M")
    sliders = [{"link": "piston", "guide": GROUND, "point": "P",
                "direction": complex(_sign(rng), 0.0)}]
    if rng.random() < 0.25:  # the piston carries a marker: a two-point sliding link
        links["piston"] = ["P", "Q"]
        sliders[0]["marker"] = ("Q", complex(rng.uniform(0.1, 0.5), rng.uniform(-0.3, 0.3)))
    return Topology(con, rng.uniform(-math.pi, math.pi), links, ["A0"], sliders,
                    family="slider-crank")


def fam_watt2(rng, loose=False) -> Topology:
    con = Construction()
    a0, a, b, b0 = _fourbar_core(rng, con, False, prefix="A")
    con.rigid("C", "A3", "A2", *(_polar(rng.uniform(0.6, 1.5), rng.uniform(0.8, 2.6))))
    d0 = complex(rng.uniform(-3, 3), rng.uniform(-3, 3))
    con.fixed("D0", d0)
    pts, _ = con.evaluate(TURN)
    x, y = _fit_dyad(rng, np.abs(pts["C"] - d0), loose)
    con.rrr("D", "C", "D0", x, y, _sign(rng))
    links = {"crank": [a0, a], "coupler1": [a, b], "rocker": ["A3", "A2", "C"],
             "coupler2": ["C", "D"], "output": _order(rng, "D0", "D", 0.2)}
    if rng.random() < 0.4:
        con.rigid("E", "D0", "D", rng.uniform(1.0, 1.8), 0.0)
        links["output"].append("E")
    return Topology(con, rng.uniform(-math.pi, math.pi), links, ["A0", "A3", "D0"],
                    family="watt2")


def _polar(rho: float, phi: float) -> tuple[float, float]:
    return rho * math.cos(phi), rho * math.sin(phi)


def fam_watt1(rng, loose=False) -> Topology:
    con = Construction()
    _fourbar_core(rng, con, False)
    con.rigid("C", "A1", "A2", *_polar(rng.uniform(0.4, 1.2), rng.uniform(-1.2, 1.2)))
    con.rigid("D", "A3", "A2", *_polar(rng.uniform(0.4, 1.2), rng.uniform(-1.2, 1.2)))
    pts, _ = con.evaluate(TURN)
    x, y = _fit_dyad(rng, np.abs(pts["C"] - pts["D"]), loose)
    con.rrr("E", "C", "D", x, y, _sign(rng))
    links = {"crank": ["A0", "A1"], "coupler": ["A1", "A2", "C"], "rocker": ["A3", "A2", "D"],
             "link5": ["C", "E"], "link6": _order(rng, "D", "E")}
    return Topology(con, rng.uniform(-math.pi, math.pi), links, ["A0", "A3"], family="watt1")


def fam_stephenson3(rng, loose=False) -> Topology:
    con = Construction()
    _fourbar_core(rng, con, False)
    con.rigid("C", "A1", "A2", *_polar(rng.uniform(0.4, 1.5), rng.uniform(-1.5, 1.5)))
    e0 = complex(rng.uniform(-3, 3), rng.uniform(-3, 3))
    con.fixed("E0", e0)
    pts, _ = con.evaluate(TURN)
    x, y = _fit_dyad(rng, np.abs(pts["C"] - e0), loose)
    con.rrr("E", "C", "E0", x, y, _sign(rng))
    links = {"crank": ["A0", "A1"], "coupler": ["A1", "A2", "C"], "rocker": ["A3", "A2"],
             "rod": ["C", "E"], "swing": _order(rng, "E0", "E", 0.2)}
    return Topology(con, rng.uniform(-math.pi, math.pi), links, ["A0", "A3", "E0"],
                    family="stephenson3")


def fam_stephenson2(rng, loose=False) -> Topology:
    con = Construction()
    _fourbar_core(rng, con, False)
    con.rigid("K", "A0", "A1", *_polar(rng.uniform(0.5, 1.0), rng.uniform(1.5, 4.5)))
    con.rigid("D", "A3", "A2", *_polar(rng.uniform(0.4, 1.2), rng.uniform(-1.2, 1.2)))
    pts, _ = con.evaluate(TURN)
    x, y = _fit_dyad(rng, np.abs(pts["K"] - pts["D"]), loose)
    con.rrr("E", "K", "D", x, y, _sign(rng))
    links = {"crank": ["A0", "A1", "K"], "coupler": ["A1", "A2"], "rocker": ["A3", "A2", "D"],
             "link5": ["K", "E"], "link6": ["D", "E"]}
    return Topology(con, rng.uniform(-math.pi, math.pi), links, ["A0", "A3"],
                    family="stephenson2")


def fam_quick_return(rng, loose=False) -> Topology:
    con = Construction()
    r = 1.0
    whitworth = rng.random() < 0.3
    d = rng.uniform(0.2, 0.7) if whitworth else rng.uniform(1.3, 3.0)
    gap = abs(d - r)
    offset = rng.uniform(-0.6, 0.6) * gap if rng.random() < 0.3 else 0.0
    if loose:
        offset = rng.uniform(-1.5, 1.5) * gap
    lever = (d + r) * rng.uniform(1.1, 1.8)
    con.fixed("A0", 0j)
    con.fixed("B0", -1j * d)
    con.crank("A1", "A0", r)
    con.rpr("C", "B0", "A1", lever, offset, r)
    links = {"crank": ["A0", "A1"], "block": ["A1"], "lever": ["B0", "C"]}
    sign = _sign(rng)
    sliders = [{"link": "block", "guide": "lever", "point": "A1",
                "direction": ("lever", sign)}]
    ground = ["A0", "B0"]
    if rng.random() < 0.75:
        pts, _ = con.evaluate(TURN)
        cy = pts["C"].imag
        h = rng.uniform(cy.min(), cy.max()) if rng.random() < 0.7 else cy.max() * 1.1
        reach = float(np.max(np.abs(cy - h)))
        rod = reach * (rng.uniform(0.5, 1.05) if loose else rng.uniform(1.2, 2.5)) + 0.05
        con.rrp("D", "C", rod, 1j * h, 1.0, _sign(rng))
        links["rod"] = ["C", "D"]
        links["ram"] = ["D"]
        sliders.append({"link": "ram", "guide": GROUND, "point": "D",
                        "direction": complex(_sign(rng), 0.0)})
    return Topology(con, rng.uniform(-math.pi, math.pi), links, ground, sliders,
                    family="whitworth" if whitworth else "quick-return")


def fam_scotch_yoke(rng, loose=False) -> Topology:
    con = Construction()
    con.fixed("A0", 0j)
    con.crank("A1", "A0", 1.0)
    theta_ref = rng.uniform(-math.pi, math.pi)
    start = complex(math.cos(theta_ref) + rng.uniform(-1.5, 1.5), rng.uniform(-2.0, 2.0))
    con.yoke("Y", "A1", start, math.cos(theta_ref))
    links = {"crank": ["A0", "A1"], "block": ["A1"], "yoke": ["Y"]}
    sliders = [{"link": "block", "guide": "yoke", "point": "A1",
                "direction": complex(0.0, _sign(rng))},
               {"link": "yoke", "guide": GROUND, "point": "Y",
                "direction": complex(_sign(rng), 0.0)}]
    return Topology(con, theta_ref, links, ["A0"], sliders, family="scotch-yoke")


_FAMILIES = {
    "fourbar": (fam_fourbar, 3),
    "slider-crank": (fam_slider_crank, 3),
    "watt2": (fam_watt2, 3),
    "watt1": (fam_watt1, 2),
    "stephenson3": (fam_stephenson3, 2),
    "stephenson2": (fam_stephenson2, 2),
    "quick-return": (fam_quick_return, 3),
    "scotch-yoke": (fam_scotch_yoke, 1),
}


def build_topology(rng, *, want: str, family: str | None = None, tries: int = 60
                   ) -> tuple[Topology, str, float, float]:
    """A topology whose classification is ``want`` (or the last one tried)."""
    names = list(_FAMILIES)
    weights = np.array([_FAMILIES[n][1] for n in names], dtype=float)
    if family is None:
        family = names[int(rng.choice(len(names), p=weights / weights.sum()))]
    maker = _FAMILIES[family][0]
    result = None
    for attempt in range(tries):
        loose = want != "valid" and attempt % 2 == 0
        topo = maker(rng, loose=loose)
        if want == "no-full-turn" and topo.family == "scotch-yoke":
            family = "fourbar"
            maker = fam_fourbar
            continue
        cls, least, q_ref = classify(topo.con, topo.theta_ref)
        result = (topo, cls, least, q_ref)
        if cls == want:
            return result
        if want == "no-full-turn" and cls == "edge":
            # try other reference angles on the same linkage
            _, q = topo.con.evaluate(TURN)
            ok = np.where(q > REGULAR)[0]
            if ok.size and np.any(np.isnan(q)):
                topo.theta_ref = float(TURN[int(rng.choice(ok))])
                cls, least, q_ref = classify(topo.con, topo.theta_ref)
                result = (topo, cls, least, q_ref)
                if cls == want:
                    return result
    assert result is not None
    return result


# ----------------------------------------------------------------------------------------------
# From a topology to a spec


def _loguniform(rng, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


@dataclass
class Transform:
    scale: float
    angle: float
    shift: complex

    def point(self, z: complex) -> complex:
        return self.scale * cmath.exp(1j * self.angle) * z + self.shift

    def vector(self, z: complex) -> complex:
        return cmath.exp(1j * self.angle) * z


def _random_transform(rng, extreme: bool = False) -> Transform:
    scale = _loguniform(rng, 1e-9, 1e9) if extreme else _loguniform(rng, 3e-4, 300.0)
    angle = rng.uniform(-math.pi, math.pi) if rng.random() < 0.6 else 0.0
    shift = 0j
    if rng.random() < 0.4:
        shift = scale * complex(rng.uniform(-3, 3), rng.uniform(-3, 3))
    return Transform(scale, angle, shift)


def _xy(z: complex) -> list[float]:
    return [float(z.real) + 0.0, float(z.imag) + 0.0]


def spec_from_topology(rng, topo: Topology, tf: Transform, *, extras: bool = True
                       ) -> tuple[dict[str, Any], dict[str, Any]]:
    """The spec dict of a topology at its reference pose, and the facts about it."""
    ref = reference_points(topo.con, topo.theta_ref)
    pts = {name: tf.point(z) for name, z in ref.items()}
    sliders = []
    for s in topo.sliders:
        marker = s.get("marker")
        if marker is not None:
            qname, local = marker
            pts[qname] = pts[s["point"]] + tf.scale * tf.vector(local)
    for s in topo.sliders:
        d = s["direction"]
        if isinstance(d, tuple):  # along a lever (its axis from its first point to its second)
            lever, sign = d
            lp = topo.links[lever]
            axis = ref[lp[1]] - ref[lp[0]]
            d = sign * axis / abs(axis)
        d = tf.vector(d)
        if rng.random() < 0.3:  # any length but zero
            d *= _loguniform(rng, 1e-3, 1e3)
        sliders.append({"link": s["link"], "guide": s["guide"], "point": s["point"],
                        "direction": _xy(d)})
    used = {p for ps in topo.links.values() for p in ps} | set(topo.ground)
    points = {p: _xy(pts[p]) for p in pts if p in used}
    doc: dict[str, Any] = {"title": f"fuzz {topo.family}",
                           "mechanism": {"type": "linkage", "input": topo.input,
                                         "points": points}}
    if sliders:
        doc["mechanism"]["sliders"] = sliders
    links: dict[str, Any] = {GROUND: {"points": list(topo.ground)}}
    ground = set(topo.ground)
    mscale = _loguniform(rng, 0.01, 100.0)
    slider_dir = {s["link"]: complex(*s["direction"]) for s in sliders}
    frames = {}
    for name, lp in topo.links.items():
        origin = pts[lp[0]]
        if len(lp) > 1:
            axis = pts[lp[1]] - origin
            length = max(abs(pts[a] - pts[b]) for a in lp for b in lp)
        else:
            axis = slider_dir[name]
            length = tf.scale
        frames[name] = (origin, math.atan2(axis.imag, axis.real))
        links[name] = {"points": list(lp), **_mass_props(rng, length, mscale, origin,
                                                           frames[name][1])}
        if extras and ground & set(lp) and rng.random() < 0.2:
            links[name]["counter_rotor"] = _r(links[name]["mass"] * length**2
                                             * rng.uniform(0.0, 2.0))
        if extras and rng.random() < 0.1:
            f = links[name]["mass"] * 9.81 * rng.uniform(0.2, 5)
            links[name]["force"] = [_r(f * rng.uniform(-1, 1)), _r(f * rng.uniform(-1, 1))]
        if extras and rng.random() < 0.1:
            links[name]["moment"] = _r(links[name]["mass"] * 9.81 * length
                                       * rng.uniform(-3, 3))
    doc["links"] = links
    # springs
    names = list(points)
    springs = []
    if extras and rng.random() < 0.25:
        for _ in range(int(rng.integers(1, 3))):
            a, b = rng.choice(len(names), size=2, replace=False)
            length0 = abs(pts[names[a]] - pts[names[b]])
            springs.append({"points": [names[a], names[b]],
                            "stiffness": _r(mscale * _loguniform(rng, 1.0, 1e4)),
                            "free_length": _r(length0 * rng.uniform(0.0, 1.5))})
        doc["springs"] = springs
    speed = _loguniform(rng, 0.3, 150.0) * (1 if rng.random() < 0.8 else -1)
    has_operation = not (extras and rng.random() < 0.04)
    if has_operation:
        doc["operation"] = {"speed": _r(speed)}
        if rng.random() < 0.7:
            doc["operation"]["samples"] = int(rng.choice([8, 9, 16, 24, 36, 90, 180, 360,
                                                          361, 720]))
    theta1 = None
    if rng.random() < 0.75:
        sim: dict[str, Any] = {"duration": _r(rng.uniform(0.05, 2.0)),
                               "omega1": _r(speed * rng.uniform(0.0, 1.5))}
        if rng.random() < 0.6:
            sim["drive"] = "constant-speed" if rng.random() < 0.6 else "free"
        if rng.random() < 0.25:
            theta1 = _r(rng.uniform(-7.0, 7.0))
            sim["theta1"] = theta1
        if rng.random() < 0.25:
            sim["gravity"] = [0.0, -9.81] if rng.random() < 0.6 else [
                _r(rng.uniform(-20, 20)), _r(rng.uniform(-20, 20))]
        if rng.random() < 0.1:
            sim["method"] = "multibody"
        if rng.random() < 0.1:
            sim["outputs"] = int(rng.integers(2, 60))
        doc["simulation"] = sim
    has_balance = extras and rng.random() < 0.6
    if has_balance:
        doc["balance"] = _balance(rng, topo, links, ground, pts)
    info = {
        "links": {n: list(p) for n, p in topo.links.items()},
        "ground": list(topo.ground),
        "input": topo.input,
        "sliders": [dict(s) for s in sliders],
        "frames_angle": {n: f[1] for n, f in frames.items()},
        "theta1": theta1,
        "has_operation": has_operation,
        "has_balance": has_balance,
        "force_balance": bool(doc.get("balance", {}).get("force_balance", True)),
    }
    return doc, info


def _r(x: float) -> float:
    return float(f"{float(x):.6g}")


def _mass_props(rng, length: float, mscale: float, origin: complex, angle: float
                ) -> dict[str, Any]:
    mass = _r(mscale * _loguniform(rng, 0.2, 5.0))
    e = _r(length * rng.uniform(-0.5, 1.2))
    f = _r(length * rng.uniform(-0.4, 0.4))
    inertia = _r(mass * (length * rng.uniform(0.05, 0.6)) ** 2)
    u = rng.random()
    if u < 0.6:
        com = {"e": e, "f": f}
    elif u < 0.8:
        com = {"s": _r(math.hypot(e, f)), "sigma": _r(math.atan2(f, e))}
    else:
        z = origin + complex(e, f) * cmath.exp(1j * angle)
        com = {"at": _xy(z)}
    return {"mass": mass, "inertia": inertia, "com": Inline(com)}


def _balance(rng, topo: Topology, links: dict[str, Any], ground: set[str],
             pts: dict[str, complex]) -> dict[str, Any]:
    bal: dict[str, Any] = {}
    if rng.random() < 0.85:
        bal["force_balance"] = True if rng.random() < 0.85 else False
    obj = {"shaking_moment": 1.0}
    for k in ("driving_torque", "shaking_force", "shaking_force_x", "added_mass"):
        if rng.random() < 0.1:
            obj[k] = _r(rng.uniform(0.0, 2.0))
    if rng.random() < 0.8:
        bal["objective"] = obj
    moving = list(topo.links)
    count = int(rng.integers(1, len(moving) + 1))
    chosen = list(rng.choice(len(moving), size=count, replace=False))
    for i in chosen:
        name = moving[int(i)]
        lp = topo.links[name]
        link = links[name]
        length = max((abs(pts[a] - pts[b]) for a in lp for b in lp), default=0.0) or 1.0
        m = link["mass"]
        free: dict[str, Any] = {"mass": [_r(m * rng.uniform(0.5, 1.0)),
                                         _r(m * rng.uniform(1.5, 4.0))]}
        if rng.random() < 0.7:
            free["com_radius"] = _r(length * rng.uniform(0.5, 1.5))
            if rng.random() < 0.5:
                free["com_about"] = str(lp[int(rng.integers(len(lp)))])
        rho = None
        if rng.random() < 0.5:
            rho = _r(length * rng.uniform(0.02, 0.2))
            free["min_gyration"] = rho
        if rng.random() < 0.15:
            lo_m = free["mass"][0]
            hi = _r(max(lo_m * (rho or 0.0) ** 2 * 4, m * length**2 * rng.uniform(0.1, 2.0)))
            free["inertia"] = [0.0, hi]
        if ground & set(lp) and rng.random() < 0.5:
            free["counter_rotor"] = [0.0, _r(m * length**2 * rng.uniform(0.5, 5.0))]
        bal[name] = free
    return bal


# ----------------------------------------------------------------------------------------------
# The shipped examples, perturbed


def _example(name: str) -> dict[str, Any]:
    return tomllib.loads((EXAMPLES / f"{name}.toml").read_text(encoding="utf-8"))


def perturbed_example(rng, big: bool) -> tuple[dict[str, Any], dict[str, Any], str]:
    name = EXAMPLE_NAMES[int(rng.integers(len(EXAMPLE_NAMES)))]
    doc = _example(name)
    mech = doc["mechanism"]
    pts = mech["points"]
    span = max(math.hypot(x - u, y - w) for x, y in pts.values() for u, w in pts.values())
    eps = rng.uniform(0.01, 0.06) if big else rng.uniform(0.0, 2e-3)
    angle = rng.uniform(-math.pi, math.pi) if rng.random() < 0.4 else 0.0
    shift = complex(rng.uniform(-1, 1), rng.uniform(-1, 1)) * span if rng.random() < 0.3 else 0j
    rot = cmath.exp(1j * angle)
    for p, (x, y) in list(pts.items()):
        z = complex(x, y) + eps * span * complex(rng.normal(), rng.normal())
        pts[p] = _xy(rot * z + shift)
    for s in mech.get("sliders", []):
        d = rot * complex(*s["direction"])
        s["direction"] = _xy(d)
    # the block's slot must stay along B0 -> A1 when the points move (quick return)
    if name == "quick_return":
        b0, a1 = complex(*pts["B0"]), complex(*pts["A1"])
        d = (a1 - b0) / abs(a1 - b0)
        mech["sliders"][0]["direction"] = _xy(d)
        # (the slot is then through B0 at the reference pose, like the example's)
    msc = _loguniform(rng, 0.2, 5.0) if rng.random() < 0.5 else 1.0
    for lname, link in doc["links"].items():
        if lname == GROUND:
            continue
        k = msc * rng.uniform(0.8, 1.25)
        link["mass"] = link["mass"] * k
        link["inertia"] = link["inertia"] * k
        link["com"] = Inline(link["com"])
        bal = doc.get("balance", {}).get(lname)
        if bal is not None and "mass" in bal:
            lo, hi = bal["mass"]
            bal["mass"] = [lo * k * 0.99, hi * k * 1.01]
    if rng.random() < 0.3:
        doc.pop("balance", None)
    if rng.random() < 0.3:
        doc["operation"]["samples"] = int(rng.choice([8, 36, 90, 360, 720]))
    info = {
        "links": {n: list(l["points"]) for n, l in doc["links"].items() if n != GROUND},
        "ground": list(doc["links"][GROUND]["points"]),
        "input": mech["input"],
        "sliders": [dict(s) for s in mech.get("sliders", [])],
        "theta1": doc.get("simulation", {}).get("theta1"),
        "has_operation": "operation" in doc,
        "has_balance": "balance" in doc,
        "force_balance": bool(doc.get("balance", {}).get("force_balance", True)),
    }
    info["frames_angle"] = _frame_angles(doc)
    return doc, info, name


#: The shipped examples solved in closed form (crank, then dyads and rigid points), to classify
#: a perturbed one independently of the tool: (crank pivot, pin, steps).
_EXAMPLE_STEPS = {
    "watt_sixbar": ("A0", "A", [("rrr", "B", "A", "B0"), ("rigid", "C", "B0", "B"),
                                ("rrr", "D", "C", "D0"), ("rigid", "E", "D0", "D")]),
    "jansen_leg": ("O", "X", [("rrr", "B", "X", "Z"), ("rigid", "C", "Z", "B"),
                              ("rrr", "D", "X", "Z"), ("rrr", "E", "C", "D"),
                              ("rigid", "F", "D", "E")]),
}


def classify_example(name: str, doc: dict[str, Any]) -> str | None:
    """``valid``/``no-full-turn``/``edge`` of a perturbed example with a closed-form solution
    (``None`` for the others: the Stephenson triad, the quick return)."""
    if name not in _EXAMPLE_STEPS:
        return None
    pivot, pin, steps = _EXAMPLE_STEPS[name]
    pts = {k: complex(*v) for k, v in doc["mechanism"]["points"].items()}
    con = Construction()
    for g in doc["links"][GROUND]["points"]:
        con.fixed(g, pts[g])
    con.crank(pin, pivot, abs(pts[pin] - pts[pivot]))
    for kind, j, a, b in steps:
        pj, pa, pb = pts[j], pts[a], pts[b]
        if kind == "rrr":
            sign = 1.0 if ((pb - pa).conjugate() * (pj - pa)).imag > 0 else -1.0
            con.rrr(j, a, b, abs(pj - pa), abs(pj - pb), sign)
        else:
            local = (pj - pa) / ((pb - pa) / abs(pb - pa))
            con.rigid(j, a, b, local.real, local.imag)
    ref = pts[pin] - pts[pivot]
    return classify(con, math.atan2(ref.imag, ref.real))[0]


def _frame_angles(doc: dict[str, Any]) -> dict[str, float]:
    pts = doc["mechanism"]["points"]
    sl = {s["link"]: s["direction"] for s in doc["mechanism"].get("sliders", [])}
    out = {}
    for n, link in doc["links"].items():
        if n == GROUND:
            continue
        lp = link["points"]
        if len(lp) > 1:
            a, b = complex(*pts[lp[0]]), complex(*pts[lp[1]])
            out[n] = math.atan2((b - a).imag, (b - a).real)
        else:
            out[n] = math.atan2(sl[n][1], sl[n][0])
    return out


# ----------------------------------------------------------------------------------------------
# Valid, no-full-turn and edge cases


def valid_doc(rng, *, want: str = "valid", family: str | None = None, extreme: bool = False
              ) -> tuple[dict[str, Any], dict[str, Any], str, str, list[str]]:
    """A spec dict of the requested class; its facts, family, class and notes."""
    topo, cls, least, q_ref = build_topology(rng, want=want, family=family)
    tf = _random_transform(rng, extreme=extreme)
    doc, info = spec_from_topology(rng, topo, tf)
    notes = [f"least transmission quality {least:.3g}, at the reference {q_ref:.3g}",
             f"scale {tf.scale:.3g} m"]
    return doc, info, topo.family, cls, notes


def _meta(doc: dict[str, Any], info: dict[str, Any]) -> dict[str, Any]:
    links = info["links"]
    ground = set(info["ground"])
    grounded = [n for n, p in links.items() if ground & set(p)]
    return {
        "links": links,
        "moving": list(links),
        "ground": list(info["ground"]),
        "grounded": grounded,
        "floating": [n for n in links if n not in grounded],
        "one_point": [n for n, p in links.items() if len(p) == 1],
        "points": list(doc["mechanism"]["points"]),
        "sliders": doc["mechanism"].get("sliders", []),
        "input": info["input"],
    }


# ----------------------------------------------------------------------------------------------
# Hostile mutations: each edits ``doc`` in place and returns (keys, note), or None if it does
# not apply to this spec.


def _pick(rng, seq):
    seq = list(seq)
    return seq[int(rng.integers(len(seq)))] if seq else None


def _fresh(names, stem: str) -> str:
    i = 9
    while f"{stem}{i}" in names:
        i += 1
    return f"{stem}{i}"


def m_missing(rng, doc, meta):
    moving = meta["moving"]
    options = [
        (("mechanism", "input"), "mechanism.input"),
        (("mechanism", "points"), "mechanism.points"),
        (("links", GROUND), "links.ground"),
        (("links",), "links"),
        (("mechanism",), "mechanism"),
    ]
    name = _pick(rng, moving)
    for k in ("points", "mass", "inertia", "com"):
        options.append((("links", name, k), f"links.{name}.{k}"))
    options.append((("links", GROUND, "points"), "links.ground.points"))
    if "operation" in doc:
        options.append((("operation", "speed"), "operation.speed"))
    for i, _s in enumerate(meta["sliders"]):
        for k in ("link", "guide", "point", "direction"):
            options.append((("mechanism", "sliders", i, k), f"mechanism.sliders[{i}].{k}"))
    for i, _ in enumerate(doc.get("springs", [])):
        for k in ("points", "stiffness", "free_length"):
            options.append((("springs", i, k), f"springs[{i}].{k}"))
    com = doc["links"][name].get("com", {})
    if "e" in com:
        options.append((("links", name, "com", "f"), f"links.{name}.com"))
    if "sigma" in com:
        options.append((("links", name, "com", "sigma"), f"links.{name}.com"))
    path, key = options[int(rng.integers(len(options)))]
    parent = doc
    for p in path[:-1]:
        parent = parent[p]
    del parent[path[-1]]
    if key == "links.ground":
        # the ground's points are then on no link, or the ground is missing: either is named
        return (key, "mechanism.points."), f"removed {key}"
    if key == "links":
        return ("links",), "removed [links]"
    if key == "mechanism.points":
        return ("mechanism.points",), "removed [mechanism.points]"
    return (key,), f"removed {key}"


_TYPOS = {"mass": "mas", "inertia": "inertial", "com": "centre", "points": "point",
          "counter_rotor": "counter-rotor", "moment": "moments"}


def m_unknown_key(rng, doc, meta):
    name = _pick(rng, meta["moving"])
    options = []
    for typo in _TYPOS.values():
        options.append((("links", name), typo, 1.0, f"links.{name}.{typo}"))
    options += [
        (("links", name), "gas_force", 100.0, f"links.{name}.gas_force"),
        (("links", name), "branch", "+", f"links.{name}.branch"),
        (("links", GROUND), "mass", 1.0, "links.ground.mass"),
        (("links", GROUND), "com", Inline({"e": 0.0, "f": 0.0}), "links.ground.com"),
        (("mechanism",), "branch", "+", "mechanism.branch"),
        (("mechanism",), "lengths", {"crank": 1.0}, "mechanism.lengths"),
        (("mechanism",), "inputs", meta["input"], "mechanism.inputs"),
        ((), "spring", [1], "spring"),
        ((), "linkage", {"a": 1}, "linkage"),
        (("links", name, "com"), "g", 0.0, f"links.{name}.com.g"),
    ]
    if "operation" in doc:
        options.append((("operation",), "speeds", 1.0, "operation.speeds"))
    if "simulation" in doc:
        options.append((("simulation",), "dt", 0.01, "simulation.dt"))
    for i, _ in enumerate(meta["sliders"]):
        options.append((("mechanism", "sliders", i), "guides", "ground",
                        f"mechanism.sliders[{i}].guides"))
        options.append((("mechanism", "sliders", i), "force", 10.0,
                        f"mechanism.sliders[{i}].force"))
    for i, _ in enumerate(doc.get("springs", [])):
        options.append((("springs", i), "damping", 1.0, f"springs[{i}].damping"))
    bal = doc.get("balance")
    if bal:
        for n in meta["moving"]:
            if isinstance(bal.get(n), dict):
                options.append((("balance", n), "com_radious", 1.0,
                                f"balance.{n}.com_radious"))
        options.append((("balance",), "force_balanced", True, "balance.force_balanced"))
        if isinstance(bal.get("objective"), dict):
            options.append((("balance", "objective"), "shaking", 1.0,
                            "balance.objective.shaking"))
    path, k, value, key = options[int(rng.integers(len(options)))]
    parent = doc
    for p in path:
        parent = parent[p]
    parent[k] = value
    return (key,), f"added unknown key {key}"


def m_unknown_point(rng, doc, meta):
    new = _fresh(meta["points"], "Q")
    options = ["link"]
    if meta["sliders"]:
        options.append("slider")
    if doc.get("springs"):
        options.append("spring")
    options.append("ground")
    where = _pick(rng, options)
    if where == "link":
        name = _pick(rng, meta["moving"])
        lp = doc["links"][name]["points"]
        lp[int(rng.integers(len(lp)))] = new
        return (f"links.{name}.points",), f"links.{name}.points names unknown {new}"
    if where == "ground":
        doc["links"][GROUND]["points"].append(new)
        return ("links.ground.points",), f"links.ground.points names unknown {new}"
    if where == "slider":
        i = int(rng.integers(len(meta["sliders"])))
        doc["mechanism"]["sliders"][i]["point"] = new
        return (f"mechanism.sliders[{i}].point",), f"slider point unknown {new}"
    i = int(rng.integers(len(doc["springs"])))
    doc["springs"][i]["points"][int(rng.integers(2))] = new
    return (f"springs[{i}].points",), f"spring point unknown {new}"


def m_one_point_link(rng, doc, meta):
    new = _fresh(meta["moving"], "lonely")
    p = _pick(rng, meta["points"])
    doc["links"][new] = {"points": [p], "mass": 1.0, "inertia": 0.1,
                         "com": Inline({"e": 0.0, "f": 0.0})}
    return (f"links.{new}.points",), f"one-point link {new} on {p}, not a slider's link"


def m_mobility(rng, doc, meta):
    pts = doc["mechanism"]["points"]
    links = doc["links"]
    kind = _pick(rng, ["truss", "dangling", "split"])
    if kind == "truss":  # a binary link between two points of different links: mobility 0
        owner = {}
        for n, l in links.items():
            for p in l["points"]:
                owner.setdefault(p, set()).add(n)
        cands = [(a, b) for a in pts for b in pts if a < b
                 and not (owner.get(a, set()) & owner.get(b, set()))]
        if not cands:
            return None
        a, b = cands[int(rng.integers(len(cands)))]
        za, zb = complex(*pts[a]), complex(*pts[b])
        if abs(za - zb) < 1e-9:
            return None
        new = _fresh(meta["moving"], "truss")
        links[new] = {"points": [a, b], "mass": 1.0, "inertia": 0.1,
                      "com": Inline({"e": 0.0, "f": 0.0})}
        return ("mechanism",), f"truss {new} between {a} and {b} (mobility 0)"
    if kind == "dangling":  # a link hanging from one point with a free end: mobility 2
        a = _pick(rng, [p for p in pts if any(p in l["points"] for n, l in links.items()
                                              if n != GROUND)])
        za = complex(*pts[a])
        span = max(abs(complex(*v)) for v in pts.values()) or 1.0
        new_p = _fresh(list(pts), "T")
        pts[new_p] = _xy(za + 0.3 * span * cmath.exp(1j * rng.uniform(0, 6.28)))
        new = _fresh(meta["moving"], "flail")
        links[new] = {"points": [a, new_p], "mass": 1.0, "inertia": 0.1,
                      "com": Inline({"e": 0.0, "f": 0.0})}
        return ("mechanism",), f"dangling link {new} from {a} (mobility 2)"
    # split a revolute joint of two moving links: mobility 2
    count: dict[str, list[str]] = {}
    for n, l in links.items():
        for p in l["points"]:
            count.setdefault(p, []).append(n)
    joints = [p for p, ns in count.items() if len(ns) >= 2 and GROUND not in ns
              and all(len(links[n]["points"]) > 1 for n in ns)]
    if not joints:
        return None
    p = _pick(rng, joints)
    n = count[p][-1]
    lp = links[n]["points"]
    new_p = _fresh(list(pts), p + "_")
    pts[new_p] = list(pts[p])
    lp[lp.index(p)] = new_p
    return ("mechanism",), f"split joint {p} of {n} into {new_p} (mobility 2)"


def m_duplicate_point(rng, doc, meta):
    kind = _pick(rng, ["in-link", "coincident"])
    if kind == "in-link":
        name = _pick(rng, meta["moving"] + [GROUND])
        lp = doc["links"][name]["points"]
        lp.append(lp[int(rng.integers(len(lp)))])
        return (f"links.{name}.points",), f"links.{name}.points names a point twice"
    # a link whose first two points are different names at one position
    cands = [n for n in meta["moving"] if len(meta["links"][n]) >= 2]
    name = _pick(rng, cands)
    if name is None:
        return None
    lp = doc["links"][name]["points"]
    pts = doc["mechanism"]["points"]
    new_p = _fresh(list(pts), "Z")
    pts[new_p] = list(pts[lp[0]])
    lp[1] = new_p  # the old second point may be left on no link, or still be a joint
    return (f"links.{name}.points", "mechanism.points."), \
        f"links.{name}: second point {new_p} coincides with {lp[0]}"


def m_point_on_no_link(rng, doc, meta):
    pts = doc["mechanism"]["points"]
    new = _fresh(list(pts), "W")
    pts[new] = [0.5, 0.25]
    return (f"mechanism.points.{new}",), f"point {new} on no link"


def m_zero_length(rng, doc, meta):
    cands = [n for n in meta["moving"] if len(meta["links"][n]) >= 2]
    name = _pick(rng, cands)
    lp = doc["links"][name]["points"]
    pts = doc["mechanism"]["points"]
    pts[lp[1]] = list(pts[lp[0]])
    # every link whose first two points now coincide may be the one named
    keys = tuple(f"links.{n}.points" for n, l in doc["links"].items()
                 if n != GROUND and len(l["points"]) >= 2
                 and pts[l["points"][0]] == pts[l["points"][1]])
    return keys or (f"links.{name}.points",), f"zero-length link {name}: {lp[1]} moved onto {lp[0]}"


def m_slider(rng, doc, meta):
    sl = doc["mechanism"].get("sliders")
    if not sl:
        return None
    i = int(rng.integers(len(sl)))
    s = sl[i]
    key = f"mechanism.sliders[{i}]"
    kind = _pick(rng, ["point-off-link", "zero-direction", "direction-3", "direction-str",
                       "on-itself", "ground-slides", "unknown-guide", "unknown-link",
                       "link-not-string", "two-sliders"])
    if kind == "point-off-link":
        others = [p for p in meta["points"] if p not in meta["links"][s["link"]]]
        s["point"] = _pick(rng, others)
        return (f"{key}.point",), f"slider {i} point {s['point']} not on {s['link']}"
    if kind == "zero-direction":
        s["direction"] = [0.0, 0.0] if rng.random() < 0.7 else [0, -0.0]
        return (f"{key}.direction",), "slider direction [0, 0]"
    if kind == "direction-3":
        s["direction"] = [1.0, 0.0, 0.0]
        return (f"{key}.direction",), "slider direction with three components"
    if kind == "direction-str":
        s["direction"] = "horizontal"
        return (f"{key}.direction",), "slider direction a string"
    if kind == "on-itself":
        s["guide"] = s["link"]
        return (f"{key}.guide",), "slider on itself"
    if kind == "ground-slides":
        s["link"] = GROUND
        return (f"{key}.link",), "ground as the sliding link"
    if kind == "unknown-guide":
        s["guide"] = "frame"
        return (f"{key}.guide",), "unknown guide link"
    if kind == "unknown-link":
        s["link"] = "pistn"
        return (f"{key}.link",), "unknown sliding link"
    if kind == "link-not-string":
        s["link"] = 3
        return (f"{key}.link",), "slider link a number"
    # a second slider on a one-point link
    sl.append(dict(s, direction=[0.0, 1.0]))
    if s["link"] in meta["one_point"]:
        return (f"links.{s['link']}.points", "mechanism"), "two sliders on one-point link"
    return ("mechanism",), "a second slider for the same link (mobility 0)"


def m_spring(rng, doc, meta):
    springs = doc.setdefault("springs", [])
    if not springs:
        a, b = rng.choice(len(meta["points"]), size=2, replace=False)
        springs.append({"points": [meta["points"][a], meta["points"][b]], "stiffness": 100.0,
                        "free_length": 0.1})
    i = int(rng.integers(len(springs)))
    s = springs[i]
    key = f"springs[{i}]"
    kind = _pick(rng, ["neg-k", "neg-l", "same", "three", "string", "table"])
    if kind == "neg-k":
        s["stiffness"] = -abs(s["stiffness"]) - 1.0
        return (f"{key}.stiffness",), "negative stiffness"
    if kind == "neg-l":
        s["free_length"] = -0.5
        return (f"{key}.free_length",), "negative free length"
    if kind == "same":
        s["points"] = [s["points"][0], s["points"][0]]
        return (f"{key}.points",), "spring between a point and itself"
    if kind == "three":
        s["points"] = list(s["points"]) + [meta["points"][0]]
        return (f"{key}.points",), "spring with three points"
    if kind == "string":
        s["stiffness"] = "stiff"
        return (f"{key}.stiffness",), "stiffness a string"
    s["points"] = Inline({"a": s["points"][0], "b": s["points"][1]})
    return (f"{key}.points",), "spring points a table"


def _numeric_leaves(doc, path=()):
    """(path, value) of every number in the spec (list elements included)."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from _numeric_leaves(v, (*path, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _numeric_leaves(v, (*path, i))
    elif isinstance(doc, int | float) and not isinstance(doc, bool):
        yield path, doc


def _key_of(path) -> str:
    """The spec key a message should name for a leaf: list indices of arrays of tables as
    ``[i]``, list elements of values dropped."""
    out = ""
    for i, p in enumerate(path):
        if isinstance(p, int):
            if path[i - 1] in ("sliders", "springs"):
                out += f"[{p}]"
            else:
                break
        else:
            out += ("." if out else "") + str(p)
    return out


def _set_path(doc, path, value):
    parent = doc
    for p in path[:-1]:
        parent = parent[p]
    parent[path[-1]] = value


def _bad_value_keys(path) -> tuple[str, ...]:
    key = _key_of(path)
    if len(path) >= 3 and path[0] == "links" and path[2] == "com":
        return (key, f"links.{path[1]}.com")
    if path[:2] == ("mechanism", "points") and len(path) >= 3:
        return (f"mechanism.points.{path[2]}",)
    return (key,)


def m_nonfinite(rng, doc, meta):
    leaves = [p for p, _ in _numeric_leaves(doc)]
    path = _pick(rng, leaves)
    word = _pick(rng, ["nan", "inf", "-inf", "+nan"])
    _set_path(doc, path, Raw(word))
    return _bad_value_keys(path), f"{_key_of(path)} = {word}"


#: Leaves at which 1e300 must be refused (the figures would leave double precision), and the
#: keys the message may name.
def _huge_expectation(path, doc=None) -> str:
    key = _key_of(path)
    if key.startswith("mechanism.points"):
        return "error"
    last = key.split(".")[-1]
    if key.startswith("links.") and last in ("mass", "inertia", "counter_rotor", "moment",
                                             "force", "e", "f", "s", "at"):
        if doc is not None and last not in ("moment", "force") and not _moves(doc):
            # At rest (no speed anywhere) a mass property enters no force but its weight:
            # the scales are m·R·ω² (zero) and m·|g|·R (an inertia not even that).
            gravity = any(doc.get("simulation", {}).get("gravity", [0.0, 0.0]))
            if last in ("inertia", "counter_rotor") or not gravity:
                return "edge"
        return "error"
    if key in ("operation.speed", "simulation.omega1", "simulation.gravity",
               "operation.samples", "simulation.outputs"):
        return "error"
    if key.startswith("links.") and key.endswith("sigma"):
        return "edge"  # an angle: 1e300 rad is a number
    return "edge"


def _moves(doc) -> bool:
    """Whether the spec gives a speed anywhere (an operating speed or an initial one)."""
    return bool(doc.get("operation", {}).get("speed")) or bool(
        doc.get("simulation", {}).get("omega1"))


def m_huge(rng, doc, meta):
    leaves = [p for p, _ in _numeric_leaves(doc)]
    path = _pick(rng, leaves)
    value = _pick(rng, [1e300, -1e300, 1e200, 1.7976931348623157e308])
    _set_path(doc, path, value)
    exp = _huge_expectation(path, doc)
    return (_bad_value_keys(path) if exp == "error" else None), f"{_key_of(path)} = {value:g}"


def m_tiny(rng, doc, meta):
    leaves = [p for p, _ in _numeric_leaves(doc)]
    path = _pick(rng, leaves)
    value = _pick(rng, [1e-300, 5e-324, -1e-300, 1e-30])
    _set_path(doc, path, value)
    return None, f"{_key_of(path)} = {value:g}"


def m_string_number(rng, doc, meta):
    leaves = [p for p, _ in _numeric_leaves(doc)]
    path = _pick(rng, leaves)
    old = _get_path(doc, path)
    _set_path(doc, path, _pick(rng, [str(old), "", "1,5", "two"]))
    return _bad_value_keys(path), f"{_key_of(path)} a string"


def _get_path(doc, path):
    for p in path:
        doc = doc[p]
    return doc


def m_bool_number(rng, doc, meta):
    leaves = [p for p, _ in _numeric_leaves(doc)]
    path = _pick(rng, leaves)
    _set_path(doc, path, True)
    return _bad_value_keys(path), f"{_key_of(path)} = true"


def m_table_for_list(rng, doc, meta):
    name = _pick(rng, meta["moving"])
    options = []
    lp = doc["links"][name]["points"]
    options.append((("links", name, "points"), Inline({str(i): p for i, p in enumerate(lp)}),
                    (f"links.{name}.points",)))
    options.append((("links", GROUND, "points"), Inline({"a": doc["links"][GROUND]["points"][0]}),
                    ("links.ground.points",)))
    p = _pick(rng, meta["points"])
    x, y = doc["mechanism"]["points"][p]
    options.append((("mechanism", "points", p), Inline({"x": x, "y": y}),
                    (f"mechanism.points.{p}",)))
    for i, s in enumerate(meta["sliders"]):
        options.append((("mechanism", "sliders", i, "direction"),
                        Inline({"x": s["direction"][0], "y": s["direction"][1]}),
                        (f"mechanism.sliders[{i}].direction",)))
    if meta["sliders"]:
        options.append((("mechanism", "sliders"), dict(meta["sliders"][0]),
                        ("mechanism.sliders",)))
    if doc.get("springs"):
        options.append((("springs",), dict(doc["springs"][0]), ("springs",)))
    sim = doc.get("simulation")
    if sim is not None:
        options.append((("simulation", "gravity"), Inline({"x": 0.0, "y": -9.81}),
                        ("simulation.gravity",)))
    options.append((("links", name, "force"), Inline({"x": 1.0, "y": 0.0}),
                    (f"links.{name}.force",)))
    bal = doc.get("balance") or {}
    for n in meta["moving"]:
        if isinstance(bal.get(n), dict) and "mass" in bal[n]:
            lo, hi = bal[n]["mass"]
            options.append((("balance", n, "mass"), Inline({"low": lo, "high": hi}),
                            (f"balance.{n}.mass",)))
    path, value, keys = options[int(rng.integers(len(options)))]
    _set_path(doc, path, value)
    return keys, f"{'.'.join(map(str, path))} a table instead of a list"


def m_list_for_table(rng, doc, meta):
    name = _pick(rng, meta["moving"])
    options = [
        (("links", name, "com"), [0.1, 0.0], (f"links.{name}.com",)),
        (("mechanism", "points"), [[0.0, 0.0]], ("mechanism.points",)),
        (("links", name), [1.0, 2.0], (f"links.{name}",)),
        (("mechanism",), ["linkage"], ("mechanism",)),
        (("links", name, "points"), "A0", (f"links.{name}.points",)),
        (("links", name, "points"), [], (f"links.{name}.points",)),
        (("links", name, "points"), [[p] for p in doc["links"][name]["points"]],
         (f"links.{name}.points",)),
    ]
    if "operation" in doc:
        options.append((("operation",), 10.0, ("operation",)))
    if doc.get("balance"):
        options.append((("balance",), [1], ("balance",)))
    path, value, keys = options[int(rng.integers(len(options)))]
    _set_path(doc, path, value)
    return keys, f"{'.'.join(map(str, path))} = {value!r}"


def m_balance(rng, doc, meta):
    bal = doc.setdefault("balance", {"objective": {"shaking_moment": 1.0}})
    kind = _pick(rng, ["ground", "unknown-link", "com-about-off", "com-about-unknown",
                       "rotor-floating", "range-reversed", "range-3", "gyration-impossible",
                       "nothing-free", "weights-zero", "com-about-no-radius", "force-bal-str",
                       "mass-negative"])
    name = _pick(rng, meta["moving"])
    if kind == "ground":
        bal[GROUND] = {"mass": [1.0, 2.0]}
        return ("balance.ground",), "[balance.ground]"
    if kind == "unknown-link":
        bal["cranck"] = {"mass": [1.0, 2.0]}
        return ("balance.cranck",), "[balance.cranck]"
    if kind in ("com-about-off", "com-about-unknown"):
        if kind == "com-about-off":
            off = [p for p in meta["points"] if p not in meta["links"][name]]
            p = _pick(rng, off)
            if p is None:
                return None
        else:
            p = "NOWHERE"
        bal[name] = {"mass": [1.0, 2.0], "com_radius": 0.1, "com_about": p}
        return (f"balance.{name}.com_about",), f"com_about {p} not on {name}"
    if kind == "com-about-no-radius":
        bal[name] = {"mass": [1.0, 2.0], "com_about": meta["links"][name][0]}
        return (f"balance.{name}.com_about",), "com_about without com_radius"
    if kind == "rotor-floating":
        floating = meta["floating"]
        if not floating:
            return None
        n = _pick(rng, floating)
        if rng.random() < 0.5:
            bal[n] = {"mass": [1.0, 2.0], "counter_rotor": [0.0, 1.0]}
            return (f"balance.{n}.counter_rotor",), f"balance counter_rotor on floating {n}"
        doc["links"][n]["counter_rotor"] = 0.5
        return (f"links.{n}.counter_rotor",), f"links counter_rotor on floating {n}"
    if kind == "range-reversed":
        bal[name] = {"mass": [2.0, 1.0]}
        return (f"balance.{name}.mass",), "mass range reversed"
    if kind == "range-3":
        bal[name] = {"mass": [1.0, 2.0, 3.0]}
        return (f"balance.{name}.mass",), "mass range of three"
    if kind == "mass-negative":
        bal[name] = {"mass": [-1.0, 2.0]}
        return (f"balance.{name}.mass",), "negative mass bound"
    if kind == "gyration-impossible":
        bal[name] = {"mass": [1.0, 2.0], "min_gyration": 10.0, "inertia": [0.0, 1.0]}
        return (f"balance.{name}.min_gyration",), "min_gyration impossible with inertia"
    if kind == "nothing-free":
        for n in list(bal):
            if n not in ("objective", "force_balance"):
                del bal[n]
        return ("balance",), "nothing free in [balance]"
    if kind == "weights-zero":
        bal["objective"] = {"shaking_moment": 0.0}
        bal.setdefault(name, {"mass": [1.0, 2.0]})
        return ("balance.objective",), "all weights zero"
    bal["force_balance"] = "yes"
    return ("balance.force_balance",), "force_balance a string"


def m_input(rng, doc, meta):
    mech = doc["mechanism"]
    kind = _pick(rng, ["floating", "ground", "unknown", "number", "reversed", "list"])
    if kind == "floating":
        n = _pick(rng, meta["floating"])
        if n is None:
            return None
        mech["input"] = n
        return ("mechanism.input",), f"input {n} not on the ground"
    if kind == "ground":
        mech["input"] = GROUND
        return ("mechanism.input",), "input = ground"
    if kind == "unknown":
        mech["input"] = "motor"
        return ("mechanism.input",), "input unknown"
    if kind == "number":
        mech["input"] = 1
        return ("mechanism.input",), "input a number"
    if kind == "list":
        mech["input"] = [meta["input"]]
        return ("mechanism.input",), "input a list"
    lp = doc["links"][meta["input"]]["points"]
    lp.reverse()  # its first point is now the crank pin
    return ("mechanism.input",), "input's points reversed (first point not a ground pivot)"


def m_singular(rng, doc, meta):
    """Replace the spec by a four-bar at a singular reference pose."""
    kind = _pick(rng, ["limit", "collinear", "slider-dead"])
    if kind == "limit":  # non-Grashof: coupler and rocker in line, A2 between A1 and A3
        r, c, ro, f = 1.0, 1.2, 1.5, 2.0  # r + f > c + ro: the crank stops at θ_lim
        # |A1 - A3| = c + ro at this crank angle (the law of cosines)
        cos_t = (r * r + f * f - (c + ro) ** 2) / (2 * r * f)
        t = math.acos(cos_t)
        a1 = r * cmath.exp(1j * t)
        a3 = complex(f, 0)
        a2 = a1 + c * (a3 - a1) / abs(a3 - a1)
        keys = ("mechanism.input", "mechanism.points")
        note = "reference pose at a limit position (coupler and rocker in line)"
    elif kind == "collinear":
        a1, a2, a3 = 1 + 0j, 3 + 0j, 2 + 0j  # crank 1, coupler 2, rocker 1, frame 2
        keys = ("mechanism.points", "mechanism.input")
        note = "all four joints on one line"
    else:
        return _slider_dead(doc, meta)
    pts = {"A0": [0.0, 0.0], "A1": _xy(a1), "A2": _xy(a2), "A3": _xy(a3)}
    doc.clear()
    doc.update({
        "mechanism": {"type": "linkage", "input": "crank", "points": pts},
        "links": {GROUND: {"points": ["A0", "A3"]},
                  "crank": _plain(), "coupler": _plain(), "rocker": _plain()},
        "operation": {"speed": 10.0},
    })
    doc["links"]["crank"]["points"] = ["A0", "A1"]
    doc["links"]["coupler"]["points"] = ["A1", "A2"]
    doc["links"]["rocker"]["points"] = ["A2", "A3"]
    return keys, note


def _slider_dead(doc, meta):
    # crank longer than rod: the rod square to the guide at the reference (a dead point)
    r, rod = 2.0, 1.0
    a1 = complex(math.sqrt(r * r - rod * rod), rod)
    p = complex(a1.real, 0.0)
    doc.clear()
    doc.update({
        "mechanism": {"type": "linkage", "input": "crank",
                      "points": {"A0": [0.0, 0.0], "A1": _xy(a1), "P": _xy(p)},
                      "sliders": [{"link": "piston", "guide": GROUND, "point": "P",
                                   "direction": [1.0, 0.0]}]},
        "links": {GROUND: {"points": ["A0"]}, "crank": _plain(), "rod": _plain(),
                  "piston": _plain()},
        "operation": {"speed": 10.0},
    })
    doc["links"]["crank"]["points"] = ["A0", "A1"]
    doc["links"]["rod"]["points"] = ["A1", "P"]
    doc["links"]["piston"]["points"] = ["P"]
    return ("mechanism.points", "mechanism.input"), "slider-crank with the rod square to the guide"


def _plain() -> dict[str, Any]:
    return {"mass": 1.0, "inertia": 0.1, "com": Inline({"e": 0.2, "f": 0.0})}


def m_sizes(rng, doc, meta):
    kind = _pick(rng, ["samples-huge", "samples-float", "samples-small", "outputs-huge",
                       "speed-zero", "duration-zero", "rtol", "method", "drive", "type"])
    if kind == "samples-huge":
        doc.setdefault("operation", {"speed": 10.0})["samples"] = _pick(
            rng, [10**9, 10**12, 2**63 - 1])
        return ("operation.samples",), "samples huge"
    if kind == "samples-float":
        doc.setdefault("operation", {"speed": 10.0})["samples"] = 360.0
        return ("operation.samples",), "samples = 360.0"
    if kind == "samples-small":
        doc.setdefault("operation", {"speed": 10.0})["samples"] = int(rng.integers(-3, 8))
        return ("operation.samples",), "samples below 8"
    if kind == "outputs-huge":
        doc.setdefault("simulation", {})["outputs"] = 10**10
        return ("simulation.outputs",), "outputs huge"
    if kind == "speed-zero":
        doc.setdefault("operation", {})["speed"] = 0.0
        return ("operation.speed",), "speed zero"
    if kind == "duration-zero":
        doc.setdefault("simulation", {})["duration"] = -1.0
        return ("simulation.duration",), "negative duration (overridden by --duration?)"
    if kind == "rtol":
        doc.setdefault("simulation", {})["rtol"] = 1e-20
        return ("simulation.rtol",), "rtol below the floor"
    if kind == "method":
        doc.setdefault("simulation", {})["method"] = _pick(rng, ["opened-loop", "lie-group",
                                                                "mass-matrix", "rk4"])
        return ("simulation.method",), f"method {doc['simulation']['method']} for a linkage"
    if kind == "drive":
        doc.setdefault("simulation", {})["drive"] = "motor"
        return ("simulation.drive",), "drive unknown"
    doc["mechanism"]["type"] = _pick(rng, ["Linkage", "linkages", "four-bar", "six-bar"])
    if doc["mechanism"]["type"] == "four-bar":
        return ("mechanism.input", "mechanism.points", "mechanism.sliders", "mechanism.lengths",
                "mechanism"), "type four-bar with linkage keys"
    return ("mechanism.type",), f"type {doc['mechanism']['type']}"


def m_com(rng, doc, meta):
    name = _pick(rng, meta["moving"])
    link = doc["links"][name]
    kind = _pick(rng, ["both", "at-3", "at-str", "empty", "s-negative"])
    if kind == "both":
        link["com"] = Inline({"e": 0.1, "f": 0.0, "s": 0.1, "sigma": 0.0})
        return (f"links.{name}.com",), "com in two forms"
    if kind == "at-3":
        link["com"] = Inline({"at": [0.0, 0.0, 0.0]})
        return (f"links.{name}.com.at",), "com.at with three values"
    if kind == "at-str":
        link["com"] = Inline({"at": "A0"})
        return (f"links.{name}.com.at",), "com.at a point name"
    if kind == "empty":
        link["com"] = Inline({})
        return (f"links.{name}.com",), "com empty"
    link["com"] = Inline({"s": -0.1, "sigma": 0.0})
    return (f"links.{name}.com.s",), "com.s negative"


def m_negative(rng, doc, meta):
    name = _pick(rng, meta["moving"])
    link = doc["links"][name]
    kind = _pick(rng, ["mass", "mass0", "inertia", "rotor"])
    if kind == "mass":
        link["mass"] = -abs(link["mass"])
        return (f"links.{name}.mass",), "negative mass"
    if kind == "mass0":
        link["mass"] = 0.0
        return (f"links.{name}.mass",), "zero mass"
    if kind == "inertia":
        link["inertia"] = -abs(link["inertia"]) - 0.01
        return (f"links.{name}.inertia",), "negative inertia"
    n = _pick(rng, meta["grounded"])
    doc["links"][n]["counter_rotor"] = -0.5
    return (f"links.{n}.counter_rotor",), "negative counter-rotor"


def m_names(rng, doc, meta):
    """Link names that collide with [balance] keys or need quoting: should stay valid."""
    old = _pick(rng, meta["moving"])
    new = _pick(rng, ["objective", "force_balance", "a.b", "λ-link", "with space", "1",
                      "crank arm", "balance"])
    links = doc["links"]
    doc["links"] = {(new if k == old else k): v for k, v in links.items()}
    for s in doc["mechanism"].get("sliders", []):
        for attr in ("link", "guide"):
            if s[attr] == old:
                s[attr] = new
    if doc["mechanism"]["input"] == old:
        doc["mechanism"]["input"] = new
    bal = doc.get("balance")
    if bal and old in bal:
        bal[new] = bal.pop(old)
    return None, f"link {old} renamed {new!r}"


def m_point_names(rng, doc, meta):
    old = _pick(rng, meta["points"])
    new = _pick(rng, ["A.0", "é", "1", "with space", "ground", "x[0]", "crank"])
    if new in meta["points"]:
        return None
    pts = doc["mechanism"]["points"]
    doc["mechanism"]["points"] = {(new if k == old else k): v for k, v in pts.items()}
    for link in doc["links"].values():
        link["points"] = [new if p == old else p for p in link["points"]]
    for s in doc["mechanism"].get("sliders", []):
        if s["point"] == old:
            s["point"] = new
    for s in doc.get("springs", []):
        s["points"] = [new if p == old else p for p in s["points"]]
    for _n, b in (doc.get("balance") or {}).items():
        if isinstance(b, dict) and b.get("com_about") == old:
            b["com_about"] = new
    return None, f"point {old} renamed {new!r}"


def m_point_vector(rng, doc, meta):
    p = _pick(rng, meta["points"])
    value = _pick(rng, [[0.0], [0.0, 0.0, 0.0], [], "0,0", 1.0, [[0.0, 0.0]], ["0", "0"]])
    doc["mechanism"]["points"][p] = value
    return (f"mechanism.points.{p}",), f"mechanism.points.{p} = {value!r}"


#: Hostile mutations: name -> (function, weight).
MUTATIONS = {
    "missing-key": (m_missing, 4),
    "unknown-key": (m_unknown_key, 4),
    "unknown-point": (m_unknown_point, 3),
    "one-point-link": (m_one_point_link, 2),
    "mobility": (m_mobility, 3),
    "duplicate-point": (m_duplicate_point, 2),
    "point-on-no-link": (m_point_on_no_link, 1),
    "zero-length-link": (m_zero_length, 2),
    "slider": (m_slider, 3),
    "spring": (m_spring, 3),
    "non-finite": (m_nonfinite, 4),
    "huge": (m_huge, 4),
    "string-for-number": (m_string_number, 3),
    "bool-for-number": (m_bool_number, 1),
    "table-for-list": (m_table_for_list, 3),
    "list-for-table": (m_list_for_table, 2),
    "balance": (m_balance, 4),
    "input": (m_input, 3),
    "singular": (m_singular, 2),
    "sizes": (m_sizes, 3),
    "com": (m_com, 2),
    "negative": (m_negative, 2),
    "point-vector": (m_point_vector, 1),
}

#: Mutations that keep the spec valid (or undecided: ``edge``).
VALID_MUTATIONS = {
    "tiny": (m_tiny, 2),
    "link-names": (m_names, 2),
    "point-names": (m_point_names, 2),
}


# ----------------------------------------------------------------------------------------------
# Text-level variants


def text_variant(rng, text: str) -> tuple[bytes, str, str, tuple[str, ...], str]:
    """(bytes, note, expect, keys, kind) of a text-level change."""
    kind = _pick(rng, ["duplicate-point-key", "truncated", "crlf", "bom", "latin1",
                       "duplicate-table", "empty"])
    if kind == "duplicate-point-key":
        lines = text.split("\n")
        i = lines.index("[mechanism.points]")
        lines.insert(i + 2, lines[i + 1])
        return "\n".join(lines).encode(), "a point given twice (TOML duplicate key)", \
            "error", (), kind
    if kind == "truncated":
        cut = int(rng.integers(len(text) // 3, len(text)))
        return text[:cut].encode(), f"truncated at {cut}", "edge", (), kind
    if kind == "crlf":
        return text.replace("\n", "\r\n").encode(), "CRLF line endings", "same", (), kind
    if kind == "bom":
        return b"\xef\xbb\xbf" + text.encode(), "UTF-8 byte-order mark", "edge", (), kind
    if kind == "latin1":
        return ("# caf\u00e9\n" + text).encode("latin-1"), "Latin-1 comment", "error", (), kind
    if kind == "duplicate-table":  # a table the spec has (not every spec has [operation])
        table = "operation" if "\n[operation]" in text else "mechanism"
        return (text + f"\n[{table}]\nspeed = 1.0\n").encode(), f"[{table}] twice", \
            "error", (), kind
    return b"", "empty file", "error", ("mechanism",), kind


# ----------------------------------------------------------------------------------------------
# Cases


#: (group, weight): the mix of a campaign.
GROUPS = (("valid", 40), ("example", 10), ("example-big", 3), ("no-full-turn", 6),
          ("edge", 4), ("error", 30), ("valid-mutation", 4), ("text", 3))


def make_case(seed: int, index: int, group: str | None = None) -> LinkageCase:
    """Case ``index`` of the campaign with ``seed``."""
    rng = np.random.default_rng([seed, index, 0x11a7])
    if group is None:
        names = [g for g, _ in GROUPS]
        w = np.array([w for _, w in GROUPS], dtype=float)
        group = names[int(rng.choice(len(names), p=w / w.sum()))]
    notes: list[str] = []
    if group in ("example", "example-big"):
        doc, info, name = perturbed_example(rng, big=group == "example-big")
        expect = "valid" if group == "example" else "edge"
        independent = classify_example(name, doc)
        if independent is not None:
            notes.append(f"independent classification: {independent}")
            if independent != "valid":
                expect = "edge" if independent == "broken" else independent
        return _case(seed, index, f"{group}/{name}", expect, doc, info, (), notes)
    if group == "no-full-turn":
        doc, info, fam, cls, notes = valid_doc(rng, want="no-full-turn")
        return _case(seed, index, f"no-full-turn/{fam}", cls, doc, info, (), notes)
    if group == "edge":
        kind = _pick(rng, ["extreme-scale", "near-singular", "huge-duration", "theta1-far",
                           "at-limit", "many-samples"])
        if kind == "at-limit":
            return _at_limit_case(seed, index, rng)
        if kind == "many-samples":
            doc, info, fam, cls, notes = valid_doc(rng)
            samples = _pick(rng, [20000, 100000, 1000000])
            doc.setdefault("operation", {"speed": 10.0})["samples"] = samples
            info["has_operation"] = True
            notes.append(f"operation.samples = {samples}")
            return _case(seed, index, f"edge/many-samples/{fam}", "edge", doc, info, (), notes,
                         heavy=True)
        if kind == "extreme-scale":
            doc, info, fam, cls, notes = valid_doc(rng, extreme=True)
            return _case(seed, index, f"edge/extreme-scale/{fam}", "edge", doc, info, (), notes)
        if kind == "near-singular":
            doc, info, fam, cls, notes = valid_doc(rng, want="edge")
            return _case(seed, index, f"edge/near-singular/{fam}", "edge", doc, info, (), notes)
        doc, info, fam, cls, notes = valid_doc(rng)
        sim = doc.setdefault("simulation", {})
        if kind == "huge-duration":
            sim["duration"] = _pick(rng, [1e6, 1e9, 1e300])
            notes.append(f"simulation.duration = {sim['duration']:g} (--duration overrides)")
            # the command lines give --duration 0.05: the spec's duration must not matter
            return _case(seed, index, f"edge/huge-duration/{fam}", cls, doc, info, (), notes)
        sim["theta1"] = _pick(rng, [1e3, -1e4, 1e6, 1e12])
        info["theta1"] = sim["theta1"]
        notes.append(f"simulation.theta1 = {sim['theta1']:g}")
        return _case(seed, index, f"edge/theta1-far/{fam}", "edge", doc, info, (), notes,
                     heavy=True)
    if group == "valid":
        doc, info, fam, cls, notes = valid_doc(rng)
        return _case(seed, index, f"valid/{fam}", cls, doc, info, (), notes)
    if group == "valid-mutation":
        doc, info, fam, cls, notes = valid_doc(rng)
        names = list(VALID_MUTATIONS)
        w = np.array([VALID_MUTATIONS[n][1] for n in names], dtype=float)
        mname = names[int(rng.choice(len(names), p=w / w.sum()))]
        out = VALID_MUTATIONS[mname][0](rng, doc, _meta(doc, info))
        if out is None:
            return _case(seed, index, f"valid/{fam}", cls, doc, info, (), notes)
        _, note = out
        notes.append(note)
        info = _refresh_info(doc, info)
        expect = "edge" if mname == "tiny" else cls
        clash = [n for n in info["links"] if n in ("objective", "force_balance")]
        if clash:  # a link named like a [balance] key: accepted, or refused naming the link
            return _case(seed, index, f"valid-mutation/{mname}-reserved", "edge", doc, info,
                         (f"links.{clash[0]}",), notes)
        return _case(seed, index, f"valid-mutation/{mname}", expect, doc, info, (), notes)
    if group == "text":
        doc, info, fam, cls, notes = valid_doc(rng)
        data, note, expect, keys, kind = text_variant(rng, to_toml(doc))
        notes.append(note)
        if expect == "same":
            expect = cls
        if expect == "error" and not data:
            pass
        return LinkageCase(seed, index, f"text/{kind}", expect, data, keys,
                           tuple(notes), False, info)
    # error
    doc, info, fam, cls, notes = valid_doc(rng)
    if cls != "valid":
        notes.append(f"(base spec {cls})")
    names = list(MUTATIONS)
    w = np.array([MUTATIONS[n][1] for n in names], dtype=float)
    for _ in range(10):
        mname = names[int(rng.choice(len(names), p=w / w.sum()))]
        trial = copy.deepcopy(doc)
        out = MUTATIONS[mname][0](rng, trial, _meta(trial, info))
        if out is not None:
            break
    keys, note = out
    notes.append(note)
    if keys is None:  # an undecided mutation (1e300 where it may be fine)
        return _case(seed, index, f"edge/{mname}", "edge", trial, info, (), notes)
    if cls != "valid" and mname not in ("singular",):
        # the base spec is not valid: its own fault may be reported first
        return _case(seed, index, f"error/{mname}", "edge", trial, info, (), notes)
    return _case(seed, index, f"error/{mname}", "error", trial, info, tuple(keys), notes)


def _at_limit_case(seed: int, index: int, rng) -> LinkageCase:
    """A linkage whose reference pose is a limit position (a dyad stretched or folded, to
    rounding): singular, or so nearly that no tolerance can tell."""
    topo, cls, least, q_ref = build_topology(rng, want="no-full-turn")
    _, q = topo.con.evaluate(TURN)
    ok = ~np.isnan(q)
    edges = np.where(ok[:-1] & ~ok[1:])[0]
    notes = []
    if edges.size:
        i = int(edges[0])
        lo, hi = float(TURN[i]), float(TURN[i + 1])  # assembles at lo, not at hi
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if np.isnan(topo.con.evaluate(np.array([mid]))[1][0]):
                hi = mid
            else:
                lo = mid
        topo.theta_ref = lo
        notes.append(f"reference at the limit θ = {lo!r} (quality "
                     f"{float(topo.con.evaluate(np.array([lo]))[1][0]):.3g})")
    tf = _random_transform(rng)
    doc, info = spec_from_topology(rng, topo, tf)
    return _case(seed, index, f"edge/at-limit/{topo.family}", "edge", doc, info, (), notes)


def _refresh_info(doc: dict[str, Any], info: dict[str, Any]) -> dict[str, Any]:
    """The facts about a spec after a mutation that keeps it valid (renamed links, points)."""
    info = copy.deepcopy(info)
    info["links"] = {n: list(l["points"]) for n, l in doc["links"].items() if n != GROUND}
    info["ground"] = list(doc["links"][GROUND]["points"])
    info["input"] = doc["mechanism"]["input"]
    info["sliders"] = [dict(s) for s in doc["mechanism"].get("sliders", [])]
    info["frames_angle"] = _frame_angles(doc)
    return info


def _case(seed, index, family, expect, doc, info, keys, notes, heavy=False) -> LinkageCase:
    text = to_toml(doc)
    return LinkageCase(seed, index, family, expect, text.encode("utf-8"), tuple(keys),
                       tuple(notes), heavy, info)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz.linkages")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--index", type=int, default=0)
    parser.add_argument("--count", type=int, default=1)
    parser.add_argument("--group")
    parser.add_argument("--summary", action="store_true", help="only family and expectation")
    args = parser.parse_args(argv)
    for i in range(args.index, args.index + args.count):
        case = make_case(args.seed, i, args.group)
        if args.summary:
            print(f"{case.name} {case.family:40s} {case.expect:13s} {case.keys} "
                  f"{'; '.join(case.notes)[:100]}")
            continue
        print(f"# {case.name} {case.family} expect={case.expect} keys={case.keys}")
        print(f"# notes: {'; '.join(case.notes)}")
        print(case.spec.decode("utf-8", "replace"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())


# ----------------------------------------------------------------------------------------------
# Directed cases: suspects found by hand around the random campaign's findings (run with
# ``linkage_campaign --directed``); they do not change the random cases' draws.


def _scaled_fourbar(k: float, extra: str = "") -> str:
    return f'''[mechanism]
type = "linkage"
input = "crank"

[mechanism.points]
A0 = [0.0, 0.0]
A1 = [0.0, {1.0 * k!r}]
A2 = [{2.2 * k!r}, {1.8 * k!r}]
A3 = [{3.2 * k!r}, 0.0]

[links.ground]
points = ["A0", "A3"]

[links.crank]
points = ["A0", "A1"]
mass = 2.0
inertia = {0.5 * k * k!r}
com = {{ e = {0.4 * k!r}, f = 0.0 }}

[links.coupler]
points = ["A1", "A2"]
mass = 3.0
inertia = {3.1 * k * k!r}
com = {{ e = {1.4 * k!r}, f = {0.3 * k!r} }}

[links.rocker]
points = ["A2", "A3"]
mass = 2.0
inertia = {1.0 * k * k!r}
com = {{ e = {1.0 * k!r}, f = 0.0 }}

[operation]
speed = 10.0
{extra}'''


def _quick_return_with_ram_direction(direction: str) -> str:
    text = (EXAMPLES / "quick_return.toml").read_text(encoding="utf-8")
    return text.replace("direction = [1.0, 0.0]", f"direction = {direction}", 1)


def directed_cases(seed: int = 0) -> list[LinkageCase]:
    """The directed cases: (family, expect, keys, spec text, notes)."""
    fourbar_info = {"links": {"crank": ["A0", "A1"], "coupler": ["A1", "A2"],
                              "rocker": ["A2", "A3"]}, "ground": ["A0", "A3"],
                    "input": "crank", "sliders": [], "theta1": None, "has_operation": True,
                    "has_balance": False, "force_balance": True}
    qr = tomllib.loads((EXAMPLES / "quick_return.toml").read_text(encoding="utf-8"))
    qr_info = {"links": {n: l["points"] for n, l in qr["links"].items() if n != GROUND},
               "ground": qr["links"][GROUND]["points"], "input": "crank",
               "sliders": qr["mechanism"]["sliders"], "theta1": None, "has_operation": True,
               "has_balance": True, "force_balance": True}
    # A direction of any length is its direction: the two extremes read as the 45° reference
    # does (whose crank cannot turn fully: exit 2 naming mechanism.points), or are refused
    # naming the direction.
    items = [
        ("directed/direction-overflow", "edge", ("mechanism.sliders[1].direction",
                                                 "mechanism.points"),
         _quick_return_with_ram_direction("[1.7e308, 1.7e308]"), qr_info,
         "ram's guide direction [1.7e308, 1.7e308] (45°; its length overflows)"),
        ("directed/direction-subnormal", "edge", ("mechanism.sliders[1].direction",
                                                  "mechanism.points"),
         _quick_return_with_ram_direction("[5e-324, 5e-324]"), qr_info,
         "ram's guide direction [5e-324, 5e-324] (45°, subnormal)"),
        ("directed/direction-45", "edge", (), _quick_return_with_ram_direction("[1.0, 1.0]"),
         qr_info, "ram's guide direction [1, 1]: the reference for the two above"),
        ("directed/theta1-1e6", "edge", ("simulation.theta1",),
         _scaled_fourbar(1.0, "\n[simulation]\ntheta1 = 1e6\nomega1 = 1.0\n"), fourbar_info,
         "simulation.theta1 = 1e6"),
        ("directed/theta1-1e12", "edge", ("simulation.theta1",),
         _scaled_fourbar(1.0, "\n[simulation]\ntheta1 = 1e12\nomega1 = 1.0\n"),
         fourbar_info, "simulation.theta1 = 1e12"),
        ("directed/min-gyration-1e-300", "valid", (),
         _scaled_fourbar(1.0, "\n[balance.crank]\nmass = [1.0, 4.0]\ninertia = [0.0, 1.0]\n"
                              "min_gyration = 1e-300\n"), dict(fourbar_info, has_balance=True),
         "balance.crank.min_gyration = 1e-300 with an inertia range"),
        ("directed/scale-1e8-verify", "edge", ("--duration",), _scaled_fourbar(1e8),
         fourbar_info, "a four-bar 1e8 m long (no [simulation]): verify --duration 0.05"),
        ("directed/scale-1e9-free", "edge", (),
         _scaled_fourbar(1e9, "\n[simulation]\nomega1 = 10.0\n"), fourbar_info,
         "a four-bar 1e9 m long, free motion at 10 rad/s"),
        ("directed/scale-1e-10", "edge", (), _scaled_fourbar(1e-10), fourbar_info,
         "a four-bar 1e-10 m long"),
    ]
    out = []
    for i, (family, expect, keys, text, info, note) in enumerate(items):
        out.append(LinkageCase(seed, 90000 + i, family, expect, text.encode("utf-8"), keys,
                               ("", "", note), False, info))
    return out
