"""The spec schema (balancer/spec/schema.py): the reader's and the docs' one list of keys.

Every entry is accepted by the reader for the mechanisms it names and refused for the others;
the reader declares no key of its own and reads none that has no entry; an unknown key is
refused in every table; and the schema agrees with the model's own names.
"""

from __future__ import annotations

import ast
import copy
import dataclasses
import os
import tempfile
import tomllib
from pathlib import Path

import pytest

from balancer.errors import SpecError
from balancer.formulations import GENERAL
from balancer.mechanisms import FOLDERS, mechanism_class
from balancer.mechanisms.engine.model import Engine
from balancer.mechanisms.fourbar.model import FourBar
from balancer.mechanisms.slidercrank.model import SliderCrank
from balancer.model import Linkage, Operation, SimulationSettings
from balancer.model.balance import (
    COUNTERWEIGHT_KEYS,
    ENGINE_OBJECTIVE_KEYS,
    LINK_KEYS,
    OBJECTIVE_KEYS,
    CounterweightPlanes,
    Objective,
    ShaftFreedom,
)
from balancer.model.motions import MotionSpec
from balancer.spec import MECHANISM_TYPES, design_from_dict, schema
from balancer.spec.tables import Table

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "balancer" / "spec"
CLASSES = {schema.FOUR_BAR: FourBar, schema.SLIDER_CRANK: SliderCrank, schema.LINKAGE: Linkage,
           schema.ENGINE: Engine}

#: A shipped example of each mechanism: the spec each key is written into.
BASES = {schema.FOUR_BAR: "pb1", schema.SLIDER_CRANK: "engine", schema.LINKAGE: "quick_return",
         schema.ENGINE: "inline_four"}
#: The link a pattern's ``<link>`` is in each base: the crank, but where a gas force goes.
SLIDER = ("links.<link>.gas_force", ("links.<link>", "gas_force"))
#: Values that depend on the base's names (points, links) or must come whole.
SPRING = {"points": ["D", "A0"], "stiffness": 100.0, "free_length": 0.3}
#: A geared crankshaft for the base engine (its cylinders stay on the first), and a wheel the
#: base linkage's crank turns by a gear pair.
TWIN = {"at": [0.2, 0.0], "masses": [{"mr": 0.01, "phase_deg": 0.0, "z": 0.0}]}
WHEEL = {"points": ["W0", "W1"], "mass": 1.0, "inertia": 0.01, "com": {"e": 0.0, "f": 0.0}}
GEAR = {"name": "mesh", "driver": "crank", "driven": "wheel", "ratio": -1.0}
#: A motion of the one-input base linkage: its crank's own waypoints.
MOTION = {"name": "turn", "times": [0.0, 1.0], "path": [[0.0], [0.1]]}
METHOD = {schema.FOUR_BAR: "complex-masses", schema.SLIDER_CRANK: "complex-masses",
          schema.LINKAGE: "multibody", schema.ENGINE: "multibody"}
#: An engine's ``[balance]`` for its keys to stand in: its required keys only.
ENGINE_BALANCE = {"objective": {}, "counterweights": {"max_mr": 0.03},
                  "shafts": [{"ratio": -1, "planes": [0.1], "max_mr": 0.01}]}
#: A part of each family, for a key of a counterweight's ``part`` to stand in.
PARTS = {
    "ring": {"shape": "ring", "outer_radius": 0.1, "thickness": 0.05},
    "sector": {"shape": "sector", "outer_radius": 0.1, "angle_deg": 90.0, "thickness": 0.05},
    "block": {"shape": "block", "length": 0.04, "width": 0.1, "thickness": 0.05},
    "insert": {"shape": "insert", "radius": 0.02, "thickness": 0.01,
               "material": "tungsten-alloy", "host": "steel", "host_density": 7850.0},
    "washers": {"shape": "washers", "size": "M12", "thickness": 0.05},
}
#: The centre of mass's partner keys (``s`` with ``sigma``, ``e`` with ``f``).
PARTNER = {"s": ("sigma", 0.3), "sigma": ("s", 0.6), "e": ("f", 0.0), "f": ("e", 0.4)}


def base(mechanism: str) -> dict:
    return tomllib.loads((ROOT / "examples" / f"{BASES[mechanism]}.toml").read_text())


def original_of(data: dict) -> dict:
    """``[original]`` for a base: its links' mass properties as they are (an engine's
    crankshaft with its masses, and its balance shafts)."""
    keep = ("mass", "inertia", "com", "masses")
    out = {name: {k: copy.deepcopy(v) for k, v in link.items() if k in keep}
           for name, link in data["links"].items() if name != "ground"}
    for name in ("balance_shafts", "crankshafts"):
        if name in data:
            out[name] = copy.deepcopy(data[name])
    return out


def path_of(data: dict, pattern: str, key: str) -> list:
    """The concrete path of a pattern's table in a base, for writing ``key`` into it."""
    slider = "slider" in data["links"] and (pattern in SLIDER or (pattern, key) in SLIDER)
    link = "slider" if slider else "crank"
    if "crankshaft" in data["links"]:  # an engine: the link that takes the key
        link = next((name for name, keys in schema.ENGINE_LINKS.items()
                     if key in keys and pattern in ("links.<link>", "original.<link>")), "rod")
        if pattern.startswith(("links.<link>.masses", "original.<link>.masses")):
            link = "crankshaft"
    out: list = []
    for part in pattern.split(".") if pattern else []:
        if part == "<link>":
            out.append(link)
        elif part.endswith("[]"):
            out += [part[:-2], 0]
        else:
            out.append(part)
    return out


def variant(mechanism: str, section: schema.Section, key: schema.Key | None,
            name: str) -> dict:
    """The base of ``mechanism`` with ``name`` (the entry ``key``, or an unknown key) written in.

    The rest of the table is made what the key needs to stand in it (its partner in a centre
    of mass, a link's original beside it, a counterweight's table alone).
    """
    data = base(mechanism)
    pattern = section.pattern
    if mechanism == schema.ENGINE and ("crankshafts" in pattern or name == "crankshafts" or (
            pattern == "mechanism.cylinders[]" and name == "crankshaft")):
        data["crankshafts"] = [copy.deepcopy(TWIN)]  # (a twin has no main bearings' planes)
        data["mechanism"].pop("main_bearings", None)
        if name == "crankshaft":  # (cylinder 1 moved to it: its firings are its own)
            data.pop("gas")
            data["mechanism"].pop("firing_order")
    if mechanism == schema.LINKAGE and (pattern.startswith("mechanism.gears")
                                        or (pattern == "mechanism" and name == "gears")):
        data["mechanism"]["points"] |= {"W0": [0.3, 0.0], "W1": [0.35, 0.0]}
        data["links"]["ground"]["points"].append("W0")
        data["links"]["wheel"] = copy.deepcopy(WHEEL)
        data["mechanism"]["gears"] = [dict(GEAR)]
    if pattern.startswith("original") or (pattern == "" and name == "original"):
        data["original"] = original_of(data)
    if pattern.startswith("springs") or (pattern == "" and name == "springs"):
        data["springs"] = [dict(SPRING)]
    weighing = mechanism == schema.LINKAGE and (
        pattern == "balance.motions" or (pattern == "balance" and name == "motions"))
    if pattern.startswith("motion") or (pattern == "" and name == "motion") or weighing:
        data["motion"] = [copy.deepcopy(MOTION)]
    if pattern.startswith("workspace") or (pattern == "" and name == "workspace"):
        data["workspace"] = {"crank": [-0.5, 0.5]}
    if pattern == "balance.<link>.counterweight":
        data["balance"]["crank"] = {"counterweight": {"mass": [0.0, 1.0], "radius": 0.1}}
    if pattern == "balance.<link>.counterweight.part":  # a part of a family that takes the key
        family = next((f for f, part in PARTS.items() if name in part), "ring")
        data["balance"]["crank"] = {"counterweight": {"mass": [0.0, 1.0], "radius": 0.1,
                                                      "part": dict(PARTS[family])}}
    if pattern == "balance.<link>" and name == "counterweight":
        data["balance"]["crank"] = {}
    if mechanism == schema.ENGINE and "balance" not in data and (
            pattern.startswith("balance") or (pattern == "" and name == "balance")):
        data["balance"] = copy.deepcopy(ENGINE_BALANCE)
    if pattern == "balance.counterweights.part":  # an engine's crank-web sector
        data["balance"]["counterweights"]["part"] = dict(PARTS["sector"])
    if pattern == "links.<link>.gas_force":
        data["links"]["slider"]["gas_force"] = {"crank_angle": [0.0, 3.0], "force": [-1.0, 0.0]}
    if pattern == "mechanism" and name == "inputs" and "input" in data["mechanism"]:
        data["mechanism"]["inputs"] = [data["mechanism"].pop("input")]  # its other spelling
        return data
    if pattern.startswith("plan") or (pattern == "" and name == "plan"):
        if mechanism in (schema.LINKAGE, schema.FOUR_BAR, schema.SLIDER_CRANK):
            data.setdefault("motion", [copy.deepcopy(MOTION)])
        if pattern.startswith("plan"):
            data["plan"] = {"objective": {}} if pattern == "plan.objective" else {}
        if pattern == "plan" and key is not None and name == "motion":
            data["plan"]["motion"] = MOTION["name"]
            return data
    if pattern == "motion[]" and key is not None and name in ("along", "pace"):
        data["motion"].append({"name": "turn planned", "along": "turn",
                               "pace": [[0.0, 1.0], [1.0, 1.0]]})  # a planned motion
        return data
    table = data
    for part in path_of(data, pattern, name):
        table = table[part]
    if name in table and (pattern, name) not in (("", "original"), ("", "springs"),
                                                 ("", "motion"), ("", "workspace")):
        return data  # the base has it already
    value = value_of(mechanism, pattern, key, name)
    if pattern.endswith(".com") and key is not None:
        table.clear()
        if name in PARTNER:
            partner, other = PARTNER[name]
            table[partner] = other
    if value is not None:
        table[name] = value
    if pattern == "motion[]" and key is not None and name == "point":
        table["path"] = [[0.0, 0.0], [0.1, 0.1]]  # a point's (x, y)
    if pattern == "motion[]" and key is not None and name == "acc_time":
        table |= {"law": "trapezoid", "acc_time": 0.25}
    if pattern == "motion[]" and key is not None and name == "file":  # instead of the table
        del table["times"], table["path"]
        table["file"] = str(_motion_csv(data["mechanism"].get("input", "crank")))
    return data


def _motion_csv(input_name: str) -> Path:
    """A CSV of MOTION's table for a one-input linkage (kept for the session's tests)."""
    folder = Path(tempfile.gettempdir()) / f"balancer-schema-{os.getpid()}"
    folder.mkdir(exist_ok=True)
    path = folder / f"{input_name}.csv"
    rows = [f"{t!r},{p[0]!r}" for t, p in zip(MOTION["times"], MOTION["path"], strict=True)]
    path.write_text("\n".join([f"t,{input_name}", *rows]) + "\n")
    return path


def value_of(mechanism: str, pattern: str, key: schema.Key | None, name: str):
    if key is None:
        return 1.0  # an unknown key
    if (pattern, name) == ("", "springs"):
        return [dict(SPRING)]
    if (pattern, name) == ("", "motion"):
        return [copy.deepcopy(MOTION)]
    if (pattern, name) == ("", "workspace"):
        return {"crank": [-0.5, 0.5]}
    if (pattern, name) == ("motion[]", "acc_time"):
        return None  # written by variant() with its law
    if (pattern, name) == ("", "original"):
        return None  # written whole by variant()
    if (pattern, name) == ("simulation", "method"):
        return METHOD[mechanism]
    if (pattern, name) == ("balance", "force"):
        return "every-motion"  # (the base is a one-input linkage: "motion" is several inputs')
    if key.example:
        return tomllib.loads(f"x = {key.example}")["x"]
    return {}  # a table of its own, where its mechanism does not have it


def cases(accepted: bool) -> list:
    out = []
    for section in schema.SECTIONS:
        open_for = section.names.mechanisms if section.names else ()
        for key in section.keys:
            for mechanism in section.mechanisms:
                if (mechanism in key.mechanisms) != accepted or (
                        not accepted and mechanism in open_for):
                    continue  # (a table of names takes any other key as a name)
                if not accepted and any(k.name == key.name and mechanism in k.mechanisms
                                        for k in section.keys):
                    continue  # another entry of the name is this mechanism's
                out.append(pytest.param(mechanism, section, key,
                                        id=f"{mechanism}:{section.header}:{key.name}"))
    return out


def load(data: dict):
    return design_from_dict(copy.deepcopy(data), source="spec.toml")


@pytest.mark.parametrize(("mechanism", "section", "key"), cases(True))
def test_every_entry_is_accepted_for_its_mechanisms(mechanism, section, key):
    load(variant(mechanism, section, key, key.name))


@pytest.mark.parametrize(("mechanism", "section", "key"), cases(False))
def test_every_entry_is_refused_for_the_other_mechanisms(mechanism, section, key):
    with pytest.raises(SpecError) as caught:
        load(variant(mechanism, section, key, key.name))
    assert caught.value.key is not None and caught.value.key.endswith(key.name), caught.value


@pytest.mark.parametrize(("mechanism", "section"), [
    pytest.param(m, s, id=f"{m}:{s.header}") for s in schema.SECTIONS for m in s.mechanisms
    if not (s.names and m in s.names.mechanisms) and s.pattern != "balance"])
def test_an_unknown_key_is_refused_in_every_table(mechanism, section):
    with pytest.raises(SpecError, match="unknown key 'zz_unknown'"):
        load(variant(mechanism, section, None, "zz_unknown"))


def test_an_original_link_takes_no_position_of_its_own():
    # A general linkage's original link has no points of its own to place `at` from (the
    # reader took it as the link's origin, e = f = 0): the schema leaves it out, so it is refused.
    data = variant(schema.LINKAGE, schema.section("original.<link>.com"), None, "zz")
    data["original"]["crank"]["com"] = {"at": [0.01, 0.0]}
    with pytest.raises(SpecError, match="unknown key 'at'"):
        load(data)


@pytest.mark.slow
def test_the_reader_reads_no_key_without_an_entry(monkeypatch):
    read: set[tuple[str, str]] = set()
    raw = Table.raw

    def recording(self, name):
        read.add((self.path, name))
        return raw(self, name)

    monkeypatch.setattr(Table, "raw", recording)
    specs = [tomllib.loads(p.read_text()) for p in sorted((ROOT / "examples").glob("*.toml"))]
    for param in cases(True):
        mechanism, section, key = param.values
        specs.append(variant(mechanism, section, key, key.name))
    for data in specs:
        load(data)
    for path, name in sorted(read):
        section = schema.section(path)
        assert section is not None, f"[{path}] has no section in the schema"
        assert name in {k.name for k in section.keys} or section.names, f"{path}.{name}"
    documented = {(schema.pattern(p), n) for p, n in read}
    for section in schema.SECTIONS:
        for key in section.keys:
            assert (section.pattern, key.name) in documented, (section.header, key.name)


def test_every_entry_says_what_it_is():
    for section in schema.SECTIONS:
        assert section.summary.endswith(".") and section.mechanisms
        names = [k.name for k in section.keys]
        for key in (*section.keys, *([section.names] if section.names else [])):
            where = f"{section.header} {key.name}"
            assert key.unit and key.default and key.meaning.endswith("."), where
            assert set(key.mechanisms) <= set(section.mechanisms), where
            if key.unit != "table" and not key.name.startswith("<"):
                assert key.example, where
            if key.example:
                tomllib.loads(f"x = {key.example}")
        for name in set(names):  # a name twice: for different mechanisms
            entries = [k for k in section.keys if k.name == name]
            assert sum(len(k.mechanisms) for k in entries) == len(
                {m for k in entries for m in k.mechanisms}), (section.header, name)
    assert len({s.pattern for s in schema.SECTIONS}) == len(schema.SECTIONS)


def test_the_schema_names_what_the_model_names():
    assert schema.MECHANISMS == MECHANISM_TYPES
    for kind in (schema.FOUR_BAR, schema.SLIDER_CRANK):
        cls = CLASSES[kind]
        assert schema.known("mechanism.lengths", kind) == cls.length_names
        assert schema.known("links", kind) == cls.chain_links
        assert schema.known("original", kind) == cls.chain_links
    for kind in (schema.FOUR_BAR, schema.SLIDER_CRANK):
        assert schema.known("balance.objective", kind) == OBJECTIVE_KEYS
    # A linkage's also by DESIGN.md's name for several inputs' torques (read as driving_torque).
    linkage_terms = schema.known("balance.objective", schema.LINKAGE)
    assert tuple(k for k in linkage_terms if k != "torque") == OBJECTIVE_KEYS
    assert "torque" in linkage_terms
    assert schema.known("balance.objective", schema.ENGINE) == ENGINE_OBJECTIVE_KEYS
    objective = {f.name for f in dataclasses.fields(Objective)}
    assert set(OBJECTIVE_KEYS) | set(ENGINE_OBJECTIVE_KEYS) == objective
    for section, cls in (("balance.counterweights", CounterweightPlanes),
                         ("balance.shafts[]", ShaftFreedom)):
        assert set(schema.known(section)) == {f.name for f in dataclasses.fields(cls)}
    assert set(schema.known("balance.<link>")) == set(LINK_KEYS)
    assert schema.known("balance.<link>.counterweight") == COUNTERWEIGHT_KEYS
    assert schema.known("operation") == tuple(f.name for f in dataclasses.fields(Operation))
    # (`file` is read into the motion's times and path)
    assert tuple(k for k in schema.known("motion[]") if k != "file") == tuple(
        f.name for f in dataclasses.fields(MotionSpec))
    assert set(schema.known("workspace")) == {"samples", "joints"}
    assert set(schema.known("simulation")) == {
        f.name for f in dataclasses.fields(SimulationSettings)} - {"given"}  # (what was given)
    method = next(k for k in schema.section("simulation").keys if k.name == "method")
    for name in (*GENERAL, *(n for m in FOLDERS for n in mechanism_class(m).own_formulations)):
        assert f"`{name}`" in method.meaning, name
    kind = next(k for k in schema.section("mechanism").keys if k.name == "type")
    assert all(f'`"{t}"`' in kind.meaning for t in MECHANISM_TYPES)


def test_the_patterns_of_paths():
    assert schema.pattern("") == ""
    assert schema.pattern("links.crank.com") == "links.<link>.com"
    assert schema.pattern("links.ground") == "links.ground"
    assert schema.pattern("mechanism.sliders[2]") == "mechanism.sliders[]"
    assert schema.pattern("springs[0]") == "springs[]"
    assert schema.pattern("balance.objective") == "balance.objective"
    assert schema.pattern("balance.rocker.counterweight") == "balance.<link>.counterweight"
    assert schema.pattern("original.rod") == "original.<link>"
    assert schema.screen("links") is None and schema.screen("mechanism.points") is None
    assert schema.screen("links.slider.gas_force") == ("crank_angle", "force", "period")


def test_the_reader_declares_no_keys_of_its_own():
    # Every key list the reader checks a table against comes from the schema: no string
    # literal in an expect(...) or _check_keys(...) call but a pattern given to schema.known.
    for path in sorted(SPEC.glob("*.py")):
        if path.name == "schema.py":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for call in ast.walk(tree):
            if not (isinstance(call, ast.Call) and _name(call.func) in ("expect", "_check_keys")):
                continue
            allowed = {id(n) for sub in ast.walk(call) if isinstance(sub, ast.Call)
                       and _name(sub.func) == "known" for n in ast.walk(sub.args[0])}
            literals = [n.value for arg in call.args for n in ast.walk(arg)
                        if isinstance(n, ast.Constant) and isinstance(n.value, str)
                        and id(n) not in allowed]
            assert not literals, f"{path.name}:{call.lineno} declares keys {literals}"
        text = path.read_text(encoding="utf-8")
        assert "_KEYS" not in text.replace("OBJECTIVE_KEYS", ""), path.name


def _name(func: ast.expr) -> str:
    return func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
