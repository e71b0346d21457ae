"""The figure along a motion (``balancer plot SPEC --motion NAME --cycle PATH``).

What it draws is the analysis' own arrays (read back from the figure's lines), its titles give
the analysis' RMS and maximum (rounding read as 0), the drawn path of the marker point passes
through the motion's waypoints (from the forward kinematics at the inverse kinematics' states),
and the command line writes the file its extension names, or nothing. The Forbal-2 example with
few samples keeps it fast.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from linkage.several_inputs_specs import crank_rocker

import balancer
from balancer.api.analysis import analyze_motion
from balancer.cli import main
from balancer.errors import SpecError
from balancer.mechanisms import geometry
from balancer.plots.style import number
from balancer.spec import loads_design
from balancer.spec.reader import design_from_dict
from balancer.spec.writer import dumps_design

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: The Forbal-2 robot's motions, each with this many states (the spec's 400: slower, the same).
SAMPLES = 41


def forbal2_text(law: str | None = None) -> str:
    """examples/forbal2.toml with :data:`SAMPLES` states per motion; with ``law``, the diamond
    run by that law (another than the trapezoid: its ``acc_time`` left out)."""
    text = (EXAMPLES / "forbal2.toml").read_text(encoding="utf-8")
    text = text.replace("samples = 400", f"samples = {SAMPLES}")
    if law not in (None, "trapezoid"):
        head, rest = text.split('name = "diamond"', 1)
        diamond, others = rest.split("[[motion]]", 1)
        diamond = diamond.replace('law = "trapezoid"\nacc_time = 0.5', f'law = "{law}"')
        text = f'{head}name = "diamond"{diamond}[[motion]]{others}'
    return text


@pytest.fixture(scope="module")
def forbal2():
    return loads_design(forbal2_text(), source="forbal2.toml")


def _curves(ax):
    return [line for line in ax.get_lines() if np.size(line.get_xdata()) > 2]


def _panels(fig):
    """The figure's axes by the first line of their titles."""
    return {ax.get_title().split("\n")[0]: ax for ax in fig.axes}


def _figures(ax) -> str:
    return ax.get_title().split("\n")[1]


@pytest.mark.slow  # (the full suite's: the fast lane's minute)
def test_the_figure_draws_the_analysis_arrays_and_titles_its_figures(forbal2):
    analysis = analyze_motion(forbal2, "diamond")
    # what `analyze` reports along the motion (the same states, gravity and loads)
    reported = balancer.analyze_motions(forbal2, ["diamond"]).motions[0]
    for key in ("shaking_force", "shaking_moment"):
        np.testing.assert_array_equal(getattr(analysis.reactions, key),
                                      getattr(reported.reactions, key))
    np.testing.assert_array_equal(analysis.reactions.torques, reported.reactions.torques)
    fig = balancer.motion_figure(analysis, balancer.motion_drawing(analysis),
                                 title=forbal2.title)
    panels = _panels(fig)
    r, t, loads = analysis.reactions, analysis.t, analysis.loads()
    force = panels["shaking force"]
    x, y, size = _curves(force)
    assert [c.get_label() for c in (x, y, size)] == ["x component", "y component", "magnitude"]
    for line, values in ((x, r.shaking_force.real), (y, r.shaking_force.imag),
                         (size, np.abs(r.shaking_force))):
        np.testing.assert_array_equal(line.get_xdata(), t)
        np.testing.assert_array_equal(line.get_ydata(), values)
    assert force.get_ylabel() == "shaking force (N)"
    assert _figures(force) == (f"RMS {number(loads['shaking_force'].rms)} N, "
                               f"max {number(loads['shaking_force'].max)} N")
    drawn = [("shaking moment about the origin", "shaking_moment", r.shaking_moment),
             *((f"torque on {name}", f"torque_{name}", torque)
               for name, torque in zip(analysis.inputs, r.torques, strict=True))]
    assert [title for title, _, _ in drawn] == ["shaking moment about the origin",
                                                "torque on link11", "torque on link21"]
    for title, key, values in drawn:
        ax = panels[title]
        (line,) = _curves(ax)
        np.testing.assert_array_equal(line.get_xdata(), t)
        np.testing.assert_array_equal(line.get_ydata(), values)
        assert ax.get_ylabel() == f"{title} (N·m)"
        assert _figures(ax) == (f"RMS {number(loads[key].rms)} N·m, "
                                f"max {number(loads[key].max)} N·m")
        # (the figures are the analysis': RMS over the samples, the largest magnitude)
        assert loads[key].rms == pytest.approx(np.sqrt(np.mean(values**2)), rel=1e-12)
        assert loads[key].max == np.max(np.abs(values))
    assert "rocking couple" not in panels  # (the robot is in one plane)
    assert panels["torque on link21"].get_xlabel() == "time t (s)"
    assert "Forbal-2" in fig.get_suptitle() and "motion diamond over 4 s" in fig.get_suptitle()
    _check_legends_outside(fig)


def _check_legends_outside(fig):
    """No legend covers any axes of the figure (as tests/plots/test_plots.py's)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    legends = [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend())]
    assert len(legends) == 2
    for legend in legends:
        box = legend.get_window_extent(renderer)
        for ax in fig.axes:
            other = ax.get_window_extent(renderer)
            assert not (box.x0 < other.x1 and other.x0 < box.x1 and box.y0 < other.y1
                        and other.y0 < box.y1), (legend, ax)


def test_the_mechanism_panels_draw_its_poses_path_and_centre_of_mass(forbal2):
    analysis = analyze_motion(forbal2, "diamond")
    drawing = balancer.motion_drawing(analysis, poses=5)
    mech = analysis.mechanism
    # the diamond is closed: its end is its start, left out of the poses
    assert drawing.t.tolist() == [analysis.t[i] for i in (0, 10, 20, 30)]
    fig = balancer.motion_figure(analysis, drawing)
    poses = next(ax for ax in fig.axes if ax.get_title().startswith("the mechanism"))
    lines = {line.get_label(): line for line in poses.get_lines()}
    path = lines["path of E"]
    places = geometry.points(mech, mech.motion_at(analysis.state))
    np.testing.assert_array_equal(path.get_xdata(), places["E"].real)
    np.testing.assert_array_equal(path.get_ydata(), places["E"].imag)
    waypoints = lines["waypoints of E"]
    np.testing.assert_array_equal(waypoints.get_xdata(), [p[0] for p in analysis.motion.path])
    centre = geometry.total_centre_of_mass(mech, mech.motion_at(analysis.state))
    track = lines["track of the total centre of mass"]
    np.testing.assert_array_equal(track.get_xdata(), centre.real)
    # the links at each pose: 4 links × 4 poses, each its points joined in the spec's order
    links = [line for line in poses.get_lines() if line.get_color() == balancer.plots.COLOURS[
        "link"]]
    assert len(links) == 4 * 4
    first = links[0]  # link11 (O, A) at t = 0
    np.testing.assert_array_equal(first.get_xdata(), [places["O"][0].real, places["A"][0].real])
    # the track magnified about its mean place, mm: the excursion `analyze` reports
    magnified = next(ax for ax in fig.axes if ax.get_xlabel() == "x (mm)")
    (curve,) = _curves(magnified)
    np.testing.assert_allclose(curve.get_xdata() + 1j * curve.get_ydata(),
                               (centre - centre.mean()) * 1e3, rtol=0, atol=1e-15)
    reach = re.search(r"moves up to ([\d.]+) mm", magnified.get_title())
    assert reach and float(reach.group(1)) == pytest.approx(
        1e3 * analysis.centre_of_mass_excursion, rel=1e-3)


@pytest.mark.parametrize(("law", "through"), [("spline", "every"), ("trapezoid", "ends"),
                                              ("quintic", "ends")])
def test_the_drawn_path_passes_through_the_waypoints(law, through):
    """A spline runs at its waypoints' own pace: through each at its time (every 10th of 41
    states over 4 s); the other laws reach the path's waypoints at their time argument's
    values, the first and last at the motion's ends."""
    design = loads_design(forbal2_text(law), source="forbal2.toml")
    analysis = analyze_motion(design, "diamond")
    assert analysis.motion.law == law
    fig = balancer.motion_figure(analysis, balancer.motion_drawing(analysis))
    path = next(line for ax in fig.axes for line in ax.get_lines()
                if line.get_label() == "path of E")
    drawn = np.asarray(path.get_xdata()) + 1j * np.asarray(path.get_ydata())
    waypoints = np.array([complex(*p) for p in analysis.motion.path])
    times = np.asarray(analysis.motion.times)
    at = [0, len(times) - 1] if through == "ends" else range(len(times))
    for k in at:
        i = int(np.flatnonzero(np.isclose(analysis.t, times[k], rtol=0, atol=1e-12))[0])
        assert abs(drawn[i] - waypoints[k]) <= 1e-12, (k, drawn[i], waypoints[k])
    if through == "every":
        assert len(at) == 5


def _balanced_parallelogram():
    from test_motion_analysis import _balanced_parallelogram as spec

    return design_from_dict(spec())


def test_a_balanced_robots_shaking_force_is_drawn_as_zero_and_reads_zero():
    """The parallelogram five-bar balanced in closed form (tests/test_motion_analysis.py): its
    shaking force is rounding (1e-16 N), and its one ground point's force is that force: the
    motors' torques give the scale. Drawn as the zero it is, its figures read 0, its centre of
    mass a dot; the torques keep their digits."""
    design = _balanced_parallelogram()
    analysis = analyze_motion(design, "wave")
    force = np.abs(analysis.reactions.shaking_force)
    assert 0 < np.max(force) <= 1e-12
    fig = balancer.motion_figure(analysis, balancer.motion_drawing(analysis))
    panels = _panels(fig)
    for line in _curves(panels["shaking force"]):
        assert not np.any(line.get_ydata())
    assert _figures(panels["shaking force"]) == "RMS 0 N, max 0 N"
    for name in ("p", "q"):
        text = _figures(panels[f"torque on {name}"])
        assert "RMS 0 " not in text and "max 0 " not in text, text
    assert "total centre of mass: stands still" in panels
    poses = panels["the mechanism along motion wave"]
    assert "total centre of mass: stationary" in [line.get_label() for line in poses.get_lines()]
    assert "path of" not in " ".join(line.get_label() for line in poses.get_lines())


def test_the_figure_without_a_drawing_has_the_loads_alone(forbal2):
    analysis = analyze_motion(forbal2, "circle")
    fig = balancer.motion_figure(analysis)
    assert sorted(_panels(fig)) == sorted(["shaking force", "shaking moment about the origin",
                                           "torque on link11", "torque on link21"])
    other = balancer.motion_drawing(analyze_motion(
        loads_design(forbal2_text().replace(f"samples = {SAMPLES}", "samples = 16"),
                     source="forbal2.toml"), "circle"))
    with pytest.raises(ValueError, match="the drawing is of 16 states, the analysis of 41"):
        balancer.motion_figure(analysis, other)


def test_the_number_of_poses_is_checked(forbal2):
    analysis = analyze_motion(forbal2, "diamond")
    for poses in (0, 51, 2.5, True):
        with pytest.raises(SpecError, match="poses"):
            balancer.motion_drawing(analysis, poses=poses)
    one = balancer.motion_drawing(analysis, poses=1)
    assert one.t.tolist() == [0.0] and all(p.shape == (1, p.shape[1])
                                           for p in one.links.values())
    assert "MotionDrawing(4 links at 1 poses" in repr(one)


# --- the command line --------------------------------------------------------------------------


@pytest.fixture
def forbal2_file(tmp_path):
    spec = tmp_path / "spec" / "forbal2.toml"
    spec.parent.mkdir()
    spec.write_text(forbal2_text(), encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    return spec, out


@pytest.mark.parametrize(("suffix", "magic"), [
    (".png", b"\x89PNG\r\n\x1a\n"),
    pytest.param(".svg", b"<svg", marks=pytest.mark.slow),  # (a second or so each: the full
    pytest.param(".pdf", b"%PDF", marks=pytest.mark.slow)])  # suite's)
def test_plot_motion_writes_the_type_its_extension_names(forbal2_file, capsys, suffix, magic):
    spec, out = forbal2_file
    path = out / f"diamond{suffix}"
    assert main(["plot", str(spec), "--motion", "diamond", "--cycle", str(path)]) == 0
    assert magic in path.read_bytes()[:500]
    assert [p.name for p in out.iterdir()] == [path.name]
    assert capsys.readouterr().err == f"wrote {path}\n"


@pytest.mark.parametrize("name", ["diamond.jpg", "diamond", "diamond.gif"])
def test_plot_motion_with_another_extension_is_refused_and_writes_nothing(forbal2_file, capsys,
                                                                          name):
    spec, out = forbal2_file
    assert main(["plot", str(spec), "--motion", "diamond", "--cycle", str(out / name)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--cycle" in err and ".png, .svg, .pdf" in err
    assert list(out.iterdir()) == []


@pytest.mark.slow
def test_without_motion_several_inputs_draw_the_first_and_say_so(forbal2_file, capsys):
    spec, out = forbal2_file
    path = out / "first.png"
    assert main(["plot", str(spec), "--cycle", str(path)]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == ["balancer: note: drawing motion diamond, the spec's first; --motion NAME "
                   "draws another (circle, figure-eight)", f"wrote {path}"]


@pytest.mark.parametrize(("args", "key", "words"), [
    (["--motion", "nowhere", "--cycle", "c.png"], "--motion", "names no motion of the spec"),
    (["--motion", "diamond", "--orders", "o.png"], "mechanism.inputs", "turns one crank"),
])
def test_what_plot_cannot_draw_along_a_motion_is_refused(forbal2_file, capsys, args, key,
                                                         words):
    spec, out = forbal2_file
    args = [str(out / a) if "." in a else a for a in args]
    assert main(["plot", str(spec), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{key}: " in err and words in err, err
    assert list(out.iterdir()) == []


def _one_input_with_a_motion(z: float = 0.0) -> str:
    """A crank-rocker whose spec gives a motion of its crank (a cubic law over a turn); its
    coupler ``z`` m along the crank's axis from the others."""
    spec: dict = crank_rocker() | {
        "operation": {"speed": 10.0},
        "motion": [{"name": "turn", "times": [0.0, 0.5, 1.0],
                    "path": [[0.0], [np.pi], [2 * np.pi]], "law": "cubic", "samples": 16}],
    }
    if z:
        spec["links"]["coupler"]["z"] = z
    return dumps_design(design_from_dict(spec))


@pytest.mark.slow
def test_a_one_input_linkage_is_drawn_along_its_motion_when_asked(tmp_path, capsys):
    spec = tmp_path / "crank.toml"
    spec.write_text(_one_input_with_a_motion(), encoding="utf-8")
    design = loads_design(spec.read_text(encoding="utf-8"))
    analysis = analyze_motion(design, "turn")
    fig = balancer.motion_figure(analysis, balancer.motion_drawing(analysis))
    panels = _panels(fig)
    assert "torque on crank" in panels and "the mechanism along motion turn" in panels
    (line,) = _curves(panels["torque on crank"])
    np.testing.assert_array_equal(line.get_ydata(), analysis.reactions.driving_torque)
    motion, cycle = tmp_path / "turn.png", tmp_path / "cycle.png"
    assert main(["plot", str(spec), "--motion", "turn", "--cycle", str(motion)]) == 0
    assert main(["plot", str(spec), "--cycle", str(cycle)]) == 0  # (a revolution, as ever)
    assert motion.read_bytes()[:4] == cycle.read_bytes()[:4] == b"\x89PNG"
    capsys.readouterr()
    gif = tmp_path / "turn.gif"  # (and the crank turning along its motion)
    assert main(["plot", str(spec), "--motion", "turn", "--animate", str(gif),
                 "--frames", "6"]) == 0
    assert gif.read_bytes()[:3] == b"GIF"


def test_an_animation_runs_along_the_motion(forbal2_file):
    # Along the robot's first motion: the frames at equally spaced times of it, its readout
    # the time; the total centre of mass drawn is the links' centres weighed by their masses.
    from balancer.linkage import trajectory
    from balancer.mechanisms import mechanism_of
    from balancer.plots.animation import _frames_of
    from balancer.plots.drawing import drawing_frames

    spec, _ = forbal2_file
    design = loads_design(spec.read_text(encoding="utf-8"))
    diamond = design.motions[0]
    mech = mechanism_of(design.mechanism)
    states, readouts = _frames_of(design.mechanism, 9, diamond)
    assert readouts[0] == "diamond: t = 0 s" and readouts[-1] == "diamond: t = 4 s"
    want = trajectory.input_state(mech.structure, diamond, np.linspace(0.0, 4.0, 9))
    for a, b in zip(states.positions, want.positions, strict=True):
        np.testing.assert_array_equal(a, b)
    _, coms, total = drawing_frames(design.mechanism, states)
    masses = np.array([link.mass for link in mech.linkage.links])
    weighed = sum(m * coms[name] for m, name in zip(masses, mech.linkage.link_names, strict=True))
    np.testing.assert_allclose(total, weighed / masses.sum(), rtol=0, atol=1e-15)
    from balancer.plots import animation_figure

    fig, update = animation_figure(design, frames=9)  # (several inputs: the first)
    artists = update(4)
    assert any(getattr(a, "get_text", lambda: "")() == readouts[4] for a in artists)


def test_links_in_several_planes_add_the_rocking_couple():
    analysis = analyze_motion(loads_design(_one_input_with_a_motion(z=0.05)), "turn")
    couple = analysis.reactions.rocking_couple
    assert np.max(np.abs(couple)) > 0.1
    fig = balancer.motion_figure(analysis)
    panels = _panels(fig)
    assert list(panels) == ["shaking force", "shaking moment about the origin", "rocking couple",
                            "torque on crank"]
    ax = panels["rocking couple"]
    for line, values in zip(_curves(ax), (couple.real, couple.imag, np.abs(couple)),
                            strict=True):
        np.testing.assert_array_equal(line.get_ydata(), values)
    figure = analysis.loads()["rocking_couple"]
    assert _figures(ax) == f"RMS {number(figure.rms)} N·m, max {number(figure.max)} N·m"
