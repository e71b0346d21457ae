"""Design specs in TOML: load and validate them into model objects.

The key names are fixed (see the project's DESIGN.md)::

    title = "optional free text"

    [mechanism]
    type = "four-bar"
    branch = "+"                      # or "-"
    [mechanism.lengths]
    crank = 1.0                       # m
    coupler = 3.0
    rocker = 2.0
    frame = 3.2

    [links.crank]                     # also [links.coupler], [links.rocker]
    mass = 2.1                        # kg
    inertia = 1.1                     # kg·m² about the centre of mass
    com = { s = 0.6, sigma = 0.3 }    # or { e = .., f = .. }, m and rad
    force = [1.1, 1.2]                # N, at the centre of mass (optional)
    moment = 0.37                     # N·m (optional)
    counter_rotor = 0.0               # kg·m², crank and rocker only (optional)

    [operation]
    speed = 10.0                      # rad/s
    samples = 360
    gravity = [0.0, -9.81]            # m/s², in the cycle analysis (optional)

    [simulation]
    duration = 5.0                    # s
    theta1 = 1.0                      # rad
    omega1 = 0.0                      # rad/s
    gravity = [0.0, -9.81]            # m/s² (optional)
    drive = "free"                    # or "constant-speed"

Every error names the file, the key and the value; unknown keys are errors (a typo such as
``mas`` must not be silently ignored).
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import validate as v
from ..errors import SpecError
from ..mechanisms import mechanism_of
from ..mechanisms.base import formulation_names
from ..model import Design, Operation, SimulationSettings
from ..model import MechanismModel as Model
from . import schema
from .codecs import MECHANISM_TYPES, MechanismSpec, balance_spec_of, spec_of
from .tables import Table

if TYPE_CHECKING:
    from ..model.motions import MotionSpec


def _read_mechanism(root: Table) -> tuple[Model, MechanismSpec]:
    """The mechanism (by its type's reader, :mod:`.codecs`) and that reader."""
    mech = root.table("mechanism")
    assert mech is not None
    codec = spec_of(mech.string("type", choices=MECHANISM_TYPES))
    return codec.read(root, mech), codec


def _read_operation(root: Table) -> Operation | None:
    table = root.table("operation", required=False)
    if table is None:
        return None
    if not table.has("speed"):
        raise table._missing("speed")
    with v.under("operation"):
        operation = Operation(speed=table.raw("speed"), samples=table.value("samples", 360),
                              gravity=table.value("gravity", (0.0, 0.0)),
                              speed_fluctuation=table.value("speed_fluctuation", None))
    table.finish()
    return operation


def _read_simulation(root: Table, mechanism: Model) -> SimulationSettings:
    table = root.table("simulation", required=False)
    defaults = SimulationSettings()
    if table is None:
        return defaults
    method = table.string("method", choices=formulation_names(mechanism_of(mechanism)),
                          default="") or None
    names = ("duration", "theta1", "omega1", "gravity", "drive", "rtol", "atol", "outputs")
    with v.under("simulation"):
        settings = SimulationSettings(
            **{name: table.value(name, getattr(defaults, name)) for name in names},
            method=method,
            given=frozenset(name for name in (*names, "method") if table.has(name)),
        )
    table.finish()
    return settings


def _read_original(root: Table, mechanism: Model, codec: MechanismSpec) -> Model | None:
    table = root.table("original", required=False)
    if table is None:
        return None
    return codec.read_original(table, mechanism)


def design_from_dict(data: dict[str, Any], source: str | None = None) -> Design:
    """Validate a parsed TOML document and build the :class:`~balancer.model.Design`.

    Raises
    ------
    SpecError
        With the key and value at fault and ``source`` as the file name.
    """
    try:
        root = Table(data, "")
        title = root.text("title", default="")
        mechanism, codec = _read_mechanism(root)
        root.expect(schema.known("", mechanism.type))  # the top-level tables of its type
        operation = _read_operation(root)
        simulation = _read_simulation(root, mechanism)
        balance = None
        if root.has("balance"):
            balance = balance_spec_of(mechanism.type).read_balance(root.table("balance"),
                                                                   mechanism)
        original = _read_original(root, mechanism, codec)
        workspace, plan = None, None
        motions: tuple[MotionSpec, ...] = ()
        if any(root.has(key) for key in ("workspace", "motion", "plan")):
            # (read by their own module, loaded where a spec has them)
            from .motions import read_motions, read_plan, read_workspace

            workspace = read_workspace(root)
            folder = Path(source).parent if source and Path(source).is_file() else Path.cwd()
            motions = (read_motions(root, mechanism_of(mechanism).linkage.inputs, folder,
                                    None if operation is None else operation.speed)
                       if root.has("motion") else ())
            plan = read_plan(root)
        root.finish()
        return Design(
            mechanism=mechanism,
            operation=operation,
            simulation=simulation,
            balance=balance,
            original=original,
            title=title,
            workspace=workspace,
            motions=motions,
            plan=plan,
        )
    except SpecError as exc:
        if source is not None and exc.source is None:
            raise exc.with_source(source) from None
        raise


def load_design(path: str | os.PathLike[str]) -> Design:
    """Read and validate a design spec from a TOML file.

    Raises
    ------
    SpecError
        If the file cannot be read, is not valid TOML, or fails validation.
    """
    p = Path(path)
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise SpecError("no such file", source=str(p)) from None
    except OSError as exc:
        raise SpecError(f"cannot read the file ({exc.strerror})", source=str(p)) from None
    try:
        # "utf-8-sig": a byte-order mark, as some Windows editors write, is not content
        data = tomllib.loads(raw.decode("utf-8-sig"))
    except UnicodeDecodeError:
        raise SpecError("not a UTF-8 text file", source=str(p)) from None
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"not valid TOML: {exc}", source=str(p)) from None
    return design_from_dict(data, source=str(p))


def loads_design(text: str, source: str = "<string>") -> Design:
    """Read and validate a design spec from TOML text."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"not valid TOML: {exc}", source=source) from None
    return design_from_dict(data, source=source)
