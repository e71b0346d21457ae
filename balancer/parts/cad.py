"""CAD files of the parts: a STEP solid and a DXF profile each, in the link's frame, millimetres.

The ``cad`` extra (``pip install 'balancer[cad]'``) brings build123d (on the OpenCascade
kernel, OCP) for STEP and ezdxf for DXF; both are imported by the functions that write, so
that the rest of the package starts without them (:func:`missing` tells, without importing
them, whether they are there).

Each part is the prism of its profile (:mod:`balancer.parts.shapes`): the profile in the link's
frame (x along the link from its first point, y across it), extruded along z from ``−t/2`` to
``+t/2`` about the link's plane. The DXF holds the profile on layer ``PART`` (a circle, or a
closed polyline of lines and arcs whose ``thickness`` is the part's) and the link's points on
layer ``LINK``; STEP and DXF both in mm. :func:`write_cad` writes a folder of them whole or not
at all.
"""

from __future__ import annotations

import importlib.util
import math
import os
import re
import shutil
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import OutputError
from .made import LinkPart
from .planes import PlanePart
from .shapes import Arc, Line, Loop, Profile

if TYPE_CHECKING:  # the cad extra's types, for the annotations only
    import build123d

#: The packages of the ``cad`` extra.
CAD_PACKAGES = ("build123d", "ezdxf")
#: Millimetres per metre: the files' unit.
MM = 1000.0


def missing() -> list[str]:
    """The packages of the ``cad`` extra that are not installed (none imported to tell)."""
    return [name for name in CAD_PACKAGES if importlib.util.find_spec(name) is None]


def require_cad(option: str = "--cad") -> None:
    """:class:`OutputError` (exit 2) naming the extra, if a package of it is missing."""
    absent = missing()
    if absent:
        raise OutputError(f"CAD files need the cad extra ({', '.join(absent)} not installed): "
                          "pip install 'balancer[cad]'", key=option)


def file_stem(link: str) -> str:
    """A file name for link ``link``.

    Its name, with characters other than letters, digits, ``-``, ``_`` and ``.`` as ``_``.
    """
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", link)
    return stem if stem.strip(".") else f"link_{stem}"


def _mm(z: complex) -> tuple[float, float]:
    return (MM * z.real, MM * z.imag)


def _arc_mid(edge: Arc) -> complex:
    return edge.point((edge.start + edge.end) / 2)


def solid(profile: Profile, z: float = 0.0) -> build123d.Solid:
    """The part's solid (build123d, mm): its profile extruded from ``z − t/2`` to ``z + t/2``.

    (``z`` m: a crank web's plane on the crankshaft; a link's part is about its plane, 0.)
    """
    import build123d as bd

    def edge(e: Line | Arc) -> bd.Edge:
        if isinstance(e, Line):
            return bd.Edge.make_line((*_mm(e.start), 0.0), (*_mm(e.end), 0.0))
        if e.closed:
            return bd.Edge.make_circle(MM * e.radius,
                                       bd.Plane(origin=(*_mm(e.centre), 0.0)))
        return bd.Edge.make_three_point_arc((*_mm(e.point(e.start)), 0.0),
                                            (*_mm(_arc_mid(e)), 0.0),
                                            (*_mm(e.point(e.end)), 0.0))

    wires = [bd.Wire([edge(e) for e in loop]) for loop in profile.loops()]
    face = bd.Face(wires[0], wires[1:])
    half = MM * profile.thickness / 2
    face = face.moved(bd.Location((0.0, 0.0, MM * z - half)))
    return bd.Solid.extrude(face, (0.0, 0.0, 2 * half))


def kernel_properties(shape: Any, density: float) -> tuple[float, complex, float, float]:
    """The CAD kernel's own mass properties of a solid (mm) at ``density`` kg/m³.

    Returns its mass (kg), the centre's x + i·y (m), its z (m) and the inertia about the axis
    along z through the centre (kg·m²), from OpenCascade's ``BRepGProp`` volume integrals.
    """
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(getattr(shape, "wrapped", shape), props)
    volume = props.Mass() * 1e-9  # m³
    c = props.CentreOfMass()
    izz = props.MatrixOfInertia().Value(3, 3) * 1e-15  # m⁵, about the centre of mass
    return (density * volume, complex(c.X(), c.Y()) / MM, c.Z() / MM, density * izz)


def write_step(profile: Profile, path: str | os.PathLike[str], name: str, z: float = 0.0
               ) -> None:
    """Write the part's solid as STEP (mm) to ``path``, about the plane ``z`` (m)."""
    import build123d as bd

    body = solid(profile, z)
    body.label = name
    if not bd.export_step(body, str(path)):
        raise OutputError("the STEP writer failed", source=str(path))


def _bulge(edge: Arc) -> float:
    """A DXF polyline's bulge for an arc: tan(sweep/4), positive counter-clockwise."""
    return math.tan((edge.end - edge.start) / 4)


def write_dxf(part: LinkPart | PlanePart, path: str | os.PathLike[str]) -> None:
    """Write the part's profile and the link's points as DXF (mm) to ``path``."""
    import ezdxf
    from ezdxf import units

    profile = part.sized.profile
    assert profile is not None
    doc = ezdxf.new("R2010", units=units.MM)
    doc.layers.add("PART", color=1)
    doc.layers.add("LINK", color=7)
    msp = doc.modelspace()
    attribs = {"layer": "PART", "thickness": MM * profile.thickness}
    for loop in profile.loops():
        _add_loop(msp, loop, attribs)
    for name, point in part.points:
        msp.add_point(_mm(point), dxfattribs={"layer": "LINK"})
        msp.add_text(name, height=MM * _text_height(part),
                     dxfattribs={"layer": "LINK", "insert": _mm(point)})
    pts = [p for _, p in part.points]
    for a, b in zip(pts, pts[1:], strict=False):
        msp.add_line(_mm(a), _mm(b), dxfattribs={"layer": "LINK"})
    doc.saveas(str(path))


def _text_height(part: LinkPart | PlanePart) -> float:
    """A label height, m: a fiftieth of the link's extent, at least a millimetre."""
    pts = [p for _, p in part.points]
    extent = max((abs(a - b) for a in pts for b in pts), default=0.0)
    return max(extent / 50, 1e-3)


def _add_loop(msp: Any, loop: Loop, attribs: dict[str, Any]) -> None:
    if len(loop) == 1 and isinstance(loop[0], Arc) and loop[0].closed:
        msp.add_circle(_mm(loop[0].centre), MM * loop[0].radius, dxfattribs=attribs)
        return
    vertices = []
    for edge in loop:
        if isinstance(edge, Line):
            vertices.append((*_mm(edge.start), 0.0))
        else:
            vertices.append((*_mm(edge.point(edge.start)), _bulge(edge)))
    polyline = msp.add_lwpolyline(vertices, format="xyb", close=True, dxfattribs=attribs)
    polyline.dxf.thickness = attribs["thickness"]


def cad_folder(folder: str | os.PathLike[str], *, force: bool, option: str = "--cad") -> Path:
    """The folder ``--cad`` writes into, checked before any work (:class:`OutputError`).

    Its parent must exist; it must not exist, or be an empty folder, or with ``force`` a
    folder (whose files of the same names are replaced).
    """
    target = Path(folder)
    if not str(folder):
        raise OutputError("an output folder must not be empty", key=option, value=str(folder))
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise OutputError("the folder to write into does not exist", key=option,
                          value=str(folder))
    if target.exists() or target.is_symlink():
        if not target.is_dir():
            raise OutputError("is a file, not a folder", key=option, value=str(folder))
        if any(target.iterdir()) and not force:
            raise OutputError("the folder exists and is not empty; give another, or --force "
                              "to replace its files of the same names", key=option,
                              value=str(folder))
    if not os.access(parent, os.W_OK):
        raise OutputError(f"cannot write into {parent}", key=option, value=str(folder))
    return target


def write_cad(folder: str | os.PathLike[str],
              parts: Mapping[str, LinkPart] | Mapping[str, PlanePart],
              drawing: Callable[[Any, Path], object] | None = None) -> list[Path]:
    """Per part ``<name>.step`` and ``<name>.dxf`` (and the drawing's files) into ``folder``.

    A link's part is named after the link; an engine's crank-web sector after its plane
    (:func:`balancer.parts.planes.plane_name`), its STEP solid at its plane on the
    crankshaft (its z in mm: the planes' files assemble), its DXF profile in its plane.

    Everything is written into a temporary folder beside it first and moved in when all is
    written: a failure leaves ``folder`` as it was. ``drawing(part, stem)`` writes the
    drawing's files at ``stem`` with their own extensions (:mod:`balancer.plots.parts`).
    Returns the paths written. A part with no profile gets no files.
    """
    require_cad()
    target = Path(folder)
    parent = target.parent if str(target.parent) else Path(".")
    try:
        scratch = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=parent))
    except OSError as exc:
        raise OutputError(f"cannot write into {parent} ({exc.strerror})",
                          source=str(folder)) from None
    try:
        for name, part in parts.items():
            if part.sized.profile is None:
                continue
            stem = scratch / file_stem(name)
            write_step(part.sized.profile, stem.with_name(stem.name + ".step"), name,
                       part.z if isinstance(part, PlanePart) else 0.0)
            write_dxf(part, stem.with_name(stem.name + ".dxf"))
            if drawing is not None:
                drawing(part, stem)
        names = sorted(p.name for p in scratch.iterdir())
        umask = os.umask(0)
        os.umask(umask)
        for p in scratch.iterdir():
            os.chmod(p, 0o666 & ~umask)
        if not target.exists():
            os.chmod(scratch, 0o777 & ~umask)
            os.replace(scratch, target)
        else:
            for n in names:
                os.replace(scratch / n, target / n)
            scratch.rmdir()
    except OSError as exc:
        shutil.rmtree(scratch, ignore_errors=True)
        raise OutputError(f"cannot write the CAD files ({exc.strerror or exc})",
                          source=str(folder)) from None
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    return [target / n for n in names]
