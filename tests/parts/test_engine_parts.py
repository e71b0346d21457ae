"""An engine's crank-web sectors (issue 45): every figure by a second route.

- each plane's sector has the optimiser's mass·radius and angle to 1e-9, by its mass times its
  centre and by the closed form ``(2/3)·ρ·t·sin α·(Ro³ − Ri³)`` of its dimensions;
- the CAD kernel's mass properties of its STEP solid equal the closed form to 1e-6, at its plane;
- the sector is the lightest of its room with that mass·radius (against sampled others);
- the engine with the sectors as built (their mass·radius as the crankshaft's) analyses to the
  balanced figures; a room too small: the nearest part, and the report says so;
- the room as a bound: the optimum equals the one with ``max_mr`` written as the room's
  largest mass·radius (that figure by Green's theorem on the sector's outline);
- the spec's ``part``: read, written back equal, bad input one line naming key and value;
  ``optimize --cad`` writes each plane's files whole.
"""

from __future__ import annotations

import cmath
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from balancer.errors import SpecError
from balancer.model.parts import Sector
from balancer.parts.shapes import AnnularSector
from balancer.parts.sizing import most_mr, sector_mr, size_web

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "inline_three_parts.toml"
KERNEL = 1e-6  # the tolerance between the CAD kernel and the closed forms
PART = ('part = { shape = "sector", material = "steel", inner_radius = 0.025, '
        'outer_radius = 0.075, angle_deg = 160.0, thickness = 0.018 }  # m, °')


def spec_with(part: str | None) -> str:
    """The example with its part line replaced by ``part`` (``None``: none)."""
    text = EXAMPLE.read_text()
    assert PART in text
    return text.replace(PART, part or "")


def balanced(text: str):
    import balancer
    from balancer.parts.planes import make_webs
    from balancer.spec import loads_design

    design = loads_design(text)
    result = balancer.optimize(design, backend="convex")
    return design, result, make_webs(design, result)


@pytest.fixture(scope="module")
def webs():
    return balanced(EXAMPLE.read_text())


def mr_of_outline(profile: AnnularSector, density: float, n: int = 400_000) -> complex:
    """``ρ·t·∫ r̄ dA`` by Green's theorem on the sector's outline, sampled (kg·m)."""
    pts = []
    for edge in profile.loops()[0]:
        if hasattr(edge, "radius"):
            a = np.linspace(edge.start, edge.end, n, endpoint=False)
            pts.append(edge.centre + edge.radius * np.exp(1j * a))
        else:
            pts.append(np.linspace(edge.start, edge.end, n, endpoint=False))
    z = np.concatenate(pts)
    x, y = z.real, z.imag
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    first = complex(((x + xn) * cross).sum(), ((y + yn) * cross).sum()) / 6
    return density * profile.thickness * first


# -- each plane's sector ---------------------------------------------------------------------

def test_each_sector_has_the_optimisers_mass_radius_and_angle(webs):
    _, result, parts = webs
    chosen = [c for c in result.rotor_masses.counterweights if c.mr > 0]
    assert [p.placed for p in parts.values()] == chosen and len(chosen) == 2
    assert list(parts) == ["crankshaft_z-113.5mm", "crankshaft_z113.5mm"]
    for part in parts.values():
        sized, profile = part.sized, part.sized.profile
        assert sized.exact and not sized.limits
        asked = cmath.rect(part.placed.mr, math.radians(part.placed.phase_deg))
        made = sized.made
        assert abs(made.mass * made.centre - asked) <= 1e-9 * part.placed.mr
        # the closed form of its dimensions, and its bisector at the angle
        closed = sector_mr(profile.inner, profile.outer, profile.angle / 2, profile.thickness,
                           sized.density)
        assert closed == pytest.approx(part.placed.mr, rel=1e-9)
        assert cmath.rect(1.0, profile.direction) == pytest.approx(
            cmath.rect(1.0, math.radians(part.placed.phase_deg)), abs=1e-12)
        # in its room: the full radius and thickness, its angle within the room's
        assert (profile.inner, profile.outer) == (0.025, 0.075)
        assert profile.thickness == pytest.approx(0.018, rel=1e-12)
        assert math.degrees(profile.angle) <= 160.0
        # Green's theorem on the outline gives the same first moment
        assert abs(mr_of_outline(profile, sized.density) - asked) <= 1e-6 * part.placed.mr


def test_the_sectors_solid_has_the_kernels_mass_properties_at_its_plane(webs, tmp_path):
    build123d = pytest.importorskip("build123d", reason="the cad extra")
    from balancer.parts.cad import kernel_properties, write_step

    for part in webs[2].values():
        path = tmp_path / f"{part.name}.step"
        write_step(part.sized.profile, path, part.name, part.z)
        m, c, z, izz = kernel_properties(build123d.import_step(str(path)), part.sized.density)
        made = part.sized.made
        assert m == pytest.approx(made.mass, rel=KERNEL)
        assert abs(c - made.centre) <= KERNEL * abs(made.centre)
        assert izz == pytest.approx(made.inertia, rel=KERNEL)
        assert z == pytest.approx(part.z, abs=KERNEL * part.sized.profile.thickness)


@settings(max_examples=60, deadline=None)
@given(share=st.floats(0.02, 1.0), angle=st.floats(20.0, 360.0), ri=st.floats(0.0, 0.04),
       other=st.tuples(st.floats(0.5, 1.0), st.floats(0.3, 1.0), st.floats(0.05, 1.0)))
def test_the_sector_is_the_lightest_of_its_room_with_that_mass_radius(share, angle, ri, other):
    room = Sector(inner_radius=ri, outer_radius=0.08, angle_deg=angle, thickness=0.02)
    mr = share * most_mr(room)
    sized = size_web(room, mr, 0.3)
    assert sized.exact
    assert abs(sized.made.mass * sized.made.centre - cmath.rect(mr, 0.3)) <= 1e-9 * mr
    # another sector of the room with the same mass·radius: smaller radius or thinner,
    # its angle solved; if it exists, it is no lighter
    fr, ft, _ = other
    ro, t = ri + fr * (0.08 - ri), ft * 0.02
    s = mr / sector_mr(ri, ro, math.pi / 2, t, 7850.0)
    best = min(math.radians(angle) / 2, math.pi / 2)
    if s <= math.sin(best):
        half = math.asin(s)
        mass = 7850.0 * t * half * (ro * ro - ri * ri)
        assert mass >= sized.made.mass * (1 - 1e-12)


def test_the_engine_as_built_analyses_to_the_balanced_figures(webs):
    from balancer.parts.planes import built_engine, webs_as_built

    _, result, parts = webs
    model = built_engine(result, parts)
    # its crankshaft carries the balanced one's masses, the new ones as the parts make them
    mine = sorted((m.z, m.mr, m.phase_deg) for m in model.crankshaft.masses)
    theirs = sorted((m.z, m.mr, m.phase_deg) for m in result.linkage.crankshaft.masses)
    assert len(mine) == len(theirs)
    for a, b in zip(mine, theirs, strict=True):
        assert a[0] == b[0] and a[1] == pytest.approx(b[1], rel=1e-9)
        assert a[2] == pytest.approx(b[2], abs=1e-7)
    built = webs_as_built(result, parts).summary
    _, after = result.operating
    for key in ("shaking_force", "rocking_couple", "shaking_moment", "driving_torque"):
        assert getattr(built, key).rms == pytest.approx(getattr(after.summary, key).rms,
                                                        rel=1e-9, abs=1e-9), key


def test_a_room_too_small_gives_the_nearest_sector_and_the_report_says_so(webs):
    from balancer.parts.planes import make_webs
    from balancer.report.parts import parts_json, parts_text
    from balancer.spec import loads_design

    _, result, _ = webs
    small = spec_with(PART.replace("thickness = 0.018", "thickness = 0.006"))
    design = loads_design(small)
    parts = make_webs(design, result)  # the optimum of the larger room, in the smaller one
    room = design.balance.counterweights.part
    most = most_mr(room)
    # the room's widest sector (160°) at full radius and thickness, by Green's theorem
    widest = AnnularSector(pivot=0j, inner=0.025, outer=0.075, angle=math.radians(160.0),
                           direction=0.0, thickness=0.006)
    assert most == pytest.approx(abs(mr_of_outline(widest, 7850.0)), rel=1e-6)
    for part in parts.values():
        assert not part.sized.exact and part.built.mr == pytest.approx(most, rel=1e-12)
        assert part.built.phase_deg == pytest.approx(part.placed.phase_deg, abs=1e-9)
        assert abs(part.moves) == pytest.approx(part.placed.mr - most, rel=1e-9)
    text = parts_text(parts)
    assert "nearest" in text and f"{most:.6g} kg·m" in text
    doc = parts_json(parts)
    assert not doc["crankshaft_z113.5mm"]["exact"]
    assert doc["crankshaft_z113.5mm"]["limits"] == ["outer_radius", "angle_deg", "thickness"]


def test_the_room_bounds_each_planes_mass_radius():
    """A room that holds less than max_mr: the optimum is the one with max_mr written as the
    room's largest mass·radius (Green's theorem on its widest sector's outline), no part."""
    small = PART.replace("thickness = 0.018", "thickness = 0.008")
    design, result, parts = balanced(spec_with(small))
    room = design.balance.counterweights.part
    profile = AnnularSector(pivot=0j, inner=0.025, outer=0.075, angle=math.radians(160.0),
                            direction=0.0, thickness=0.008)  # the room's widest
    most = abs(mr_of_outline(profile, 7850.0))
    assert most_mr(room) == pytest.approx(most, rel=1e-6) and most < 0.025
    written = spec_with(None).replace("max_mr = 0.025 ", f"max_mr = {most_mr(room)!r} ")
    _, by_hand, _ = balanced(written)
    assert result.objective == pytest.approx(by_hand.objective, rel=1e-7)
    for a, b in zip(result.rotor_masses.counterweights, by_hand.rotor_masses.counterweights,
                    strict=True):
        assert a.mr == pytest.approx(b.mr, rel=1e-6)
        assert a.mr <= most_mr(room) * (1 + 1e-12)
    for part in parts.values():  # held by the room, and exactly made
        assert part.sized.exact and part.placed.mr == pytest.approx(most_mr(room), rel=1e-6)
    assert result.objective > balanced(EXAMPLE.read_text())[1].objective


# -- the spec --------------------------------------------------------------------------------

def test_the_part_round_trips_through_the_spec():
    from balancer.spec import dumps_design, loads_design

    design = loads_design(EXAMPLE.read_text())
    again = loads_design(dumps_design(design))
    assert again.balance == design.balance
    assert design.balance.counterweights.part == Sector(
        inner_radius=0.025, outer_radius=0.075, angle_deg=160.0, thickness=0.018)


@pytest.mark.parametrize(("part", "key", "value"), [
    ('part = { shape = "ring", outer_radius = 0.07, thickness = 0.02 }', "part.shape", "ring"),
    ('part = { shape = "sector", outer_radius = 0.07, angle_deg = 400.0, thickness = 0.02 }',
     "part.angle_deg", 400.0),
    ('part = { shape = "sector", outer_radius = 0.07, angle_deg = 90.0, thickness = 0.02, '
     'size = "M12" }', "part.size", None),  # (an unknown key: named alone)
    ('part = { shape = "sector", inner_radius = 0.08, outer_radius = 0.07, angle_deg = 90.0, '
     'thickness = 0.02 }', "part.outer_radius", 0.07),
    ('part = "sector"', "counterweights.part", "sector"),
])
def test_a_bad_part_is_one_error_naming_key_and_value(part, key, value):
    from balancer.spec import loads_design

    with pytest.raises(SpecError) as caught:
        loads_design(spec_with(part))
    error = caught.value
    assert error.key.startswith("balance.counterweights") and error.key.endswith(key)
    assert error.value == value and "\n" not in str(error)


# -- the command line ------------------------------------------------------------------------

def test_optimize_cad_writes_each_planes_sector_whole(tmp_path, capsys):
    pytest.importorskip("build123d", reason="the cad extra")
    from balancer.cli import main

    folder = tmp_path / "webs"
    assert main(["optimize", str(EXAMPLE), "--no-verify", "--backend", "convex", "--json",
                 "--cad", str(folder)]) == 0
    doc = json.loads(capsys.readouterr().out)
    names = ["crankshaft_z-113.5mm", "crankshaft_z113.5mm"]
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        f"{n}.{x}" for n in names for x in ("dxf", "png", "step", "svg"))
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    for name, cw in zip(names, doc["crankshaft_counterweights"], strict=True):
        part = doc["parts"][name]
        assert part["exact"] and part["z"] == cw["z"]
        assert part["built"]["mr"] == pytest.approx(cw["mr"], rel=1e-9)
        made = part["made"]
        vector = made["mass"] * complex(made["e"], made["f"])
        assert vector == pytest.approx(cmath.rect(cw["mr"], math.radians(cw["phase_deg"])),
                                       rel=1e-9)
    assert doc["as_built"]["rocking_couple"]["rms"] == pytest.approx(
        doc["after"]["rocking_couple"]["rms"], rel=1e-9)


def test_cad_for_an_engine_without_a_part_is_one_line_and_exit_2(tmp_path, capsys):
    from balancer.cli import main

    spec = tmp_path / "engine.toml"
    spec.write_text(spec_with(None))
    folder = tmp_path / "webs"
    assert main(["optimize", str(spec), "--no-verify", "--cad", str(folder)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "balance.counterweights.part" in err
    assert not folder.exists()


def test_the_text_report_has_each_planes_sector_only_with_a_part(capsys):
    from balancer.cli import main

    assert main(["optimize", str(EXAMPLE), "--no-verify", "--backend", "convex"]) == 0
    out = capsys.readouterr().out
    assert "crankshaft_z-113.5mm" in out and "as built: RMS shaking force" in out
    path = ROOT / "examples" / "inline_three_to_balance.toml"
    assert main(["optimize", str(path), "--no-verify", "--backend", "convex", "--json"]) == 0
    assert "parts" not in json.loads(capsys.readouterr().out)
