"""Seeded generators of design specs and command lines for fuzzing the ``balancer`` CLI.

Everything is a pure function of ``(seed, index)``: :func:`make_case` builds one
:class:`Case` (the spec's bytes, the argv relative to a work folder, the exit codes the input
alone decides, if any) and :func:`prepare_workdir` lays out the folder the argv refers to::

    spec.toml      the spec (its mode may be 000 for an unreadable spec)
    out/           an empty folder for outputs
    ro/            a read-only folder (mode 555)
    adir/          an existing folder, used as an output *file* path

Valid specs cover both mechanism types: Grashof four-bars of every class (including ones whose
crank does not turn fully, change-point ones and non-Grashof ones), slider-cranks in line, with
offset, with crank ≈ rod or a crank that cannot turn, gas-force tables, loads, counter-rotors,
``[operation]``, ``[simulation]``, ``[balance]`` and ``[original]``. Hostile variants mutate a
valid spec or the command line. Sizes are such that a correct tool answers within seconds,
except the cases tagged ``heavy`` (absurd sizes on purpose); the ``cheap`` profile leaves those
out.
"""

from __future__ import annotations

import json
import math
import os
import stat
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

SPEC = "spec.toml"
VERBS = ("analyze", "simulate", "optimize", "verify", "plot")
METHODS = ("opened-loop", "complex-masses", "mass-matrix", "lie-group")
METHODS_BY_TYPE = {"four-bar": METHODS, "slider-crank": ("mass-matrix", "complex-masses")}
LINKS_BY_TYPE = {
    "four-bar": ("crank", "coupler", "rocker"),
    "slider-crank": ("crank", "rod", "slider"),
}
JOINTS = {
    "crank": ("A0", "A1"),
    "coupler": ("A1", "A2"),
    "rocker": ("A2", "A3"),
    "rod": ("A1", "A2"),
    "slider": ("A2",),
}
GROUNDED = {"four-bar": ("crank", "rocker"), "slider-crank": ("crank",)}
FOUR_BAR_CLASSES = (
    "crank-rocker",
    "double-crank",
    "rocker-crank",
    "double-rocker",
    "triple-rocker",
    "change-point",
)
#: Four-bar classes whose crank turns a full revolution.
FULL_TURN = ("crank-rocker", "double-crank", "change-point")
SLIDER_CLASSES = ("in-line", "offset", "crank-near-rod", "no-full-turn")


class Raw(str):
    """TOML text emitted as written (a literal such as ``nan`` or a datetime)."""


class Inline(dict):
    """A table emitted inline (``{ a = 1 }``) wherever it sits."""


@dataclass(frozen=True)
class Case:
    """One fuzz case: a spec and a command line, both relative to a prepared work folder.

    ``expect`` holds the exit codes that the input alone decides (``None``: any of 0, 1, 2);
    ``outputs`` the output paths named on the command line; ``heavy`` marks absurd sizes on
    purpose.
    """

    seed: int
    index: int
    kind: str
    verb: str
    spec: bytes
    argv: tuple[str, ...]
    expect: frozenset[int] | None = None
    outputs: tuple[str, ...] = ()
    heavy: bool = False
    spec_mode: int = 0o644
    notes: tuple[str, ...] = field(default_factory=tuple)

    @property
    def name(self) -> str:
        if self.kind.startswith("directed/"):
            return f"directed-{self.index:03d}"
        return f"case-{self.seed}-{self.index:05d}"


# ----------------------------------------------------------------------------------------------
# TOML text


def _value(v: Any) -> str:
    if isinstance(v, Raw):
        return str(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} as TOML")


def _key(k: str) -> str:
    ok = k and all(c.isalnum() or c in "-_" for c in k) and k.isascii()
    return k if ok else json.dumps(k)


def _inline(key: str, value: Any) -> bool:
    return isinstance(value, Inline) or key in ("com", "gas_force")


def to_toml(doc: dict[str, Any]) -> str:
    """TOML text of a nested dict (sections for tables, inline for ``com`` and ``gas_force``)."""
    lines: list[str] = []

    def table(d: dict[str, Any], path: tuple[str, ...]) -> None:
        subs = []
        for k, v in d.items():
            if isinstance(v, dict) and not _inline(k, v):
                subs.append((k, v))
            else:
                lines.append(f"{_key(k)} = {_value(v)}")
        for k, v in subs:
            if not v or any(not isinstance(x, dict) or _inline(n, x) for n, x in v.items()):
                lines.append("")
                lines.append("[" + ".".join(_key(p) for p in (*path, k)) + "]")
            table(v, (*path, k))

    table(doc, ())
    return "\n".join(lines).lstrip("\n") + "\n"


# ----------------------------------------------------------------------------------------------
# Valid specs


def _r(x: float) -> float:
    """Round to four significant digits (readable reproducers)."""
    return float(f"{float(x):.4g}")


def _choice(rng: np.random.Generator, options):
    return options[int(rng.integers(len(options)))]


def four_bar_lengths(rng: np.random.Generator, cls: str) -> tuple[float, float, float, float]:
    """``(crank, coupler, rocker, frame)`` of the given Grashof class."""
    if cls == "change-point":
        base = _choice(rng, [(1, 2, 1, 2), (2, 1, 2, 1), (1, 3, 2, 2), (2, 2, 1, 3), (1, 2, 2, 1)])
        scale = 2.0 ** int(rng.integers(-3, 3))
        return tuple(float(b) * scale for b in base)  # type: ignore[return-value]
    scale = float(10 ** rng.uniform(-1.5, 0.7))
    for _ in range(1000):
        if cls == "triple-rocker":
            x = np.sort(rng.uniform(1.0, 4.0, 4))
            s, p, q, big = x
            if not (s + big > p + q + 0.05 and big < s + p + q - 0.05):
                continue
            order = rng.permutation(4)
            lengths = [float(x[i]) for i in order]
        else:
            shortest = {
                "crank-rocker": 0,
                "double-crank": 3,
                "rocker-crank": 2,
                "double-rocker": 1,
            }[cls]
            others = rng.uniform(1.25, 4.0, 3)
            if 1.0 + others.max() > others.sum() - others.max() - 0.05:
                continue
            lengths = list(others)
            lengths.insert(shortest, 1.0)
        return tuple(_r(v * scale) for v in lengths)  # type: ignore[return-value]
    raise RuntimeError("no lengths found")  # pragma: no cover


def slider_lengths(rng: np.random.Generator, cls: str) -> tuple[float, float, float]:
    """``(crank, rod, offset)`` of the given slider-crank class."""
    r = _r(10 ** rng.uniform(-2, 0.5))
    if cls == "in-line":
        return r, _r(r * rng.uniform(1.5, 5.0)), 0.0
    if cls == "offset":
        rod = _r(r * rng.uniform(1.5, 5.0))
        return r, rod, _r(rng.uniform(-0.8, 0.8) * (rod - r))
    if cls == "crank-near-rod":
        return r, r * (1 + float(10 ** -_choice(rng, [1, 2, 3, 4, 7]))), 0.0
    return r, _r(r * rng.uniform(0.3, 0.95)), _r(rng.uniform(-0.3, 0.3) * r)


def _link(rng, length: float, *, rotor: bool, slider: bool = False) -> dict[str, Any]:
    m = _r(10 ** rng.uniform(-1, 1))
    d: dict[str, Any] = {"mass": m}
    if not slider or rng.random() < 0.5:
        d["inertia"] = _r(m * (rng.uniform(0.1, 0.5) * length) ** 2)
    if slider or rng.random() < 0.5:
        e, f = rng.uniform(-0.5, 1.2) * length, rng.uniform(-0.3, 0.3) * length
        d["com"] = {"e": _r(e), "f": _r(f)}
    else:
        s, sigma = rng.uniform(0, 1.2) * length, rng.uniform(-math.pi, math.pi)
        d["com"] = {"s": _r(s), "sigma": _r(sigma)}
    if rng.random() < 0.4:
        d["force"] = [_r(rng.uniform(-5, 5) * m), _r(rng.uniform(-5, 5) * m)]
    if rng.random() < 0.3:
        d["moment"] = _r(rng.uniform(-2, 2) * m * length)
    if rotor and rng.random() < 0.3:
        d["counter_rotor"] = _r(rng.uniform(0, 2) * m * length**2)
    return d


def _gas_force(rng, scale: float) -> Any:
    if rng.random() < 0.4:
        return _r(rng.uniform(-3000, 500) * scale)
    period = _choice(rng, [2 * math.pi, 4 * math.pi])
    n = int(rng.integers(1, 16))
    angles = np.unique(np.round(rng.uniform(0, period, n), 4))
    angles = np.concatenate([[0.0], angles[angles > 0]])
    angles = angles[angles < period]
    values = [_r(v * scale) for v in rng.uniform(-5000, 500, len(angles))]
    d: dict[str, Any] = {"crank_angle": [float(a) for a in angles], "force": values}
    if period != 2 * math.pi or rng.random() < 0.3:
        d["period"] = _r(period) if period != 2 * math.pi else period
    return Inline(d) if rng.random() < 0.5 else d


def _freedom(rng, name: str, link: dict[str, Any], length: float, grounded: bool) -> dict:
    m = link["mass"]
    f: dict[str, Any] = {}
    if rng.random() < 0.75:
        f["mass"] = _r(m * 1.5) if rng.random() < 0.15 else [m, _r(m * _choice(rng, [2, 4, 40]))]
    if rng.random() < 0.85:
        f["com_radius"] = _r(length * rng.uniform(0.5, 3.0))
        if rng.random() < 0.5:
            f["com_about"] = _choice(rng, JOINTS[name])
    rho = None
    if rng.random() < 0.6:
        rho = _r(0.1 * length * rng.uniform(0.5, 2))
        f["min_gyration"] = rho
    if rng.random() < 0.2:
        m_lo = f["mass"][0] if isinstance(f.get("mass"), list) else f.get("mass", m)
        hi = max(link.get("inertia", 0.0) * 4, (m_lo * rho * rho * 2) if rho else 0.0, 1e-6)
        f["inertia"] = [0.0, _r(hi)]
    if grounded and rng.random() < 0.6:
        f["counter_rotor"] = [0.0, _r(rng.uniform(1, 20) * m * length**2)]
    if not f:
        f["mass"] = [m, _r(4 * m)]
    return f


def _balance(rng, kind: str, links: dict[str, dict], lengths: dict[str, float]) -> dict:
    names = LINKS_BY_TYPE[kind]
    odds = {"crank": 0.85, "rocker": 0.8, "coupler": 0.4, "rod": 0.6, "slider": 0.4}
    chosen = [n for n in names if rng.random() < odds[n]] or [_choice(rng, names)]
    d: dict[str, Any] = {}
    if rng.random() < 0.8:
        d["force_balance"] = bool(rng.random() < 0.8)
    if rng.random() < 0.8:
        obj: dict[str, Any] = {"shaking_moment": _choice(rng, [1.0, 1.0, 0.5, 0.0])}
        for k in ("driving_torque", "shaking_force", "shaking_force_x", "shaking_force_y",
                  "added_mass"):
            if rng.random() < 0.2:
                obj[k] = _r(10 ** rng.uniform(-3, 1))
        if not any(obj.values()):
            obj["shaking_moment"] = 1.0
        d["objective"] = obj
    for n in chosen:
        d[n] = _freedom(rng, n, links[n], lengths[n], n in GROUNDED[kind])
    return d


_CLASS_WEIGHTS = {
    "four-bar": {"crank-rocker": 3, "double-crank": 2, "change-point": 1, "rocker-crank": 1,
                 "double-rocker": 1, "triple-rocker": 1},
    "slider-crank": {"in-line": 3, "offset": 3, "crank-near-rod": 1, "no-full-turn": 1},
}


def assembles_at(kind: str, lengths: dict[str, float], theta1: float) -> bool:
    """Whether the linkage assembles at crank angle ``theta1`` (with a small margin)."""
    if kind == "four-bar":
        l1, l2, l3, l4 = (lengths[k] for k in ("crank", "coupler", "rocker", "frame"))
        d = math.sqrt(l1 * l1 + l4 * l4 - 2 * l1 * l4 * math.cos(theta1))
        return abs(l2 - l3) * 1.001 < d < (l2 + l3) * 0.999
    r, rod, e = lengths["crank"], lengths["rod"], lengths.get("offset", 0.0)
    return abs(e - r * math.sin(theta1)) < rod * 0.999


def valid_spec(rng: np.random.Generator, *, kind: str | None = None, cls: str | None = None,
               balance: bool | None = None) -> tuple[dict[str, Any], str]:
    """A spec (as a dict) and its class label, e.g. ``"four-bar/crank-rocker"``."""
    kind = kind or _choice(rng, ["four-bar", "four-bar", "slider-crank"])
    weights = _CLASS_WEIGHTS[kind]
    doc: dict[str, Any] = {}
    if rng.random() < 0.4:
        doc["title"] = _choice(rng, ["fuzz", "σ ≈ 0.3 rad — test", 'quote " and \\ back', ""])
    if kind == "four-bar":
        cls = cls or str(rng.choice(list(weights), p=np.array(list(weights.values())) / sum(
            weights.values())))
        l1, l2, l3, l4 = four_bar_lengths(rng, cls)
        lengths = {"crank": l1, "coupler": l2, "rocker": l3, "frame": l4}
        link_len = {"crank": l1, "coupler": l2, "rocker": l3}
    else:
        cls = cls or str(rng.choice(list(weights), p=np.array(list(weights.values())) / sum(
            weights.values())))
        r, rod, offset = slider_lengths(rng, cls)
        lengths = {"crank": r, "rod": rod}
        if offset or rng.random() < 0.3:
            lengths["offset"] = offset
        link_len = {"crank": r, "rod": rod, "slider": r}
    mech: dict[str, Any] = {"type": kind}
    if rng.random() < 0.8:
        mech["branch"] = _choice(rng, ["+", "-"])
    mech["lengths"] = lengths
    doc["mechanism"] = mech
    links = {}
    for n in LINKS_BY_TYPE[kind]:
        links[n] = _link(rng, link_len[n], rotor=n in GROUNDED[kind], slider=n == "slider")
    engine = kind == "slider-crank" and rng.random() < 0.3
    speed = float(10 ** rng.uniform(1.5, 3.0) if engine else 10 ** rng.uniform(0, 1.5))
    if kind == "slider-crank" and rng.random() < 0.6:
        # peak about 1-5 times the slider's inertia force m·r·ω² (an engine's proportions)
        inertial = links["slider"]["mass"] * link_len["crank"] * speed**2
        links["slider"]["gas_force"] = _gas_force(rng, inertial * rng.uniform(0.2, 1) / 1000)
    speed = _r(speed * _choice(rng, [1, 1, 1, -1]))
    doc["links"] = links
    if rng.random() < 0.92:
        doc["operation"] = {"speed": speed}
        if rng.random() < 0.8:
            doc["operation"]["samples"] = _choice(rng, [8, 12, 36, 90, 360, 360, 361, 720])
    if rng.random() < 0.85:
        revs = rng.uniform(0.2, 2.0)
        sim: dict[str, Any] = {"duration": _r(min(0.6, revs * 2 * math.pi / abs(speed)))}
        if rng.random() < 0.8:
            for _ in range(200):
                sim["theta1"] = _r(rng.uniform(-math.pi, math.pi))
                if rng.random() < 0.15 or assembles_at(kind, lengths, sim["theta1"]):
                    break
        if rng.random() < 0.7:
            sim["omega1"] = _r(speed * rng.uniform(0, 1.2))
        if rng.random() < 0.3:
            sim["gravity"] = _choice(rng, [[0.0, -9.81], [_r(rng.uniform(-10, 10)), 0.0]])
        if rng.random() < 0.7:
            sim["drive"] = _choice(rng, ["free", "constant-speed"])
        if rng.random() < 0.4:
            sim["method"] = _choice(rng, METHODS_BY_TYPE[kind])
        sim["rtol"] = _choice(rng, [1e-6, 1e-8, 1e-8, 1e-10])
        if rng.random() < 0.5:
            sim["atol"] = _choice(rng, [1e-8, 1e-10, 1e-12])
        if rng.random() < 0.7:
            sim["outputs"] = _choice(rng, [2, 3, 50, 201, 501])
        doc["simulation"] = sim
    if balance if balance is not None else rng.random() < 0.4:
        doc["balance"] = _balance(rng, kind, links, link_len)
    if rng.random() < 0.08:
        doc["original"] = {
            n: {**{k: v for k, v in links[n].items() if k != "gas_force"},
                "mass": _r(links[n]["mass"] * 0.8)}
            for n in LINKS_BY_TYPE[kind]
        }
    return doc, f"{kind}/{cls}"


# ----------------------------------------------------------------------------------------------
# Hostile specs


def _leaves(d: Any, path: tuple = ()):
    """``(path, value)`` of every non-table value, list elements included."""
    if isinstance(d, dict):
        for k, v in d.items():
            yield from _leaves(v, (*path, k))
        return
    yield path, d
    if isinstance(d, list):
        for i, x in enumerate(d):
            if not isinstance(x, list | dict):
                yield (*path, i), x


def _tables(d: dict, path: tuple = ()):
    yield path, d
    for k, v in d.items():
        if isinstance(v, dict):
            yield from _tables(v, (*path, k))


def _get(d: Any, path: tuple) -> Any:
    for p in path:
        d = d[p]
    return d


def _set(d: Any, path: tuple, value: Any) -> None:
    _get(d, path[:-1])[path[-1]] = value


def _numeric(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def _dotted(path: tuple) -> str:
    return ".".join(str(p) for p in path)


#: Keys that take a number or a list (or a table).
_POLYMORPHIC = ("mass", "inertia", "counter_rotor", "gas_force")


def _required(path: tuple, kind: str) -> bool:
    """Whether removing the key at ``path`` must be rejected (exit 2)."""
    p = [str(x) for x in path]
    if p in (["mechanism"], ["mechanism", "type"], ["mechanism", "lengths"], ["links"]):
        return True
    if p[:2] == ["mechanism", "lengths"] and len(p) == 3:
        return p[2] != "offset"
    if p[0] in ("links", "original") and len(p) >= 2:
        if len(p) == 2:
            return True
        if p[2] == "mass" or (p[2] == "inertia" and p[1] != "slider"):
            return True
        if p[2] == "com":
            return True
        if p[2] == "gas_force" and len(p) == 4:
            return p[3] in ("crank_angle", "force")
    return p == ["operation", "speed"]


def _mutate_magnitude(rng, doc, kind):
    leaves = [(p, v) for p, v in _leaves(doc) if _numeric(v)]
    path, _ = leaves[int(rng.integers(len(leaves)))]
    value = _choice(rng, [1e300, -1e300, 1e-300, 5e-324, 1.7976931348623157e308, 1e12, -1e12,
                          1e-12, 2**63, -(2**63)])
    _set(doc, path, value)
    return f"{_dotted(path)} = {value!r}", None


def _mutate_wrong_type(rng, doc, kind):
    leaves = list(_leaves(doc))
    path, old = leaves[int(rng.integers(len(leaves)))]
    if isinstance(old, str):
        options = [1.0, True, ["+"], Inline({"a": 1})]
    elif isinstance(old, bool):
        options = [1, "true", [True]]
    elif isinstance(old, list):
        options = ["[1, 2]", 3.0, Inline({"x": 1.0, "y": 2.0}), ["a", "b"], [1.0, 2.0, 3.0], []]
    elif isinstance(old, dict):
        options = [1.0, "table", [1.0]]
    else:
        options = ["1.0", True, [old], Inline({"value": old}), Raw("1979-05-27T07:32:00Z"),
                   Raw("07:32:00"), ""]
    new = _choice(rng, options)
    _set(doc, path, new)
    key = str(path[-1]) if not isinstance(path[-1], int) else str(path[-2])
    poly = key in _POLYMORPHIC and str(path[0]) in ("balance", "links", "original")
    gas_list = "gas_force" in path and isinstance(new, list) and all(map(_numeric, new))
    lenient = gas_list or (poly and (isinstance(new, list | float) or isinstance(old, list)))
    expect = None if lenient else frozenset({2})
    return f"{_dotted(path)}: {type(old).__name__} -> {_value(new)}", expect


def _mutate_missing(rng, doc, kind):
    paths = [p for p, _ in _tables(doc) if p] + [p for p, _ in _leaves(doc)
                                                   if not isinstance(p[-1], int)]
    path = paths[int(rng.integers(len(paths)))]
    del _get(doc, path[:-1])[path[-1]]
    return f"without {_dotted(path)}", frozenset({2}) if _required(path, kind) else None


def _mutate_unknown(rng, doc, kind):
    tables = [p for p, _ in _tables(doc)]
    path = tables[int(rng.integers(len(tables)))]
    name = _choice(rng, ["mas", "masss", "colour", "sigma2", "Mass", "speed ", "ωmega", "x"])
    table = _get(doc, path)
    if name in table:
        name += "_"
    table[name] = _choice(rng, [1.0, "x", True])
    return f"unknown {_dotted((*path, name))}", frozenset({2})


def _mutate_nonpositive(rng, doc, kind):
    targets: list[tuple[tuple, list]] = []
    for p, v in _leaves(doc):
        s = [str(x) for x in p]
        last = s[-1]
        if s[:2] == ["mechanism", "lengths"] and last != "offset":
            targets.append((p, [0.0, -v, -1e-300]))
        elif s[0] in ("links", "original") and last == "mass":
            targets.append((p, [0.0, -v, -0.0]))
        elif s[0] in ("links", "original") and last == "inertia":
            targets.append((p, [-v, -1.0]))  # zero: a point mass (allowed)
        elif last in ("s", "counter_rotor") and s[0] in ("links", "original"):
            targets.append((p, [-1.0, -1e-9]))
        elif s == ["operation", "speed"]:
            targets.append((p, [0.0, -0.0, 0]))
        elif s == ["operation", "samples"]:
            targets.append((p, [0, -1, 7, 360.0, 8.5]))
        elif s == ["simulation", "duration"]:
            targets.append((p, [0.0, -1.0]))
        elif s == ["simulation", "outputs"]:
            targets.append((p, [1, 0, -3, 50.0]))
        elif s == ["simulation", "rtol"]:
            targets.append((p, [0.0, -1e-8, 1.0, 2.0, 1e-15]))
        elif s == ["simulation", "atol"]:
            targets.append((p, [0.0, -1e-10]))
        elif last == "period":
            targets.append((p, [0.0, -6.0]))
        elif s[0] == "balance" and last in ("min_gyration", "com_radius"):
            targets.append((p, [-0.1, -1e-300]))
        elif s[0] == "balance" and len(s) == 3 and s[1] == "objective":
            targets.append((p, [-1.0]))
        elif s[0] == "balance" and last == "mass" and len(s) == 3:
            targets.append((p, [[0.0, 1.0], [-1.0, 2.0], 0.0, [3.0, 1.0]]))
        elif s[0] == "balance" and last in ("inertia", "counter_rotor") and len(s) == 3:
            targets.append((p, [[-1.0, 1.0], -1.0, [2.0, 1.0]]))
    path, values = targets[int(rng.integers(len(targets)))]
    value = _choice(rng, values)
    _set(doc, path, value)
    return f"{_dotted(path)} = {_value(value)}", frozenset({2})


def _mutate_nan(rng, doc, kind):
    leaves = [(p, v) for p, v in _leaves(doc) if _numeric(v)]
    path, _ = leaves[int(rng.integers(len(leaves)))]
    value = _choice(rng, ["nan", "NaN", "inf", "-Infinity", "1e400", Raw("nan"), Raw("-nan"),
                          Raw("inf"), Raw("-inf"), Raw("+inf"), Raw("1e400"), Raw("-1e400")])
    _set(doc, path, value)
    return f"{_dotted(path)} = {_value(value)}", frozenset({2})


def _mutate_no_assembly(rng, doc, kind):
    lengths = doc["mechanism"]["lengths"]
    if kind == "four-bar":
        l1, l2, l3 = lengths["crank"], lengths["coupler"], lengths["rocker"]
        lengths["frame"] = _r((l1 + l2 + l3) * rng.uniform(1.05, 3))
        return "frame longer than the other three together", frozenset({2})
    lengths["offset"] = _r((lengths["crank"] + lengths["rod"]) * rng.uniform(1.05, 3)
                           * _choice(rng, [1, -1]))
    return "guide beyond the reach of crank and rod", frozenset({2})


def _mutate_gas(rng, doc, kind):
    if kind != "slider-crank":
        doc["links"]["crank"]["gas_force"] = 100.0
        return "gas_force on a four-bar's crank", frozenset({2})
    slider = doc["links"]["slider"]
    bad = _choice(rng, ["unsorted", "mismatch", "empty", "beyond", "negative", "crank", "extra"])
    table = {"crank_angle": [0.0, 1.0, 2.0], "force": [-100.0, -50.0, 0.0]}
    if bad == "unsorted":
        table["crank_angle"] = [0.0, 2.0, 1.0]
    elif bad == "mismatch":
        table["force"] = [-100.0, -50.0]
    elif bad == "empty":
        table = {"crank_angle": [], "force": []}
    elif bad == "beyond":
        table["crank_angle"] = [0.0, 1.0, 7.0]
    elif bad == "negative":
        table["crank_angle"] = [-1.0, 1.0, 2.0]
    elif bad == "extra":
        table["phase"] = 1.0
    else:
        doc["links"]["crank"]["gas_force"] = 100.0
        return "gas_force on the crank", frozenset({2})
    slider["gas_force"] = Inline(table)
    return f"gas_force {bad}", frozenset({2})


def _mutate_balance(rng, doc, kind):
    names = LINKS_BY_TYPE[kind]
    bal = doc.setdefault("balance", {})
    bad = _choice(rng, ["lo>hi", "about", "about-alone", "rotor", "gyration", "weights",
                        "nothing", "foreign", "force_balance"])
    name = _choice(rng, names)
    m = doc["links"][name]["mass"]
    if bad == "lo>hi":
        bal[name] = {"mass": [2 * m, m]}
    elif bad == "about":
        bal[name] = {"mass": [m, 2 * m], "com_radius": 1.0, "com_about": "A3" if name != "rocker"
                     else "A0"}
    elif bad == "about-alone":
        bal[name] = {"mass": [m, 2 * m], "com_about": JOINTS[name][0]}
    elif bad == "rotor":
        ungrounded = [n for n in names if n not in GROUNDED[kind]]
        bal[_choice(rng, ungrounded)] = {"counter_rotor": [0.0, 1.0]}
    elif bad == "gyration":
        bal[name] = {"mass": [m, 2 * m], "min_gyration": 10.0, "inertia": [0.0, 1e-6]}
    elif bad == "weights":
        bal["objective"] = {k: 0.0 for k in ("shaking_moment", "driving_torque")}
        bal[name] = {"mass": [m, 2 * m]}
    elif bad == "nothing":
        doc["balance"] = {"force_balance": True}
    elif bad == "foreign":
        other = "rod" if kind == "four-bar" else "coupler"
        bal[other] = {"mass": [1.0, 2.0]}
    else:
        bal["force_balance"] = _choice(rng, ["yes", 1, Raw("1979-05-27")])
        bal[name] = {"mass": [m, 2 * m]}
    return f"[balance] {bad}", frozenset({2})


def _mutate_type(rng, doc, kind):
    doc["mechanism"]["type"] = _choice(rng, ["Four-Bar", "fourbar", "six-bar", "slider", ""])
    return f"mechanism.type = {doc['mechanism']['type']!r}", frozenset({2})


def _mutate_cross_type(rng, doc, kind):
    """Links or lengths of the other mechanism type."""
    other = "slider-crank" if kind == "four-bar" else "four-bar"
    doc["mechanism"]["type"] = other
    return f"{kind} keys under type = {other!r}", frozenset({2})


def _mutate_degenerate(rng, doc, kind):
    """Geometry that assembles but is singular or wildly disparate (no exit code implied)."""
    lengths = doc["mechanism"]["lengths"]
    if kind == "slider-crank":
        r = lengths["crank"]
        which = _choice(rng, ["crank=rod", "crank=rod+offset", "tiny-crank"])
        if which == "crank=rod":
            lengths["rod"] = r
            lengths.pop("offset", None)
        elif which == "crank=rod+offset":
            lengths["rod"] = r
            lengths["offset"] = _r(r * 0.1)
        else:
            lengths["crank"] = r * 1e-9
        return which, None
    which = _choice(rng, ["folded", "tiny-crank", "huge-frame-ratio", "all-equal"])
    if which == "folded":
        lengths.update(crank=1.0, coupler=1.0, rocker=1.0, frame=3.0)
    elif which == "tiny-crank":
        lengths["crank"] = lengths["frame"] * 1e-9
    elif which == "huge-frame-ratio":
        lengths.update(crank=1.0, coupler=1e6, rocker=1e6, frame=1e6)
    else:
        lengths.update(crank=1.0, coupler=1.0, rocker=1.0, frame=1.0)
    return which, None


#: Targeted absurd magnitudes: (name, heavy, function(doc, kind) -> note).
def _scale_lengths(doc, factor):
    for k, v in doc["mechanism"]["lengths"].items():
        doc["mechanism"]["lengths"][k] = v * factor


def _scale_masses(doc, factor):
    for link in doc["links"].values():
        link["mass"] *= factor
        if "inertia" in link:
            link["inertia"] *= factor


def _absurd(rng, doc, kind, *, heavy_ok: bool):
    light = [
        "speed-1e300", "speed-1e-300", "lengths-1e300", "lengths-1e-300", "masses-1e300",
        "masses-1e-300", "slider-mass-1e12", "mass-1e12", "force-1e300", "omega1-1e300",
        "gravity-1e300", "theta1-1e300", "rtol-1e-14", "atol-1e-300", "gas-1e300",
        "rotor-1e300", "samples-8", "outputs-2",
    ]
    heavy = ["samples-1e8", "samples-2e9", "outputs-1e9", "duration-1e9", "duration-1e5"]
    which = _choice(rng, light + (heavy if heavy_ok else []))
    sim = doc.setdefault("simulation", {})
    op = doc.setdefault("operation", {"speed": 10.0})
    if which == "speed-1e300":
        op["speed"] = 1e300
    elif which == "speed-1e-300":
        op["speed"] = 1e-300
    elif which == "lengths-1e300":
        _scale_lengths(doc, 1e300)
    elif which == "lengths-1e-300":
        _scale_lengths(doc, 1e-300)
    elif which == "masses-1e300":
        _scale_masses(doc, 1e300)
    elif which == "masses-1e-300":
        _scale_masses(doc, 1e-300)
    elif which == "slider-mass-1e12":
        name = "slider" if kind == "slider-crank" else "rocker"
        doc["links"][name]["mass"] = 1e12
    elif which == "mass-1e12":
        doc["links"][_choice(rng, LINKS_BY_TYPE[kind])]["mass"] = 1e12
    elif which == "force-1e300":
        doc["links"][_choice(rng, LINKS_BY_TYPE[kind])]["force"] = [1e300, -1e300]
    elif which == "omega1-1e300":
        sim["omega1"] = 1e300
    elif which == "gravity-1e300":
        sim["gravity"] = [0.0, -1e300]
    elif which == "theta1-1e300":
        sim["theta1"] = 1e300
    elif which == "rtol-1e-14":
        sim["rtol"] = 1e-14
    elif which == "atol-1e-300":
        sim["atol"] = 1e-300
    elif which == "gas-1e300":
        if kind == "slider-crank":
            doc["links"]["slider"]["gas_force"] = 1e300
        else:
            doc["links"]["crank"]["moment"] = 1e300
    elif which == "rotor-1e300":
        doc["links"]["crank"]["counter_rotor"] = 1e300
    elif which == "samples-8":
        op["samples"] = 8
    elif which == "outputs-2":
        sim["outputs"] = 2
    elif which == "samples-1e8":
        op["samples"] = 100_000_000
    elif which == "samples-2e9":
        op["samples"] = 2_000_000_000
    elif which == "outputs-1e9":
        sim["outputs"] = 1_000_000_000
    elif which == "duration-1e9":
        sim["duration"] = 1e9
    elif which == "duration-1e5":
        sim["duration"] = 1e5
    return which, which in heavy


SPEC_MUTATIONS = {
    "magnitude": _mutate_magnitude,
    "wrong-type": _mutate_wrong_type,
    "missing-key": _mutate_missing,
    "unknown-key": _mutate_unknown,
    "non-positive": _mutate_nonpositive,
    "nan-like": _mutate_nan,
    "no-assembly": _mutate_no_assembly,
    "gas-force": _mutate_gas,
    "balance": _mutate_balance,
    "mechanism-type": _mutate_type,
    "cross-type": _mutate_cross_type,
    "degenerate": _mutate_degenerate,
}


def _text_mutation(rng, text: str) -> tuple[bytes, str]:
    """Byte-level damage: non-UTF-8, invalid TOML, empty files."""
    which = _choice(rng, ["latin1", "ff", "utf16", "bom", "truncate", "duplicate", "unclosed",
                          "dangling", "double-dot", "empty", "comments", "nul", "array-table",
                          "crlf"])
    raw = text.encode("utf-8")
    if which == "latin1":
        return b'title = "\xf3 \xe9"\n' + raw, which
    if which == "ff":
        i = int(rng.integers(len(raw)))
        return raw[:i] + b"\xff\xfe" + raw[i:], which
    if which == "utf16":
        return text.encode("utf-16"), which
    if which == "bom":
        return b"\xef\xbb\xbf" + raw, which
    if which == "truncate":
        lines = text.splitlines(keepends=True)
        i = int(rng.integers(1, len(lines)))
        cut = lines[i]
        return ("".join(lines[:i]) + cut[: max(1, len(cut) // 2)].rstrip("\n") + " = [").encode(
        ), which
    if which == "duplicate":
        return raw.replace(b"[mechanism]\n", b"[mechanism]\ntype = \"four-bar\"\n", 1), which
    if which == "unclosed":
        return raw.replace(b"[mechanism]", b"[mechanism", 1), which
    if which == "dangling":
        return raw + b"mass =\n", which
    if which == "double-dot":
        return raw + b"\n[operation2]\nspeed = 1.0.0\n", which
    if which == "empty":
        return b"", which
    if which == "comments":
        return b"# nothing but a comment\n", which
    if which == "nul":
        return raw.replace(b"\n", b"\n\x00", 1), which
    if which == "array-table":
        return raw + b"\n[[links]]\nmass = 1.0\n", which
    return raw.replace(b"\n", b"\r\r\n"), which


# ----------------------------------------------------------------------------------------------
# Command lines


def _out_path(rng, stem: str, ext: str, *, hostile: bool) -> tuple[str, str]:
    """An output path and its kind (``ok`` unless ``hostile``)."""
    if not hostile:
        return f"out/{stem}{ext}", "ok"
    kind = _choice(rng, ["missing", "readonly", "spec", "dir", "dir-slash", "empty",
                         "file-parent", "nested-missing", "ok"])
    return {
        "missing": f"missing/{stem}{ext}",
        "readonly": f"ro/{stem}{ext}",
        "spec": SPEC,
        "dir": "adir",
        "dir-slash": "out/",
        "empty": "",
        "file-parent": f"{SPEC}/{stem}{ext}",
        "nested-missing": f"out/a/b/{stem}{ext}",
        "ok": f"out/{stem}{ext}",
    }[kind], kind


#: Exit codes an output path decides.
_PATH_EXPECT = {
    "missing": frozenset({2}),
    "nested-missing": frozenset({2}),
    "dir": frozenset({2}),
    "dir-slash": frozenset({2}),
    "file-parent": frozenset({2}),
    "readonly": frozenset({1, 2}),
}

_BAD_FLOATS = ["0", "-1", "nan", "NaN", "inf", "-inf", "1e400", "abc", "", "1,5", "0x10"]
_BAD_COUNTS = ["1", "0", "-5", "1e3", "2.5", "", "many"]


def _merge(a: frozenset[int] | None, b: frozenset[int] | None) -> frozenset[int] | None:
    if a is None or b is None:
        return a if b is None else b
    return (a & b) or (a | b)


@dataclass
class _Cmd:
    argv: list[str]
    outputs: list[str] = field(default_factory=list)
    expect: frozenset[int] | None = None
    notes: list[str] = field(default_factory=list)
    heavy: bool = False

    def add_output(self, option: str, path: str, kind: str) -> None:
        self.argv += [option, path]
        if path:
            self.outputs.append(path)
        if kind != "ok":
            self.notes.append(f"{option} {kind}")
        self.expect = _merge(self.expect, _PATH_EXPECT.get(kind))

    def bad_value(self, option: str, value: str) -> None:
        self.argv += [option, value]
        self.notes.append(f"{option} {value!r}")
        self.expect = _merge(self.expect, frozenset({2}))


def _short_duration(rng, doc: dict | None) -> str:
    speed = 10.0
    try:
        speed = abs(float(doc["operation"]["speed"]))  # type: ignore[index]
        if not 1e-3 < speed < 1e4:
            speed = 10.0
    except (KeyError, TypeError, ValueError):
        pass
    return f"{min(0.5, rng.uniform(0.1, 1.5) * 2 * math.pi / speed):.3g}"


def _mechanism_type(doc: Any) -> str | None:
    try:
        kind = doc["mechanism"]["type"]
    except (KeyError, TypeError, IndexError):
        return None
    return kind if isinstance(kind, str) and kind in METHODS_BY_TYPE else None


def command(rng: np.random.Generator, verb: str, doc: dict | None, *, hostile: bool,
            cheap: bool) -> _Cmd:
    """A command line for ``verb`` on ``spec.toml``; ``hostile`` damages one option or path."""
    kind = _mechanism_type(doc)
    has_sim = isinstance(doc, dict) and isinstance(doc.get("simulation"), dict)
    cmd = _Cmd([verb, SPEC])
    want_bad_value = hostile and rng.random() < 0.5
    want_bad_path = hostile and not want_bad_value

    def maybe(p: float) -> bool:
        return bool(rng.random() < p)

    if verb == "analyze":
        if maybe(0.6):
            cmd.argv.append("--json")
        if maybe(0.4) or want_bad_path:
            ext = _choice(rng, [".csv", ".csv", ".txt", ""])
            cmd.add_output("--csv", *_out_path(rng, "cycle", ext, hostile=want_bad_path))
        if maybe(0.4):
            cmd.argv += ["--route", _choice(rng, ["newton-euler", "mass-matrix"])]
        if want_bad_value:
            cmd.bad_value("--route", _choice(rng, ["lagrange", "", "NEWTON-EULER"]))
    elif verb == "simulate":
        if maybe(0.4):
            methods = METHODS_BY_TYPE.get(kind or "", METHODS)
            method = _choice(rng, methods if maybe(0.9) else METHODS)
            cmd.argv += ["--method", method]
            if method not in methods:
                cmd.notes.append(f"--method {method} on a {kind}")
                cmd.expect = _merge(cmd.expect, frozenset({2}))
        if maybe(0.4):
            cmd.argv += ["--drive", _choice(rng, ["free", "constant-speed"])]
        if maybe(0.6) or not has_sim:
            cmd.argv += ["--duration", _short_duration(rng, doc)]
        if maybe(0.3):
            cmd.argv += ["--rtol", _choice(rng, ["1e-6", "1e-8", "1e-10"])]
        if maybe(0.2):
            cmd.argv += ["--atol", _choice(rng, ["1e-8", "1e-12"])]
        if maybe(0.3):
            cmd.argv += ["--outputs", str(_choice(rng, [2, 3, 11, 101]))]
        if maybe(0.4) or want_bad_path:
            ext = _choice(rng, [".csv", ".csv", ".txt"])
            cmd.add_output("--out", *_out_path(rng, "history", ext, hostile=want_bad_path))
            if maybe(0.3):
                cmd.argv.append("--all-columns")
        if maybe(0.6):
            cmd.argv.append("--json")
        if want_bad_value:
            option = _choice(rng, ["--duration", "--rtol", "--atol", "--outputs", "--method",
                                   "--drive", "absurd"])
            if option == "absurd":
                absurd = ["--rtol", "1e-300"], ["--atol", "1e-300"], ["--duration", "1e-300"]
                big = ["--duration", "1e9"], ["--outputs", "1000000000"], ["--outputs", "10000000"]
                args = _choice(rng, list(absurd) + ([] if cheap else list(big)))
                cmd.argv += args
                cmd.notes.append(" ".join(args))
                cmd.heavy = args in big
            elif option == "--outputs":
                cmd.bad_value(option, _choice(rng, _BAD_COUNTS))
            elif option in ("--method", "--drive"):
                cmd.bad_value(option, _choice(rng, ["euler", "", "Free"]))
            else:
                cmd.bad_value(option, _choice(rng, _BAD_FLOATS))
    elif verb == "verify":
        if maybe(0.3) or want_bad_path:
            ext = _choice(rng, [".png", ".svg", ".png", ".pdf", ".txt", ""])
            cmd.add_output("--plot", *_out_path(rng, "reactions", ext, hostile=want_bad_path))
        if maybe(0.85) or not has_sim:
            cmd.argv += ["--duration", _short_duration(rng, doc)]
        if maybe(0.3):
            methods = METHODS_BY_TYPE.get(kind or "", METHODS)
            cmd.argv += ["--method", _choice(rng, methods)]
        if maybe(0.6):
            cmd.argv.append("--json")
        if want_bad_value:
            option = _choice(rng, ["--duration", "--method"])
            cmd.bad_value(option, _choice(rng, _BAD_FLOATS if option == "--duration"
                                          else ["euler", ""]))
    elif verb == "optimize":
        if maybe(0.4) or want_bad_path:
            cmd.add_output("--out", *_out_path(rng, "balanced", ".toml", hostile=want_bad_path))
        if maybe(0.5):
            cmd.argv += ["--backend", _choice(rng, ["nlp", "convex"])]
        if maybe(0.6):
            cmd.argv.append("--json")
        if maybe(0.8 if cheap else 0.5):
            cmd.argv.append("--no-verify")
        elif maybe(0.85) or not has_sim:
            cmd.argv += ["--verify-duration", _short_duration(rng, doc)]
        if want_bad_value:
            option = _choice(rng, ["--verify-duration", "--backend"])
            cmd.bad_value(option, _choice(rng, _BAD_FLOATS if option != "--backend"
                                          else ["cvxpy", "", "NLP"]))
    elif verb == "plot":
        if maybe(0.9) or want_bad_path:
            ext = _choice(rng, [".gif", ".gif", ".gif", ".mp4", ".png", ".txt"])
            cmd.add_output("--animate", *_out_path(rng, "anim", ext, hostile=want_bad_path))
        else:
            cmd.expect = _merge(cmd.expect, frozenset({2}))
        cmd.argv += ["--frames", str(_choice(rng, [2, 4, 6, 8] if cheap else [2, 6, 12, 24]))]
        if want_bad_value:
            cmd.bad_value("--frames", _choice(rng, _BAD_COUNTS))
    return cmd


def _odd_command(rng) -> _Cmd:
    """Command lines that are wrong or unusual as a whole."""
    which = _choice(rng, ["none", "unknown-verb", "unknown-option", "help", "verb-help",
                          "version", "missing-spec", "dir-spec", "empty-spec", "two-specs",
                          "dash-spec", "unreadable"])
    table = {
        "none": ([], {2}),
        "unknown-verb": (["balance", SPEC], {2}),
        "unknown-option": (["analyze", SPEC, "--bogus"], {2}),
        "help": (["--help"], {0}),
        "verb-help": ([_choice(rng, VERBS), "--help"], {0}),
        "version": (["--version"], None),
        "missing-spec": ([_choice(rng, VERBS[:4]), "nope.toml"], {2}),
        "dir-spec": ([_choice(rng, VERBS[:4]), "adir"], {2}),
        "empty-spec": (["analyze", ""], {2}),
        "two-specs": (["analyze", SPEC, SPEC], {2}),
        "dash-spec": (["analyze", "-"], {2}),
        "unreadable": (["analyze", SPEC], {2}),
    }
    argv, expect = table[which]
    cmd = _Cmd(list(argv), expect=frozenset(expect) if expect is not None else None)
    cmd.notes.append(which)
    return cmd


# ----------------------------------------------------------------------------------------------
# Cases


def _expect_for_valid(verb: str, doc: dict, cls: str) -> frozenset[int] | None:
    """Exit codes a valid spec decides for ``verb``."""
    kind, _, sub = cls.partition("/")
    full = sub in FULL_TURN if kind == "four-bar" else sub in ("in-line", "offset")
    if verb in ("analyze", "optimize", "verify"):
        if "operation" not in doc:
            return frozenset({2})
        if not full and sub != "crank-near-rod":
            return frozenset({2})
    if verb == "optimize" and "balance" not in doc:
        return frozenset({2})
    return None


def _number(doc: Any, *path: str) -> float:
    try:
        v = _get(doc, path)
    except (KeyError, TypeError, IndexError):
        return 0.0
    return abs(float(v)) if _numeric(v) else 0.0


def heavy_doc(doc: Any, verb: str) -> bool:
    """Whether a correct tool may take long on this spec (absurd sizes or durations)."""
    samples = _number(doc, "operation", "samples")
    if samples > 1e6 and verb in ("analyze", "optimize", "verify"):
        return True
    if verb in ("simulate", "verify", "optimize"):
        duration = _number(doc, "simulation", "duration")
        speed = max(_number(doc, "simulation", "omega1"), _number(doc, "operation", "speed"))
        if duration > 10 or _number(doc, "simulation", "outputs") > 1e6:
            return True
        if speed * max(duration, 1.0) > 1e5:
            return True
    return False


_VERB_WEIGHTS = {
    "full": {"analyze": 0.3, "simulate": 0.25, "optimize": 0.2, "verify": 0.15, "plot": 0.1},
    "cheap": {"analyze": 0.4, "simulate": 0.25, "optimize": 0.17, "verify": 0.13, "plot": 0.05},
}


GROUPS = ("valid", "spec", "absurd", "text", "cmd", "odd")


def make_case(seed: int, index: int, profile: str = "full", group: str | None = None) -> Case:
    """Case number ``index`` of the campaign with ``seed``.

    ``profile``: ``full`` or ``cheap`` (no absurd sizes, fewer expensive options); ``group``
    forces one of :data:`GROUPS` (valid spec and command; damaged spec, absurd magnitudes,
    damaged bytes; damaged command line, odd command line).
    """
    rng = np.random.default_rng(np.random.SeedSequence([seed, index]))
    cheap = profile == "cheap"
    weights = _VERB_WEIGHTS[profile]
    verb = str(rng.choice(list(weights), p=list(weights.values())))
    drawn = _choice(rng, ["valid"] * 45 + ["spec"] * 30 + ["absurd"] * 8 + ["text"] * 5
                    + ["cmd"] * 9 + ["odd"] * 3)
    group = group or drawn
    doc, cls = valid_spec(rng, balance=(verb == "optimize" and rng.random() < 0.9) or None)
    kind = doc["mechanism"]["type"]
    notes: list[str] = []
    heavy = False
    expect: frozenset[int] | None = None
    spec_mode = 0o644
    if group == "spec":
        name = _choice(rng, list(SPEC_MUTATIONS))
        note, expect = SPEC_MUTATIONS[name](rng, doc, kind)
        notes.append(note)
        label = f"spec/{name}"
        spec = to_toml(doc).encode()
    elif group == "absurd":
        note, heavy = _absurd(rng, doc, kind, heavy_ok=not cheap and rng.random() < 0.35)
        notes.append(note)
        label = f"absurd/{note}"
        spec = to_toml(doc).encode()
    elif group == "text":
        spec, note = _text_mutation(rng, to_toml(doc))
        notes.append(note)
        label = f"text/{note}"
        # Line ends and a byte-order mark (as Windows editors write them) are not content: the
        # spec reads as without them (balancer.spec decodes "utf-8-sig").
        expect = None if note in ("crlf", "bom") else frozenset({2})
    else:
        label = f"valid/{cls}"
        spec = to_toml(doc).encode()
        expect = _expect_for_valid(verb, doc, cls)
    if group != "valid" and heavy_doc(doc, verb):
        heavy = True
        if cheap:  # keep the cheap profile cheap: the same case without its damage
            doc, cls = valid_spec(np.random.default_rng([seed, index, 1]), kind=kind)
            group, label, expect, spec = "valid", f"valid/{cls}", None, to_toml(doc).encode()
            notes, heavy = [], False
    if group == "odd":
        cmd = _odd_command(rng)
        label = f"odd/{cmd.notes[0]}"
        expect = cmd.expect
        if cmd.notes[0] == "unreadable":
            spec_mode = 0
    else:
        cmd = command(rng, verb, doc, hostile=group == "cmd", cheap=cheap)
        if group == "cmd":
            label = f"cmd/{verb}"
            expect = _merge(_expect_for_valid(verb, doc, cls), cmd.expect)
        elif cmd.expect is not None:
            expect = _merge(expect, cmd.expect)
    return Case(
        seed=seed,
        index=index,
        kind=label,
        verb=cmd.argv[0] if cmd.argv else "",
        spec=spec,
        argv=tuple(cmd.argv),
        expect=expect,
        outputs=tuple(cmd.outputs),
        heavy=heavy or cmd.heavy,
        spec_mode=spec_mode,
        notes=tuple(notes + cmd.notes),
    )


def prepare_workdir(case: Case, folder: str | os.PathLike[str]) -> Path:
    """Lay out the work folder of ``case`` (see the module docstring); returns it."""
    root = Path(folder)
    root.mkdir(parents=True, exist_ok=True)
    (root / "out").mkdir(exist_ok=True)
    (root / "adir").mkdir(exist_ok=True)
    ro = root / "ro"
    ro.mkdir(exist_ok=True)
    ro.chmod(stat.S_IRUSR | stat.S_IXUSR | stat.S_IRGRP | stat.S_IXGRP | stat.S_IROTH
             | stat.S_IXOTH)
    spec = root / SPEC
    spec.write_bytes(case.spec)
    spec.chmod(case.spec_mode)
    return root


def release_workdir(folder: str | os.PathLike[str]) -> None:
    """Make a work folder removable again (undo the read-only parts)."""
    root = Path(folder)
    for p in (root / "ro", root / SPEC):
        if p.exists():
            p.chmod(0o755 if p.is_dir() else 0o644)


# ----------------------------------------------------------------------------------------------
# Directed cases: known suspects, one command each


def _paper(balance: bool = True) -> dict[str, Any]:
    """Meijaard & van der Wijk's four-bar (Eq. 56) with PB1's redesign problem."""
    doc: dict[str, Any] = {
        "mechanism": {"type": "four-bar", "branch": "+",
                      "lengths": {"crank": 1.0, "coupler": 3.0, "rocker": 2.0, "frame": 3.2}},
        "links": {
            "crank": {"mass": 2.1, "inertia": 1.1, "com": {"s": 0.6, "sigma": 0.3}},
            "coupler": {"mass": 3.0, "inertia": 3.1, "com": {"s": 1.45, "sigma": 0.4}},
            "rocker": {"mass": 2.2, "inertia": 2.1, "com": {"s": 1.66, "sigma": -0.4}},
        },
        "operation": {"speed": 10.0, "samples": 360},
        "simulation": {"duration": 0.3, "theta1": 1.0, "omega1": 1.0, "drive": "free"},
    }
    if balance:
        doc["balance"] = {
            "force_balance": True,
            "objective": {"shaking_moment": 1.0},
            "crank": {"mass": [2.1, 8.4], "com_radius": 1.0, "min_gyration": 0.1,
                      "counter_rotor": [0.0, 20.0]},
            "rocker": {"mass": [2.2, 8.8], "com_radius": 2.0, "min_gyration": 0.2,
                       "counter_rotor": [0.0, 20.0]},
        }
    return doc


def _engine(balance: bool = True) -> dict[str, Any]:
    """A slider-crank like ``examples/engine.toml`` (no gas force)."""
    doc: dict[str, Any] = {
        "mechanism": {"type": "slider-crank", "branch": "+",
                      "lengths": {"crank": 0.02, "rod": 0.085, "offset": 0.0}},
        "links": {
            "crank": {"mass": 0.9, "inertia": 4.5e-4, "com": {"e": -0.004, "f": 0.0}},
            "rod": {"mass": 0.07, "inertia": 4.2e-5, "com": {"e": 0.025, "f": 0.0}},
            "slider": {"mass": 0.06, "com": {"e": 0.004, "f": 0.0}},
        },
        "operation": {"speed": 100.0, "samples": 360},
        "simulation": {"duration": 0.1, "theta1": 0.0, "omega1": 100.0,
                       "drive": "constant-speed"},
    }
    if balance:
        doc["balance"] = {
            "force_balance": False,
            "objective": {"shaking_moment": 0.0, "shaking_force_x": 1.0, "shaking_force_y": 1.0},
            "crank": {"mass": [0.9, 1.4], "com_radius": 0.03, "min_gyration": 0.015},
        }
    return doc


def _edit(doc: dict[str, Any], **paths: Any) -> dict[str, Any]:
    """A deep copy of ``doc`` with dotted keys (``a__b__c``) set."""
    out = json.loads(json.dumps(doc))
    for dotted, value in paths.items():
        keys = dotted.split("__")
        table = out
        for k in keys[:-1]:
            table = table.setdefault(k, {})
        table[keys[-1]] = value
    return out


#: A spec whose optimisation reports a NaN objective for its tie-break stage.
_TIE_BREAK_NAN = """
[mechanism]
type = "four-bar"
[mechanism.lengths]
crank = 1.964
coupler = 6.273
rocker = 4.111
frame = 5.368
[links.crank]
mass = 0.128
inertia = 0.05188
com = { s = 1.707, sigma = -1.988 }
[links.coupler]
mass = 3.947
inertia = 3.535
com = { s = 2.385, sigma = 1.379 }
[links.rocker]
mass = 3.094
inertia = 1.324
com = { e = 1.749, f = -0.5326 }
[operation]
speed = 1.713
[balance.objective]
shaking_moment = 0.5
shaking_force_y = 0.1215
[balance.crank]
mass = [0.128, 5.12]
com_radius = 2.117
counter_rotor = [0.0, 1.009]
[balance.rocker]
mass = [3.094, 123.8]
com_radius = 7.585
com_about = "A2"
min_gyration = 0.3087
"""


def directed_cases(seed: int = 0) -> list[Case]:
    """One case per suspect of the fuzzing brief, plus the output-path suspects per verb."""
    paper, engine = _paper(), _engine()
    crank_rod = _edit(engine, mechanism__lengths={"crank": 0.05, "rod": 0.05, "offset": 0.0})
    change_point = _edit(_paper(balance=False),
                         mechanism__lengths={"crank": 1.0, "coupler": 2.0, "rocker": 1.0,
                                             "frame": 2.0})
    # PB2's optimum as optimize writes it (shaking moment zero): optimising it again
    balanced = _edit(
        paper,
        links__crank={"mass": 2.4912078312256667, "inertia": 1.1, "counter_rotor":
                      6.082415661761015, "com": {"e": -0.9999999999084436,
                                                 "f": 4.481419992398072e-14}},
        links__coupler={"mass": 3.0, "inertia": 3.8025211073079515,
                        "com": {"e": 0.5087921690024193, "f": 1.1164148580073467e-13}},
        links__rocker={"mass": 2.2, "inertia": 0.08800000019178533, "counter_rotor":
                       2.5938404420484464, "com": {"e": 2.462538335456745,
                                                   "f": 1.0149225981884958e-13}},
        balance__coupler={"mass": [3.0, 12.0], "com_radius": 3.0, "com_about": "A1",
                          "min_gyration": 0.3},
    )
    tie_break = tomllib.loads(_TIE_BREAK_NAN)
    items: list[tuple[str, dict, list[str], frozenset[int] | None]] = []
    for folder, note in (("ro", "read-only folder"), ("missing", "missing folder")):
        exp = frozenset({1, 2}) if folder == "ro" else frozenset({2})
        items += [
            (f"analyze --csv in a {note}", paper, ["analyze", SPEC, "--csv", f"{folder}/c.csv"],
             exp),
            (f"simulate --out in a {note}", paper,
             ["simulate", SPEC, "--out", f"{folder}/h.csv"], exp),
            (f"optimize --out in a {note}", paper,
             ["optimize", SPEC, "--no-verify", "--out", f"{folder}/b.toml"], exp),
            (f"verify --plot in a {note}", paper,
             ["verify", SPEC, "--duration", "0.1", "--plot", f"{folder}/r.png"], exp),
            (f"plot --animate in a {note}", paper,
             ["plot", SPEC, "--frames", "4", "--animate", f"{folder}/a.gif"], exp),
        ]
    items += [
        ("samples = 1e8", _edit(paper, operation__samples=100_000_000),
         ["analyze", SPEC, "--json"], None),
        ("simulate --outputs 1e9", paper,
         ["simulate", SPEC, "--json", "--outputs", "1000000000"], None),
        ("simulation.outputs = 1e9", _edit(paper, simulation__outputs=1_000_000_000),
         ["simulate", SPEC, "--json"], None),
        ("slider-crank crank = rod: analyze", crank_rod, ["analyze", SPEC, "--json"], None),
        ("slider-crank crank = rod: simulate", crank_rod,
         ["simulate", SPEC, "--json", "--duration", "0.1"], None),
        ("slider-crank crank = rod: optimize", crank_rod,
         ["optimize", SPEC, "--json", "--no-verify"], None),
        ("speed = 1e300: analyze", _edit(paper, operation__speed=1e300),
         ["analyze", SPEC, "--json"], None),
        ("speed = 1e300: optimize", _edit(paper, operation__speed=1e300),
         ["optimize", SPEC, "--json", "--no-verify"], None),
        ("lengths x 1e300: analyze",
         _edit(paper, mechanism__lengths={"crank": 1e300, "coupler": 3e300, "rocker": 2e300,
                                          "frame": 3.2e300}), ["analyze", SPEC, "--json"], None),
        ("lengths x 1e300: optimize",
         _edit(paper, mechanism__lengths={"crank": 1e300, "coupler": 3e300, "rocker": 2e300,
                                          "frame": 3.2e300}),
         ["optimize", SPEC, "--json", "--no-verify"], None),
        ("masses 1e300: analyze",
         _edit(paper, links__crank__mass=1e300, links__coupler__mass=1e300,
               links__rocker__mass=1e300), ["analyze", SPEC, "--json"], None),
        ("masses 1e300: optimize",
         _edit(paper, links__crank__mass=1e300, links__coupler__mass=1e300,
               links__rocker__mass=1e300, balance__crank__mass=[1e300, 4e300],
               balance__rocker__mass=[1e300, 4e300]),
         ["optimize", SPEC, "--json", "--no-verify"], None),
        ("objective zero on the feasible set (tie): nlp",
         _edit(paper, balance__objective={"shaking_moment": 0.0, "shaking_force": 1.0}),
         ["optimize", SPEC, "--json", "--no-verify"], None),
        ("objective zero on the feasible set (tie): convex",
         _edit(paper, balance__objective={"shaking_moment": 0.0, "shaking_force": 1.0}),
         ["optimize", SPEC, "--json", "--no-verify", "--backend", "convex"], None),
        ("objective added_mass only",
         _edit(paper, balance__objective={"shaking_moment": 0.0, "added_mass": 1.0}),
         ["optimize", SPEC, "--json", "--no-verify"], None),
        ("slider mass 1e12: optimize convex", _edit(engine, links__slider__mass=1e12),
         ["optimize", SPEC, "--json", "--no-verify", "--backend", "convex"], None),
        ("slider mass 1e12: optimize nlp", _edit(engine, links__slider__mass=1e12),
         ["optimize", SPEC, "--json", "--no-verify"], None),
        ("slider mass 1e12, force balance: optimize",
         _edit(engine, links__slider__mass=1e12, balance__force_balance=True,
               balance__rod={"mass": [0.07, 1.0], "com_radius": 0.1}),
         ["optimize", SPEC, "--json", "--no-verify"], None),
        ("lie-group driven through a change point", _edit(change_point, simulation__omega1=10.0),
         ["simulate", SPEC, "--json", "--method", "lie-group", "--drive", "constant-speed",
          "--duration", "1.0"], None),
        ("lie-group free through a change point", _edit(change_point, simulation__omega1=10.0),
         ["simulate", SPEC, "--json", "--method", "lie-group", "--duration", "1.0"], None),
        ("complex-masses driven through a change point", change_point,
         ["simulate", SPEC, "--json", "--method", "complex-masses", "--drive",
          "constant-speed", "--duration", "1.0"], None),
        ("verify a change-point linkage (lie-group)", change_point,
         ["verify", SPEC, "--json", "--method", "lie-group", "--duration", "1.0"], None),
        ("--out equal to the input spec", paper, ["optimize", SPEC, "--no-verify", "--out", SPEC],
         None),
        ("simulate --out equal to the input spec", paper, ["simulate", SPEC, "--out", SPEC],
         None),
        ("--out an existing folder", paper, ["simulate", SPEC, "--out", "adir"],
         frozenset({2})),
        ("--out ''", paper, ["simulate", SPEC, "--out", ""], None),
        ("tie-break stage objective NaN (found by the hypothesis tests)", tie_break,
         ["optimize", SPEC, "--json", "--no-verify", "--out", "out/balanced.toml"], None),
        ("optimize a completely balanced design (PB2's own optimum)", balanced,
         ["optimize", SPEC, "--json", "--no-verify"], None),
        ("optimize a completely balanced design, convex", balanced,
         ["optimize", SPEC, "--json", "--no-verify", "--backend", "convex"], None),
    ]
    cases = []
    for i, (name, doc, argv, expect) in enumerate(items):
        cases.append(Case(seed=seed, index=i, kind=f"directed/{name}", verb=argv[0],
                          spec=to_toml(doc).encode(), argv=tuple(argv), expect=expect,
                          heavy="1e8" in name or "1e9" in name, notes=(name,)))
    return cases
