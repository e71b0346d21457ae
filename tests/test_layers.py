"""The package's layers hold by themselves: every import runs down or sideways, none in a cycle.

Read from the source with :mod:`ast`, counting imports inside functions and under
``TYPE_CHECKING`` as much as those at the top (docs/architecture.md draws the layers). And the
package's public names: every type a user meets is a name of ``balancer``, loaded lazily.
"""

from __future__ import annotations

import ast
import functools
import re
import subprocess
import sys
import typing
from pathlib import Path

import pytest

import balancer

PACKAGE = Path(balancer.__file__).resolve().parent

#: The layers, lowest first: a module may import its own layer and those below. A module is
#: placed by its longest matching prefix.
LAYERS: tuple[tuple[str, ...], ...] = (
    ("errors", "validate", "tomltext", "progress", "interrupts", "outputs", "lazy", "rounding",
     "quantities"),
    ("model",),
    # The general core; the profiles of parts and their sizing (link-level mass models).
    ("linkage", "orders", "parts.shapes", "parts.sizing"),
    # The mechanism interface (and its wording for the layers that print), and what every
    # mechanism's formulations share.
    ("mechanisms.base", "mechanisms.presentation", "mechanisms.drawing", "mechanisms.geometry",
     "mechanisms.formulation", "mechanisms.chains"),
    # Each mechanism in its own folder; the general formulations (any mechanism).
    ("mechanisms.fourbar", "mechanisms.slidercrank", "mechanisms.general",
     "formulations.compiled", "formulations.crank_angle", "formulations.multibody"),
    # The registry of mechanisms and of formulations, and what runs over any mechanism.
    ("mechanisms", "formulations", "force_balance", "columns", "cycle", "motion_analysis",
     "speed_fluctuation", "phasors"),
    ("balance", "planning", "arrangements"),
    ("simulation", "verification", "motion_verification", "report", "plots", "plausibility",
     "parts"),
    ("spec", "examples", "api", "sweeps", "cli", "__main__"),
)


def modules() -> dict[str, Path]:
    """Every module of the package by dotted name (``balancer`` left out)."""
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if parts:
            out[".".join(parts)] = path
    return out


#: A mechanism's reader and writer of its tables of a spec (``mechanisms/<name>/spec.py``): it
#: reads TOML tables, so it sits in the spec's layer, and the spec reader finds it by name
#: through the registry (``balancer.mechanisms.folder_module``).
SPEC_MODULE = re.compile(r"^mechanisms\.\w+\.spec$")


def layer(name: str) -> int:
    """The layer of module ``name`` (by its longest prefix in :data:`LAYERS`)."""
    if SPEC_MODULE.match(name):
        name = "spec"
    best, found = -1, None
    for level, prefixes in enumerate(LAYERS):
        for prefix in prefixes:
            if (name == prefix or name.startswith(prefix + ".")) and len(prefix) > best:
                best, found = len(prefix), level
    if found is None:
        raise AssertionError(f"module balancer.{name} is in no layer: place it in LAYERS")
    return found


@functools.cache
def nodes(path: Path) -> tuple[ast.AST, ...]:
    """Every node of a module's syntax tree (parsed once for all the tests here)."""
    return tuple(ast.walk(ast.parse(path.read_text(encoding="utf-8"))))


def imports(name: str, path: Path, known: dict[str, Path]) -> set[str]:
    """The package's modules that module ``name`` imports, anywhere in its source."""
    is_package = path.name == "__init__.py"
    base = name.split(".") if name else []
    if not is_package:
        base = base[:-1]
    out = set()
    for node in nodes(path):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names if a.name.startswith("balancer.")]
            out |= {t.removeprefix("balancer.") for t in targets}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = base[: len(base) - (node.level - 1)]
                module = ".".join([*parts, *([node.module] if node.module else [])])
            elif node.module and node.module.startswith("balancer"):
                module = node.module.removeprefix("balancer").removeprefix(".")
            else:
                continue
            for alias in node.names:
                full = f"{module}.{alias.name}" if module else alias.name
                out.add(full if full in known else module)
    out.discard(name)
    out.discard("")
    return {m for m in out if m in known}


def graph() -> dict[str, set[str]]:
    known = modules()
    return {name: imports(name, path, known) for name, path in known.items()}


@pytest.mark.slow
def test_every_import_runs_down_or_sideways():
    upward = [f"balancer.{a} (layer {layer(a)}) imports balancer.{b} (layer {layer(b)})"
              for a, targets in graph().items() for b in sorted(targets) if layer(b) > layer(a)]
    assert not upward, "\n".join(upward)


def test_no_import_cycle():
    edges = graph()
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    cycles: list[list[str]] = []

    def visit(v: str) -> None:  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10 * len(edges)))
    for v in edges:
        if v not in index:
            visit(v)
    assert not cycles, cycles


def test_the_layer_table_knows_every_module():
    for name in modules():
        if name:
            layer(name)


@pytest.mark.parametrize("name", balancer.__all__)
def test_every_public_name_resolves(name):
    assert getattr(balancer, name) is not None


def test_every_api_call_returns_a_public_type():
    from balancer import api

    public = {getattr(balancer, n) for n in balancer.__all__}
    plain = (dict, list, tuple, str, float, int, type(None), typing.Any)

    def classes(kind):  # the classes a (possibly nested) annotation names
        args = typing.get_args(kind)
        if args:
            for arg in args:
                yield from classes(arg)
        if (typing.get_origin(kind) or kind) not in plain and not args:
            yield kind

    for name in api.__all__:
        hints = typing.get_type_hints(getattr(api, name), vars(balancer) | vars(typing))
        for kind in classes(hints["return"]):
            assert kind in public, f"api.{name} returns {kind!r}, not a name of balancer"


def test_import_balancer_loads_no_numerics():
    code = "import sys, balancer; print(sorted(m for m in ('numpy', 'scipy', 'casadi') " \
           "if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


def test_the_architecture_page_draws_every_layer_as_the_test_holds_it():
    """Each module of LAYERS is named in docs/architecture.md's diagram, in its own layer."""
    page = (PACKAGE.parent / "docs" / "architecture.md").read_text(encoding="utf-8")
    diagram = page.split("```text", 1)[1].split("```", 1)[0]
    rows: dict[int, str] = {}
    current = -1
    for line in diagram.splitlines():
        head = line[:3].strip()
        if head.isdigit():
            current = int(head)
        if current >= 0:
            rows[current] = rows.get(current, "") + line
    for level, prefixes in enumerate(LAYERS):
        for prefix in prefixes:
            if prefix == "__main__" or "." in prefix:  # the entry point; a module of a package
                continue
            name = prefix
            assert name in rows.get(level, ""), f"{prefix} is not drawn in layer {level}"


def test_every_registered_mechanism_reads_and_writes_its_spec_tables_in_its_folder():
    """``spec`` in each mechanism's folder gives the reader and writer of its tables, and its
    ``mechanism`` module the class the registry builds for that type."""
    import importlib

    from balancer.mechanisms import FOLDERS, folder_module, mechanism_class
    from balancer.spec.codecs import balance_spec_of

    for kind in FOLDERS:
        cls = mechanism_class(kind)
        folder = cls.__module__.rpartition(".")[0]
        name = folder_module(kind, "spec")
        assert name == f"{folder}.spec" and folder.startswith("balancer.mechanisms.")
        module = importlib.import_module(name)
        for function in ("read", "lines", "read_original", "original_lines"):
            assert callable(getattr(module, function)), f"{kind}: {name}.{function}"
        from balancer.formulations import own_formulation
        from balancer.mechanisms.formulation import Formulation

        for name in cls.own_formulations:  # each imported from the folder when asked for
            own = own_formulation(cls, name)
            assert own is not None and issubclass(own, Formulation), f"{kind}: {name}"
            assert own.__module__.startswith(f"{folder}."), f"{kind}: {name}"
        assert own_formulation(cls, "no-such-formulation") is None
        balance = balance_spec_of(kind)
        assert balance.__name__ == module.BALANCE
        for function in ("read_balance", "balance_lines"):
            assert callable(getattr(balance, function)), f"{kind}: {module.BALANCE}.{function}"


@pytest.mark.slow
def test_the_spec_reader_and_writer_ask_no_mechanism_what_it_is():
    """``balancer/spec`` imports no mechanism's folder: each is reached through the registry."""
    edges = graph()
    for name, targets in edges.items():
        if name.startswith("spec"):
            folders = {t for t in targets if t.startswith("mechanisms.")
                       and t.count(".") >= 1 and not t.startswith("mechanisms.base")}
            assert not folders, f"balancer.{name} imports {sorted(folders)}"


#: The most lines a module may have: one concept each (issue 41).
MODULE_LINES = 800


def test_no_module_is_over_800_lines():
    long = {name: n for name, path in modules().items()
            if (n := len(path.read_text(encoding="utf-8").splitlines())) > MODULE_LINES}
    assert not long, f"modules over {MODULE_LINES} lines: {long}"


#: The core's joint kinds (:mod:`balancer.linkage.constraints`), which dispatch through their
#: own methods: no other module asks a joint which kind it is (issue 41).
JOINT_KINDS = {"Pin", "Prism", "Mesh", "Driver", "SlideDriver"}


def _kinds_asked(node: ast.AST) -> set[str]:
    """The joint kinds an ``isinstance`` call's second argument names (a name, tuple or union)."""
    if isinstance(node, ast.Name):
        return {node.id} & JOINT_KINDS
    if isinstance(node, ast.Attribute):
        return {node.attr} & JOINT_KINDS
    if isinstance(node, ast.Tuple):
        return set().union(*(_kinds_asked(e) for e in node.elts))
    if isinstance(node, ast.BinOp):
        return _kinds_asked(node.left) | _kinds_asked(node.right)
    return set()


def _kind_questions(node: ast.AST) -> set[str]:
    """The joint kinds a node asks about: ``isinstance``/``issubclass`` of them, ``type(x) is``
    (or ``==``) one of them, or a ``case`` pattern of their class."""
    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
            and node.func.id in ("isinstance", "issubclass") and len(node.args) == 2):
        return _kinds_asked(node.args[1])
    if (isinstance(node, ast.Compare) and isinstance(node.left, ast.Call)
            and isinstance(node.left.func, ast.Name) and node.left.func.id == "type"):
        return set().union(*(_kinds_asked(c) for c in node.comparators))
    if isinstance(node, ast.MatchClass):
        return _kinds_asked(node.cls)
    return set()


def test_no_module_but_the_joints_own_asks_a_joint_its_kind():
    asked: dict[str, set[str]] = {}
    for name, path in modules().items():
        if name == "linkage.constraints":
            continue
        for node in nodes(path):
            if kinds := _kind_questions(node):
                asked.setdefault(name, set()).update(kinds)
    assert not asked, f"joint kinds asked outside linkage.constraints: {asked}"


def test_the_joint_kind_check_sees_each_way_of_asking():
    """The check above catches each form (a check that could not fail would hold nothing)."""
    forms = ["isinstance(j, Pin)", "isinstance(j, (Prism, Mesh))", "isinstance(j, Pin | Driver)",
             "issubclass(type(j), SlideDriver)", "type(j) is Prism", "type(j) == Mesh",
             "match j:\n    case Pin():\n        pass"]
    for form in forms:
        found = set().union(*(_kind_questions(n) for n in ast.walk(ast.parse(form))))
        assert found, form
    assert not set().union(*(_kind_questions(n) for n in ast.walk(ast.parse("isinstance(j, V)"))))


def test_the_mechanism_interface_is_what_the_architecture_page_lists():
    """docs/architecture.md lists every public member of the mechanism interface, and no more."""
    from balancer.mechanisms.base import Mechanism

    page = (PACKAGE.parent / "docs" / "architecture.md").read_text(encoding="utf-8")
    listed = page.split("<!-- interface:", 1)[1].split("<!-- /interface -->", 1)[0]
    names = set(re.findall(r"`(\w+)`", listed.split("-->", 1)[1]))
    members = {n for n in vars(Mechanism) if not n.startswith("_")}
    assert names == members, (f"not on the page: {sorted(members - names)}; "
                              f"not on the class: {sorted(names - members)}")
    count = re.search(r"`Mechanism` class \(`mechanisms/base.py`\), (\d+)\s+members", page)
    assert count is not None and int(count.group(1)) == len(members)


def test_no_two_public_classes_share_a_name():
    """A class name says which class it is, across the package (issue 41)."""
    where: dict[str, list[str]] = {}
    for name, path in modules().items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in tree.body:
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                where.setdefault(node.name, []).append(name)
    shared = {cls: mods for cls, mods in where.items() if len(mods) > 1}
    assert not shared, f"public classes of one name in several modules: {shared}"


def test_the_members_no_mechanism_gives_are_those_the_page_calls_computed():
    """The architecture page's seven computed members are those no registered mechanism
    overrides; every other member is one some mechanism gives."""
    from balancer.mechanisms import FOLDERS, mechanism_class
    from balancer.mechanisms.base import Mechanism

    page = (PACKAGE.parent / "docs" / "architecture.md").read_text(encoding="utf-8")
    listed = page.split("<!-- services -->", 1)[1].split("<!-- /services -->", 1)[0]
    computed = set(re.findall(r"`(\w+)`", listed))
    classes = [mechanism_class(kind) for kind in FOLDERS]
    given = {n for cls in classes for n in vars(cls) if not n.startswith("_")}
    members = {n for n in vars(Mechanism) if not n.startswith("_")}
    assert computed == members - given


def _dataclass_keywords(node: ast.ClassDef) -> dict[str, object] | None:
    """A class's ``@dataclass(...)`` keywords (``{}`` bare), or ``None`` if it is none."""
    for d in node.decorator_list:
        if isinstance(d, ast.Name) and d.id == "dataclass":
            return {}
        if isinstance(d, ast.Call) and isinstance(d.func, ast.Name) and d.func.id == "dataclass":
            return {k.arg: ast.literal_eval(k.value) for k in d.keywords if k.arg}
    return None


def test_records_of_arrays_compare_by_identity():
    """A dataclass with an array field is ``eq=False``: arrays' equality has no one truth value
    (``==`` of two such records raised), and on Python 3.11 each ``__eq__`` and ``__hash__`` is
    compiled at import, a command's start-up."""
    compared = []
    for name, path in modules().items():
        for node in nodes(path):
            if not isinstance(node, ast.ClassDef) or (keys := _dataclass_keywords(node)) is None:
                continue
            arrays = [n.target.id for n in node.body if isinstance(n, ast.AnnAssign)
                      and isinstance(n.target, ast.Name) and "NDArray" in ast.unparse(n.annotation)]
            if arrays and keys.get("eq", True):
                compared.append(f"{name}.{node.name}")
    assert not compared, f"records of arrays with value equality: {compared}"
