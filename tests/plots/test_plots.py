"""Report figures: what they draw is the computation's numbers, and files are what was asked.

``balancer plot --cycle`` (one revolution: the shaking force's polar diagram, the shaking moment
and driving torque over the crank angle, before and after), the animations' file types (GIF,
MP4), and the placement of legends (outside the data).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from balancer import api, cycle, outputs, plots
from balancer.api import analyze
from balancer.cli import main
from balancer.mechanisms import geometry, mechanism_of
from balancer.mechanisms.base import in_one_plane
from balancer.plots import drawing, style
from balancer.rounding import speed_text
from balancer.spec import load_design
from balancer.sweeps import atlas_figure

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: One of each mechanism type: four-bar, slider-crank (gas force), general linkages.
SPECS = ("meijaard2020", "engine", "jansen_leg", "quick_return")


@pytest.fixture(scope="module")
def pb1_balanced(tmp_path_factory):
    out = tmp_path_factory.mktemp("pb1") / "balanced.toml"
    assert main(["optimize", str(EXAMPLES / "pb1.toml"), "--out", str(out), "--no-verify",
                 "--backend", "convex", "--json"]) == 0
    return out


def _lines(ax):
    """The axes' curves with data (the θ1 = 0 dots and the axis lines left out)."""
    return [line for line in ax.get_lines() if len(line.get_xdata()) > 2]


def _closed(values):
    return np.append(values, values[:1])


def _drawn(a, key):
    """What a panel draws of an analysis: its values, or zeros where all are rounding.

    Rounding: every sample below 1e-9 of the largest force on one ground point or guide (times
    the linkage's size for a moment), the scale the loads that cancel are made of.
    """
    values = getattr(a.reactions, key)
    force = max(np.max(np.abs(v)) for v in (*a.reactions.ground.values(),
                                            *a.reactions.slider_normal.values()))
    scale = force * (1.0 if key == "shaking_force" else a.mechanism.structure.length_scale())
    return np.zeros_like(values) if np.max(np.abs(values)) <= 1e-9 * scale else values


def _check_cycle_figure(fig, after, before):
    force, moment, torque = fig.axes
    curves = [a for a in (before, after) if a is not None]
    # The polar diagram: the shaking force's tip, x against y, closed over the revolution.
    lines = _lines(force)
    assert len(lines) == len(curves)
    for line, a in zip(lines, curves, strict=True):
        f = _closed(_drawn(a, "shaking_force"))
        np.testing.assert_array_equal(line.get_xdata(), f.real)
        np.testing.assert_array_equal(line.get_ydata(), f.imag)
    for ax, key in ((moment, "shaking_moment"), (torque, "driving_torque")):
        lines = _lines(ax)
        assert len(lines) == len(curves)
        for line, a in zip(lines, curves, strict=True):
            np.testing.assert_allclose(line.get_xdata(), np.degrees(_closed(a.theta1)) +
                                       np.r_[np.zeros(a.samples), 360.0])
            np.testing.assert_array_equal(line.get_ydata(), _closed(_drawn(a, key)))
        assert ax.get_xlabel() == "crank angle θ1 (°)" and ax.get_ylabel().endswith("(N·m)")
    assert force.get_xlabel().endswith("(N)") and force.get_ylabel().endswith("(N)")


def test_rounding_is_drawn_as_zero_and_labelled_with_its_figures(pb1_balanced):
    # The balanced PB1's shaking force is rounding (about 1e-13 N against reactions of
    # hundreds): drawn as the point at the origin it is, its label still giving the figures.
    after, _ = api.cycle_analyses(load_design(pb1_balanced))
    fig = plots.cycle_figure(after)
    force = fig.axes[0]
    line = _lines(force)[0]
    assert not np.any(line.get_xdata()) and not np.any(line.get_ydata())
    assert 0 < np.max(np.abs(after.reactions.shaking_force)) < 1e-9
    assert "max" in line.get_label() and "e-" in line.get_label()


@pytest.mark.parametrize("name", SPECS)
def test_the_cycle_figure_draws_the_cycle_analysis_of_every_mechanism(name):
    design = load_design(EXAMPLES / f"{name}.toml")
    after, before = api.cycle_analyses(design)
    assert before is None
    # At least the spec's samples, and the arrays are those of the design's own analysis at
    # that many angles (the same route, speed, gravity and loads as `analyze`).
    assert after.samples >= max(design.operation.samples, cycle.PLOT_SAMPLES[0])
    reference = analyze(replace(design, operation=replace(design.operation,
                                                          samples=after.samples)))
    for key in ("shaking_force", "shaking_moment", "driving_torque"):
        np.testing.assert_array_equal(getattr(after.reactions, key),
                                      getattr(reference.reactions, key))
    fig = plots.cycle_figure(after, title=design.title)
    _check_cycle_figure(fig, after, None)


@pytest.mark.parametrize("name", SPECS)
def test_the_sampling_draws_every_curve_within_a_pixel(name):
    # Checked independently of the refinement: at the midpoints between the drawn samples, the
    # curves lie within DRAWING_TOLERANCE of the panel's span from the drawn chords.
    design = load_design(EXAMPLES / f"{name}.toml")
    after, _ = api.cycle_analyses(design)
    n = after.samples
    mid = analyze(replace(design, operation=replace(design.operation, samples=2 * n)))
    for key in ("shaking_force", "shaking_moment", "driving_torque"):
        drawn, between = getattr(after.reactions, key), getattr(mid.reactions, key)[1::2]
        chord = 0.5 * (drawn + np.roll(drawn, -1))
        span = max(np.ptp(drawn.real), np.ptp(drawn.imag))
        assert np.max(np.abs(between - chord)) <= cycle.DRAWING_TOLERANCE * span


def test_a_curve_with_a_sharp_feature_is_sampled_more_finely_than_a_smooth_one():
    # The engine's gas force rises steeply after top dead centre; the paper's four-bar is smooth.
    engine = api.cycle_analyses(load_design(EXAMPLES / "engine.toml"))[0]
    smooth = api.cycle_analyses(load_design(EXAMPLES / "meijaard2020.toml"))[0]
    coarse = api.cycle_analyses(load_design(EXAMPLES / "engine.toml"), samples=16)[0]
    assert coarse.samples == 16
    assert engine.samples >= smooth.samples
    fine_spec = load_design(EXAMPLES / "meijaard2020.toml")
    fine_spec = replace(fine_spec, operation=replace(fine_spec.operation, samples=5000))
    assert api.cycle_analyses(fine_spec)[0].samples >= 5000


def test_before_and_after_are_the_original_and_the_balanced_design(pb1_balanced):
    balanced = load_design(pb1_balanced)
    original = load_design(EXAMPLES / "pb1.toml")
    after, before = api.cycle_analyses(balanced)
    assert before is not None and before.samples == after.samples
    for analysis, design in ((after, balanced), (before, original)):
        reference = analyze(replace(design, operation=replace(design.operation,
                                                              samples=analysis.samples)))
        for key in ("shaking_force", "shaking_moment", "driving_torque"):
            np.testing.assert_allclose(getattr(analysis.reactions, key),
                                       getattr(reference.reactions, key), rtol=0, atol=1e-9)
    # The balanced design's shaking force vanishes; the original's does not.
    assert np.max(np.abs(after.reactions.shaking_force)) < 1e-6 * np.max(
        np.abs(before.reactions.shaking_force))
    fig = plots.cycle_figure(after, before, title="PB1")
    _check_cycle_figure(fig, after, before)
    _check_legends_outside(fig)
    assert "before and after" in fig.get_suptitle()


def _overlaps(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def _check_legends_outside(fig):
    """No legend covers the data area of any axes of the figure."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    legends = [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend())]
    assert legends
    for legend in legends:
        box = legend.get_window_extent(renderer)
        for ax in fig.axes:
            assert not _overlaps(box, ax.get_window_extent(renderer)), (legend, ax)


@pytest.mark.parametrize(("suffix", "magic"), [(".png", b"\x89PNG"), (".svg", b"<svg"),
                                               (".pdf", b"%PDF")])
@pytest.mark.slow
def test_plot_cycle_writes_the_type_its_extension_names(tmp_path, capsys, pb1_balanced, suffix,
                                                         magic):
    out = tmp_path / f"cycle{suffix}"
    assert main(["plot", str(pb1_balanced), "--cycle", str(out)]) == 0
    assert magic in out.read_bytes()[:500]
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]
    assert capsys.readouterr().err == f"wrote {out}\n"


@pytest.mark.parametrize("name", ["cycle.jpg", "cycle", "cycle.gif", "cycle.mp4"])
def test_plot_cycle_with_another_extension_is_refused_before_any_work(tmp_path, capsys, name):
    assert main(["plot", str(EXAMPLES / "pb1.toml"), "--cycle", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--cycle" in err and ".png, .svg, .pdf" in err
    assert list(tmp_path.iterdir()) == []


def test_plot_needs_something_to_draw_and_distinct_paths(tmp_path, capsys):
    spec = str(EXAMPLES / "pb1.toml")
    assert main(["plot", spec]) == 2
    assert ("--cycle PATH, --orders PATH, --phasors PATH or --animate PATH"
            in capsys.readouterr().err)
    assert main(["plot", spec, "--cycle", str(tmp_path / "a.png"), "--animate",
                 str(tmp_path / "a.png")]) == 2
    assert "same file" in capsys.readouterr().err
    assert main(["plot", spec, "--cycle", str(tmp_path / "a.png"), "--orders",
                 str(tmp_path / "a.png")]) == 2
    assert "--orders: names the same file as --cycle" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("name", "panels"), [("pb1_counterweights", 3), ("two_plane_drive", 4)])
@pytest.mark.slow
def test_plot_orders_draws_the_order_table(tmp_path, capsys, name, panels):
    """Bars of `analyze`'s orders: force, (rocking couple in planes,) moment, torque; the
    heights are the order table's, before and after for a spec with [original]."""
    from balancer.api import cycle_analyses
    from balancer.plots import orders_figure
    from balancer.spec import load_design

    out = tmp_path / "orders.png"
    spec = EXAMPLES / f"{name}.toml"
    assert main(["plot", str(spec), "--orders", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    design = load_design(spec)
    after, before = cycle_analyses(design, samples=design.operation.samples)
    fig = orders_figure(after, before)
    assert len(fig.axes) == panels
    force = fig.axes[0]
    heights = sorted(round(p.get_height(), 9) for p in force.patches)
    want = sorted(round(v, 9) for a in ([after] if before is None else [before, after])
                  for o in a.orders for v in (o.shaking_force.forward, o.shaking_force.backward))
    assert heights == want


def test_plot_cycle_of_a_crank_that_cannot_turn_is_bad_input(tmp_path, capsys):
    text = (EXAMPLES / "meijaard2020.toml").read_text().replace("crank = 1.0", "crank = 2.9")
    spec = tmp_path / "rocking.toml"
    spec.write_text(text)
    out = tmp_path / "c.png"
    assert main(["plot", str(spec), "--cycle", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "a cycle plot needs a crank that turns a full revolution" in err
    assert not out.exists()


@pytest.mark.slow
def test_cycle_and_animation_in_one_call(tmp_path, capsys):
    cycle, gif = tmp_path / "c.pdf", tmp_path / "a.gif"
    assert main(["plot", str(EXAMPLES / "engine.toml"), "--cycle", str(cycle), "--animate",
                 str(gif), "--frames", "4"]) == 0
    assert cycle.read_bytes()[:4] == b"%PDF" and gif.read_bytes()[:3] == b"GIF"
    capsys.readouterr()


needs_ffmpeg = pytest.mark.skipif(outputs.ffmpeg() is None,
                                  reason="no ffmpeg (pip install imageio-ffmpeg)")


@needs_ffmpeg
@pytest.mark.slow
def test_an_mp4_animation_has_one_frame_per_crank_angle(tmp_path, capsys):
    import subprocess

    out = tmp_path / "run.mp4"
    assert main(["plot", str(EXAMPLES / "watt_sixbar.toml"), "--animate", str(out),
                 "--frames", "10"]) == 0
    assert out.read_bytes()[4:8] == b"ftyp"  # an ISO media file
    # ffmpeg decodes it back: 10 frames.
    probe = subprocess.run([outputs.ffmpeg(), "-i", str(out), "-map", "0:v:0", "-f", "null", "-"],
                           capture_output=True, text=True, check=True)
    assert "frame=   10" in probe.stderr.replace("frame=10", "frame=   10")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.mp4"]
    capsys.readouterr()


def test_an_mp4_without_ffmpeg_is_refused_before_any_work(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(outputs, "ffmpeg", lambda: None)
    out = tmp_path / "run.mp4"
    assert main(["plot", str(EXAMPLES / "pb1.toml"), "--animate", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--animate" in err and "needs ffmpeg" in err
    assert ".gif" in err and list(tmp_path.iterdir()) == []


def test_a_failing_ffmpeg_leaves_nothing_behind(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(outputs, "ffmpeg", lambda: "/bin/false")
    out = tmp_path / "run.mp4"
    assert main(["plot", str(EXAMPLES / "pb1.toml"), "--animate", str(out), "--frames",
                 "3"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "ffmpeg could not write the MP4" in err
    assert list(tmp_path.iterdir()) == []


def test_every_animation_extension_is_checked(tmp_path):
    assert set(outputs.ANIMATION_TYPES) == {".gif", ".mp4"}
    assert set(outputs.FIGURE_TYPES) == {".png", ".svg", ".pdf"}
    for name in ("a.GIF", "a.Mp4"):
        assert outputs.figure_type(tmp_path / name, types=outputs.ANIMATION_TYPES) in {"gif", "mp4"}


# --- verify's figure: before and after on every panel, legends outside, no aliasing -------


def _verify(path, **kw):
    from balancer.verification import verify

    return verify(load_design(path), **kw)


@pytest.mark.slow
def test_the_verification_figure_draws_before_and_after_on_every_panel(pb1_balanced):
    design = load_design(pb1_balanced)
    from balancer.verification import verify

    v = verify(design, duration=0.3)
    fig = plots.verification_figure(design, v)
    axes = np.array(fig.axes).reshape(3, 2)
    for col, run in enumerate((v.driven, v.free)):
        after, before = run.trajectory, run.original
        assert after is not None and before is not None
        forces, moment, com = axes[:, col]
        # Forces on the ground: each ground point's magnitude and the sum's, before then after.
        lines = _lines(forces)
        expected = [np.abs(values) for r in (before, after) for values in r.ground.values()]
        sums = [np.abs(r.shaking_force) for r in (before, after)]
        drawn = [line.get_ydata() for line in lines]
        assert len(drawn) == len(expected) + len(sums)
        for values in [*expected, *sums]:
            assert any(np.array_equal(values, d) for d in drawn)
        for line in lines:
            t = line.get_xdata()
            assert np.array_equal(t, before.t) or np.array_equal(t, after.t)
        # Shaking moment, before and after.
        drawn = [line.get_ydata() for line in _lines(moment)]
        assert len(drawn) == 2
        np.testing.assert_array_equal(drawn[0], before.shaking_moment)
        np.testing.assert_array_equal(drawn[1], after.shaking_moment)
        # Path of the total centre of mass: the original's curve, the balanced one's point.
        labels = [line.get_label() for line in com.get_lines()]
        assert "before (original)" in labels and any(x.startswith("after") for x in labels)
        assert forces.get_ylabel().endswith("(N)") and moment.get_ylabel().endswith("(N·m)")
        assert com.get_xlabel() == "x (m)" and forces.get_xlabel() == "time t (s)"
    _check_legends_outside(fig)


@pytest.mark.slow
def test_a_design_without_an_original_keeps_the_papers_components():
    v = _verify(EXAMPLES / "meijaard2020.toml", duration=0.2)
    design = load_design(EXAMPLES / "meijaard2020.toml")
    fig = plots.verification_figure(design, v)
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert labels == ["$R_{A0x}$", "$R_{A0y}$", "$R_{A3x}$", "$R_{A3y}$", "sum, x", "sum, y"]
    np.testing.assert_array_equal(fig.axes[0].get_lines()[4].get_ydata(),
                                  v.driven.trajectory.shaking_force.real)
    _check_legends_outside(fig)


def test_verify_samples_every_run_finely_enough_to_draw_it():
    # The paper's four-bar driven at 10 rad/s for 5 s turns eight times: 501 outputs would
    # give 6° steps; verify takes at least PER_REVOLUTION a turn.
    from balancer import verification as verify_module

    v = _verify(EXAMPLES / "meijaard2020.toml")
    step = 2 * np.pi / verify_module.PER_REVOLUTION
    driven = v.driven.trajectory
    assert driven.t.size > 501
    assert np.max(np.abs(np.diff(driven.theta[0]))) <= step * (1 + 1e-9)
    assert np.max(np.abs(np.diff(v.free.trajectory.theta[0]))) <= step


def test_a_free_run_faster_than_estimated_gets_finer_outputs(tmp_path, monkeypatch):
    from balancer import verification as verify_module

    monkeypatch.setattr(verify_module, "FREE_MARGIN", 0.01)  # a poor first estimate
    text = (EXAMPLES / "meijaard2020.toml").read_text().replace("omega1 = 0.0", "omega1 = 30.0")
    spec = tmp_path / "fast.toml"
    spec.write_text(text)
    calls = []
    v = _verify(spec, duration=1.0, progress=lambda done, total: calls.append((done, total)))
    free = v.free.trajectory
    assert free.t.size > 501  # 30 rad/s for 1 s in 500 steps would be 3.4° a step
    assert np.max(np.abs(np.diff(free.theta[0]))) <= 2 * np.pi / verify_module.PER_REVOLUTION
    # The outputs are resampled from the steps, not run again: the progress counts the two
    # simulations once each, in simulated seconds.
    done, total = np.array(calls).T
    assert np.all(np.diff(done) >= 0) and np.all(total == pytest.approx(2.0))
    assert done[-1] == pytest.approx(2.0)


def test_verify_with_given_outputs_takes_them_as_they_are():
    v = _verify(EXAMPLES / "meijaard2020.toml", duration=1.0, outputs=11)
    assert v.driven.trajectory.t.size == 11 and v.free.trajectory.t.size == 11


def test_counterweights_turn_with_their_links_in_the_animation(tmp_path):
    """Each counterweight's centre is carried rigidly by its link: at every frame it lies at
    its (e, f) in the link's frame, i.e. A0 + e^{iθ1}·(e + i·f) for the crank, whose angle the
    frames sample evenly; the animation of a balanced spec draws them."""
    import balancer
    from balancer.plots.drawing import counterweight_paths, revolution

    design = balancer.example("pb1_counterweights")
    result = balancer.optimize(design, backend="convex")
    balanced = result.balanced_design(design)
    frames = 16
    paths = counterweight_paths(balanced.mechanism, result.counterweights,
                                revolution(frames))
    assert set(paths) == {"crank", "rocker"}
    centres, radius = paths["crank"]
    w = result.counterweights["crank"]
    theta = 2 * np.pi * np.arange(frames) / frames
    expected = np.exp(1j * theta) * complex(w.e, w.f)  # A0 at the origin
    assert np.max(np.abs(centres - expected)) <= 8 * np.finfo(float).eps * abs(expected[0])
    assert radius == w.disc_radius
    rocker, _ = paths["rocker"]
    pivot = complex(design.mechanism.lengths[3], 0.0)  # A3
    distance = np.abs(rocker - pivot)  # rigid: constant distance from the rocker's pivot
    assert np.ptp(distance) <= 1e-12 * distance[0]
    out = tmp_path / "balanced.gif"
    spec = tmp_path / "balanced.toml"
    balancer.save_design(balanced, spec)
    from balancer.cli import main

    assert main(["plot", str(spec), "--animate", str(out), "--frames", "6"]) == 0
    assert out.read_bytes()[:6] == b"GIF89a"


# --- sweep atlases: axes in units, the original marked, no-design cells told apart --------


COUPLER, FRAME = "mechanism.lengths.coupler", "mechanism.lengths.frame"


def _atlas_table(path, statuses, keys=(COUPLER, FRAME), values=((2.5, 3.0, 3.5), (3.0, 3.2))):
    """A sweep's table over a grid of ``keys``; the given statuses row by row (those without
    a balanced design have no ``after``)."""
    import itertools

    import pyarrow as pa
    import pyarrow.parquet as pq

    points = list(itertools.product(*values))
    rows = [{**dict(zip(keys, p, strict=True)), "point": i, "status": s,
             "shaking_moment_before": 200.0 + i, "shaking_force_before": 400.0,
             "shaking_moment_after": 100.0 + i if s == "optimal" else None}
            for i, (p, s) in enumerate(zip(points, statuses, strict=True))]
    pq.write_table(pa.Table.from_pylist(rows), path)
    return path


@pytest.mark.parametrize(("key", "unit"), [
    ("mechanism.lengths.coupler", "m"), ("mechanism.points.B.1", "m"), ("links.crank.com.e", "m"),
    ("links.crank.com.f", "m"), ("links.rocker.com.s", "m"), ("links.crank.mass", "kg"),
    ("links.crank.inertia", "kg·m²"), ("links.rocker.counter_rotor", "kg·m²"),
    ("links.crank.com.sigma", "rad"), ("operation.speed", "rad/s"),
    ("links.coupler.force.0", "N"), ("links.coupler.moment", "N·m"),
    ("balance.crank.mass.1", "kg"), ("balance.crank.counterweight.radius", "m"),
    ("operation.samples", ""), ("balance.objective.driving_torque", "")])
def test_a_spec_keys_unit_comes_from_the_key(key, unit):
    from balancer.sweeps import key_unit

    assert key_unit(key) == unit


def test_the_atlas_names_its_axes_with_units_marks_the_original_and_tells_empty_cells_apart(
        tmp_path):
    from matplotlib.collections import PolyCollection

    statuses = ["bad-geometry", "infeasible", "optimal", "infeasible", "optimal", "optimal"]
    path = _atlas_table(tmp_path / "atlas.parquet", statuses)
    fig = atlas_figure(path, [COUPLER, FRAME], original={COUPLER: 3.0, FRAME: 3.2})
    ax = fig.axes[0]
    assert ax.get_xlabel() == f"{COUPLER} (m)" and ax.get_ylabel() == f"{FRAME} (m)"
    # The original design: a marker at the spec's values.
    marks = [line for line in ax.get_lines() if line.get_label().startswith("original design")]
    assert len(marks) == 1
    assert list(marks[0].get_xdata()) == [3.0] and list(marks[0].get_ydata()) == [3.2]
    # The cells without a design: one hatched layer per status, covering exactly its cells,
    # and a legend entry for each that a reader tells apart.
    layers = [c for c in ax.collections if isinstance(c, PolyCollection) and c.get_hatch()]
    assert sorted(int(np.ma.count(c.get_array())) for c in layers) == [1, 2]
    assert len({c.get_hatch() for c in layers}) == 2
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    assert any(label.startswith("infeasible") for label in labels)
    assert any(label.startswith("bad geometry") for label in labels)
    assert any(label.startswith("original design") for label in labels)


def test_an_original_outside_the_swept_ranges_is_an_arrow_at_the_edge(tmp_path):
    path = _atlas_table(tmp_path / "atlas.parquet", ["optimal"] * 6)
    fig = atlas_figure(path, [COUPLER, FRAME], original={COUPLER: 3.0, FRAME: 4.5})
    ax = fig.axes[0]
    limits = ax.get_ylim()
    assert limits[1] < 4.0  # the map keeps the swept ranges
    assert any(t.arrow_patch is not None for t in ax.texts)
    assert any(f"{FRAME} = 4.5 m" in t.get_text() for t in ax.texts)
    # The marker keeps the coordinate that lies within the limits: the coupler's 3.0 m.
    (mark,) = (line for line in ax.get_lines() if line.get_label().startswith("original"))
    (x0, x1) = ax.get_xlim()
    assert mark.get_xdata()[0] == pytest.approx((3.0 - x0) / (x1 - x0))
    assert mark.get_ydata()[0] == pytest.approx(1.0 - style.EDGE_INSET)


def test_one_varied_key_has_its_unit_and_the_original_and_no_design_points(tmp_path):
    path = _atlas_table(tmp_path / "line.parquet", ["bad-geometry", "infeasible", "optimal"],
                        keys=("links.crank.mass",), values=((2.0, 3.0, 4.0),))
    fig = atlas_figure(path, ["links.crank.mass"], original={"links.crank.mass": 2.1})
    ax = fig.axes[0]
    assert ax.get_xlabel() == "links.crank.mass (kg)"
    labels = {line.get_label(): line for line in ax.get_lines()}
    assert "original design: links.crank.mass = 2.1 kg" in labels
    assert list(labels["original design: links.crank.mass = 2.1 kg"].get_xdata()) == [2.1, 2.1]
    missing = [line for name, line in labels.items()
               if name.startswith(("infeasible", "bad geometry"))]
    assert sorted(float(line.get_xdata()[0]) for line in missing) == [2.0, 3.0]


def test_a_scattered_atlas_marks_the_points_without_a_design(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows = [{COUPLER: c, FRAME: f, "point": i, "status": s, "shaking_moment_before": 1.0,
             "shaking_force_before": 1.0, "shaking_moment_after": 1.0 if s == "optimal" else None}
            for i, (c, f, s) in enumerate([(2.1, 3.0, "optimal"), (2.6, 3.3, "infeasible"),
                                           (3.4, 2.9, "bad-geometry"), (3.0, 3.1, "optimal")])]
    pq.write_table(pa.Table.from_pylist(rows), tmp_path / "lhs.parquet")
    fig = atlas_figure(tmp_path / "lhs.parquet", [COUPLER, FRAME],
                             original={COUPLER: 3.0, FRAME: 3.2})
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    assert [label.split(":")[0] for label in labels] == ["infeasible", "bad geometry",
                                                         "original design"]


def test_the_sweep_command_marks_the_specs_design_on_its_atlas(tmp_path, monkeypatch, capsys):
    drawn = []
    monkeypatch.setattr("balancer.cli.sweep.save_figure", lambda fig, path: drawn.append(fig))
    out = tmp_path / "atlas.parquet"
    assert main(["sweep", str(EXAMPLES / "pb1.toml"), "--vary", f"{COUPLER}=2.6:3.4:2",
                 "--vary", f"{FRAME}=3.0:3.4:2", "--out", str(out), "--workers", "0",
                 "--plot", str(tmp_path / "atlas.png"), "--json"]) == 0
    capsys.readouterr()
    (ax, *_), = (fig.axes for fig in drawn)
    (mark,) = (line for line in ax.get_lines() if line.get_label().startswith("original"))
    assert list(mark.get_xdata()) == [3.0] and list(mark.get_ydata()) == [3.2]


def test_the_tolerance_histogram_names_the_key_its_sigma_and_the_draws(tmp_path, monkeypatch,
                                                                        capsys, pb1_balanced):
    drawn = []
    monkeypatch.setattr("balancer.cli.sweep.save_figure", lambda fig, path: drawn.append(fig))
    assert main(["sweep", str(pb1_balanced), "--perturb", "links.crank.mass=0.01",
                 "--samples", "30", "--out", str(tmp_path / "p.parquet"), "--workers", "0",
                 "--plot", str(tmp_path / "hist.png"), "--json"]) == 0
    capsys.readouterr()
    (fig,) = drawn
    title = fig.axes[0].get_title()
    assert "links.crank.mass = 2.1 kg" in title and "σ = 0.01 kg" in title
    assert "30 designs drawn" in title
    assert fig.axes[0].get_xlabel().endswith("(N)")


# --- trade-off fronts: the axes on the front, the original marked and explained -----------


def _front_figure_of(tmp_path, monkeypatch, capsys, spec, against):
    drawn = []
    monkeypatch.setattr("balancer.cli.pareto.save_figure", lambda fig, path: drawn.append(fig))
    assert main(["pareto", str(spec), "--against", against, "--points", "5", "--plot",
                 str(tmp_path / "front.png"), "--json"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    (fig,) = drawn
    return fig, doc


def _legend_texts(fig):
    return [t.get_text() for legend in fig.legends for t in legend.get_texts()]


def test_a_front_far_from_the_original_keeps_the_axes_on_the_front(tmp_path, monkeypatch,
                                                                   capsys):
    # PB2's front reaches zero shaking moment with a driving torque of a few N·m; the original
    # (not force-balanced) lies at some 150 N·m and 215 N·m, far outside it.
    fig, doc = _front_figure_of(tmp_path, monkeypatch, capsys, EXAMPLES / "pb2.toml",
                                "driving-torque")
    ax = fig.axes[0]
    xs = [p["driving_torque"] for p in doc["points"]]
    ys = [max(p["shaking_moment"], p["lower_bound"]) for p in doc["points"]]
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert x0 <= min(xs) and max(xs) <= x1 and y0 <= min(ys) and max(ys) <= y1
    # The front fills the axes: they reach no more than a third beyond it each way.
    assert x1 - x0 <= 1.34 * (max(xs) - min(xs)) and y1 <= 1.34 * max(ys)
    original = doc["original"]
    assert original["driving_torque"] > x1 and original["shaking_moment"] > y1
    # The original is marked at the edge by an arrow that gives its coordinates.
    (arrow,) = (t for t in ax.texts if t.arrow_patch is not None and not t.get_text())
    (where,) = (t for t in ax.texts if "original design" in t.get_text())
    assert f"{original['shaking_moment']:.3g}" in where.get_text()
    labels = _legend_texts(fig)
    assert any(label.startswith("original design") and "not force-balanced" in label
               for label in labels)
    assert any("force-balanced" in label for label in labels if label.startswith("least"))


def test_an_original_within_reach_of_the_front_is_drawn_where_it_is(tmp_path, monkeypatch,
                                                                    capsys):
    fig, doc = _front_figure_of(tmp_path, monkeypatch, capsys, EXAMPLES / "pb1.toml",
                                "driving-torque")
    ax = fig.axes[0]
    (mark,) = (line for line in ax.get_lines() if line.get_label().startswith("original"))
    original = doc["original"]
    assert list(mark.get_xdata()) == [original["driving_torque"]]
    assert list(mark.get_ydata()) == [original["shaking_moment"]]
    assert "not force-balanced" in mark.get_label()
    assert not [t for t in ax.texts if t.arrow_patch is not None]


# --- animations: a title inside the picture, the crank angle, what the balancing added ----


def _drawn_animation(design, frames, **kw):
    fig, update = plots.animation_figure(design.mechanism, frames=frames, title=design.title,
                                         **kw)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return fig, update, canvas.get_renderer()


@pytest.mark.parametrize("name", ["pb1_balanced", "v8_to_balance"])
def test_the_animations_title_and_labels_lie_inside_the_picture(pb1_balanced, name):
    # PB1's title is long for a 6-inch animation; the V8's, as wide as the picture, once
    # pushed the axes left until the y label was cut off by the picture's edge.
    design = load_design(pb1_balanced if name == "pb1_balanced" else
                         EXAMPLES / f"{name}.toml")
    fig, _, renderer = _drawn_animation(design, 4)
    assert fig.get_suptitle().replace("\n", " ") == design.title
    page = fig.bbox
    ax = fig.axes[0]
    for box in (fig.get_tightbbox(renderer).transformed(fig.dpi_scale_trans),
                ax.yaxis.label.get_window_extent(renderer),
                ax.xaxis.label.get_window_extent(renderer)):
        assert page.x0 <= box.x0 and box.x1 <= page.x1 and page.y0 <= box.y0
        assert box.y1 <= page.y1
    assert ax.get_ylabel() == "y (m)" and ax.get_xlabel() == "x (m)"


def test_the_animation_reads_the_crank_angle_of_every_frame():
    design = load_design(EXAMPLES / "watt_sixbar.toml")
    fig, update, _ = _drawn_animation(design, 8)
    readouts = []
    for k in range(8):
        (text,) = (a for a in update(k) if hasattr(a, "get_text"))
        readouts.append(text.get_text())
    assert readouts[0].endswith("θ1 =   0.0°") and readouts[2].endswith("θ1 =  90.0°")
    assert len(set(readouts)) == 8


def test_the_animation_carries_each_centre_of_mass_and_counterweight_with_its_link(
        pb1_balanced):
    """PB1's balanced crank and rocker keep their masses and move their centres of mass off
    the links: each is drawn on an arm from a point of its link, at the same distance from it
    in every frame; a spec with counterweights draws their discs where they are carried."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle

    import balancer
    from balancer.balance.counterweights import counterweights

    design = load_design(pb1_balanced)
    frames = 6
    weights = counterweights(design.original, design.mechanism)
    fig, update, _ = _drawn_animation(design, frames, counterweights=weights)
    _, coms, _ = drawing.drawing_frames(design.mechanism, drawing.revolution(frames))
    reach = {}  # per link: the length of its centre of mass's arm
    for k in range(frames):
        arms = [a.get_xydata() for a in update(k) if isinstance(a, Line2D)
                and a.get_color() == plots.COLOURS["com"] and a.get_linestyle() == "-"]
        for name, path in coms.items():
            (arm,) = (xy for xy in arms if abs(complex(*xy[1]) - path[k]) < 1e-12)
            length = reach.setdefault(name, np.hypot(*(arm[1] - arm[0])))
            assert np.hypot(*(arm[1] - arm[0])) == pytest.approx(length, rel=1e-9)
    assert reach["crank"] > 0.3 and reach["rocker"] > 0.3  # off the links
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    assert any(label.startswith("rebuilt") and "crank" in label for label in labels)
    # Counterweights added to the paper's links: discs that move with them.
    cw = balancer.example("pb1_counterweights")
    result = balancer.optimize(cw, backend="convex")
    balanced = result.balanced_design(cw)
    fig, update, _ = _drawn_animation(balanced, frames, counterweights=result.counterweights)
    paths = drawing.counterweight_paths(balanced.mechanism, result.counterweights,
                                        drawing.revolution(frames))
    discs = [p for p in fig.axes[0].patches if isinstance(p, Circle)]
    assert len(discs) == len(paths) == 2
    for k in (0, 3):
        update(k)
        centres = sorted(d.get_center() for d in discs)
        expected = sorted((c[k].real, c[k].imag) for c, _ in paths.values())
        np.testing.assert_allclose(centres, expected, rtol=0, atol=1e-12)


# --- verify's figure: coinciding curves both visible, spikes clipped and said so ---------


@pytest.fixture(scope="module")
def watt_balanced(tmp_path_factory):
    out = tmp_path_factory.mktemp("watt") / "balanced.toml"
    assert main(["optimize", str(EXAMPLES / "watt_sixbar.toml"), "--out", str(out),
                 "--no-verify", "--backend", "convex", "--json"]) == 0
    return out


def test_a_curve_that_coincides_with_another_is_drawn_over_it_visibly(pb1_balanced):
    # A force-balanced four-bar's ground reactions are equal and opposite: |R_A0| = |R_A3|
    # after balancing, one curve exactly on the other. The later one is drawn on top, dashed
    # and thinner, and its legend entry says which one it hides.
    design = load_design(pb1_balanced)
    v = _verify(pb1_balanced, duration=0.3)
    fig = plots.verification_figure(design, v)
    forces = fig.axes[0]
    lines = {line.get_label(): line for line in _lines(forces)}
    (a3,) = (line for name, line in lines.items() if name.startswith("$|R_{A3}|$, after"))
    a0 = lines["$|R_{A0}|$, after"]
    np.testing.assert_allclose(a3.get_ydata(), a0.get_ydata(), rtol=1e-9, atol=1e-9)
    assert "coincides with $|R_{A0}|$, after" in a3.get_label()
    assert a3.get_linestyle() != "-" and a3.get_linewidth() < a0.get_linewidth()
    assert a3.get_zorder() > a0.get_zorder()
    legend = [t.get_text() for t in forces.get_legend().get_texts()]
    assert a3.get_label() in legend
    # Curves that differ keep their own style.
    assert lines["$|R_{A0}|$, before"].get_label() == "$|R_{A0}|$, before"


def test_free_motion_spikes_are_clipped_and_marked_not_squashing_the_rest(watt_balanced):
    # The Watt six-bar's free motion passes near a toggle: brief spikes of the forces on the
    # ground some 30 times the rest of the motion. The axes are set on the bulk of the samples
    # (most of every curve visible); the spikes are marked at the edge and their size given.
    design = load_design(watt_balanced)
    v = _verify(watt_balanced, duration=1.0)
    fig = plots.verification_figure(design, v)
    axes = np.array(fig.axes).reshape(3, 2)
    for ax, unit in ((axes[0, 1], "N"), (axes[1, 1], "N·m")):
        curves = _lines(ax)
        values = np.concatenate([line.get_ydata() for line in curves])
        low, high = ax.get_ylim()
        inside = (values >= low) & (values <= high)
        assert high < np.max(values)  # clipped
        assert np.mean(inside) > 0.95
        assert high - low < 0.25 * np.ptp(values)  # the bulk is no longer squashed
        marks = [line for line in ax.get_lines() if line.get_label().startswith("clipped")]
        (mark,) = marks
        peak = np.max(np.abs(values))
        assert f"{style.number(peak)} {unit}" in mark.get_label()
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        assert mark.get_label() in labels
    # The driven run has no spikes: its axes hold every sample.
    for ax in axes[:2, 0]:
        values = np.concatenate([line.get_ydata() for line in _lines(ax)])
        low, high = ax.get_ylim()
        assert low <= np.min(values) and np.max(values) <= high
        assert not [line for line in ax.get_lines() if line.get_label().startswith("clipped")]


# --- engines' figures: planes, mount torque, speeds in rpm (issue 40) -------------------------


#: Counterweights for the single cylinder in two planes off its own: the balanced design has
#: links out of the plane, its original none.
TWO_PLANES = """
[balance.objective]
rocking_couple = 1.0
shaking_force = 0.04
shaking_moment = 0.0
unbalance = 0.0

[balance.counterweights]
planes = [-0.024, 0.03]
max_mr = 0.03
"""


@pytest.fixture(scope="module")
def flat_single():
    """The single cylinder without its counterweights (all in the cylinder's plane), to
    balance in two planes off it; and the balanced design (``optimize``'s)."""
    import balancer

    text = (EXAMPLES / "single_cylinder.toml").read_text(encoding="utf-8")
    text = "\n".join(line for line in text.splitlines()
                     if 'label = "counterweight"' not in line) + TWO_PLANES
    design = balancer.loads_design(text)
    balanced = balancer.optimize(design).balanced_design(design)
    assert in_one_plane(mechanism_of(design.mechanism))
    assert not in_one_plane(mechanism_of(balanced.mechanism))
    return design, balanced


def _panel(fig, words):
    """The axes whose title starts with ``words``."""
    (ax,) = (ax for ax in fig.axes if ax.get_title().startswith(words))
    return ax


@pytest.mark.parametrize("order", ["balanced after an original in one plane",
                                   "in one plane after one in planes"])
def test_the_cycle_figure_of_designs_in_one_and_several_planes(flat_single, order):
    """The tutorial's call, ``cycle_figure(analyze(balanced), before=analyze(design))``, where
    one of the two has links out of the plane (it raised KeyError 'couple'): the rocking
    couple's panel draws both, the one in a plane as the zero it is."""
    import balancer

    design, balanced = flat_single
    after, before = balancer.analyze(balanced), balancer.analyze(design)
    if order.startswith("in one plane"):
        after, before = before, after
    fig = balancer.cycle_figure(after, before=before)
    couple = _panel(fig, "rocking couple")
    lines = _lines(couple)
    assert len(lines) == 2
    for line, a in zip(lines, (before, after), strict=True):
        drawn = complex(1, 0) * line.get_xdata() + 1j * line.get_ydata()
        values = _closed(a.reactions.rocking_couple)
        scale = cycle.natural_scales(a)["couple"]
        expected = values if np.max(np.abs(values)) > 1e-9 * scale else 0 * values
        np.testing.assert_array_equal(drawn, expected)
    # The figures of the drawing's own sampling (``plot --cycle``) at the same angles.
    drawn = cycle.drawn_analyses([balanced.mechanism, design.mechanism],
                                 balanced.operation.speed)
    assert drawn[0].samples == drawn[1].samples >= 720
    assert cycle.panel_keys(*drawn) == ("force", "couple", "moment", "torque", "mount")


def test_an_engines_cycle_figure_draws_the_torque_on_its_mounts():
    """The mount torque (``analyze``'s table and JSON) over the crank angle: the shaking moment
    plus the driving torque, sample by sample, its RMS and maximum in the panel's title; a
    mechanism that is not an engine has no such panel."""
    design = load_design(EXAMPLES / "single_cylinder.toml")
    a = analyze(design)
    fig = plots.cycle_figure(a)
    mount = _panel(fig, "mount torque")
    (line,) = _lines(mount)
    np.testing.assert_array_equal(line.get_ydata(), _closed(a.mount_torque))
    np.testing.assert_allclose(a.mount_torque, a.reactions.shaking_moment
                               + a.reactions.driving_torque, rtol=0, atol=1e-12 * np.max(
                                   np.abs(a.reactions.driving_torque)))
    assert mount.get_ylabel() == "torque about z on the mounts (N·m)"
    summary = a.summary.mount_torque
    assert (f"RMS {style.number(summary.rms)} N·m, max {style.number(summary.max)} N·m"
            in mount.get_title())
    assert not any(ax.get_title().startswith("mount")
                   for ax in plots.cycle_figure(analyze(load_design(
                       EXAMPLES / "pb1.toml"))).axes)
    with pytest.raises(ValueError, match="'shaking_moment', 'driving_torque'"):
        plots.plot_over_crank_angle(analyze(load_design(EXAMPLES / "pb1.toml")),
                                    "mount_torque")


@pytest.mark.slow
def test_figures_give_speeds_in_rpm_beside_rad_per_s(tmp_path):
    design = load_design(EXAMPLES / "single_cylinder.toml")  # 680.678 rad/s, 6500 rpm
    a = analyze(design)
    assert "680.678 rad/s (6500 rpm)" in plots.cycle_figure(a).get_suptitle()
    assert "680.678 rad/s (6500 rpm)" in plots.orders_figure(a).get_suptitle()
    assert speed_text(10.0) == "10 rad/s (95.49 rpm)"  # the one text of a speed
    # A sweep over the speed: a second axis in rpm, the original's speed in both.
    path = _atlas_table(tmp_path / "speed.parquet", ["optimal"] * 3,
                        keys=("operation.speed",), values=((500.0, 600.0, 700.0),))
    fig = atlas_figure(path, ["operation.speed"], original={"operation.speed": 680.678})
    ax = fig.axes[0]
    assert ax.get_xlabel() == "operation.speed (rad/s)"
    (rpm,) = ax.child_axes
    assert rpm.get_xlabel() == "operation.speed (rpm)"
    labels = [line.get_label() for line in ax.get_lines()]
    assert "original design: operation.speed = 680.7 rad/s (6500 rpm)" in labels


def _bars(ax, label):
    """The heights of the bars of one legend entry, by order."""
    (bars,) = (c for c in ax.containers if c.get_label() == label)
    return np.array([p.get_height() for p in bars.patches])


def test_order_zero_of_a_moment_or_torque_is_drawn_as_its_signed_mean():
    """A firing engine's driving torque has a negative mean (the load's torque on the crank):
    order 0's bar is that mean with its sign (it was drawn as its magnitude), as the JSON's
    order table gives it; every other bar a peak amplitude."""
    from balancer.api import to_dict

    design = load_design(EXAMPLES / "single_cylinder.toml")
    a = analyze(design)
    fig = plots.orders_figure(a)
    means = {"driving torque": a.reactions.driving_torque, "mount torque": a.mount_torque,
             "shaking moment": a.reactions.shaking_moment}
    for words, values in means.items():
        heights = _bars(_panel(fig, words), "design")
        mean = float(np.mean(values))
        floor = 1e-9 * cycle.natural_scales(a)["moment"]
        assert heights[0] == (mean if abs(mean) > floor else 0.0)
        assert np.all(heights[1:] >= 0)
    torque = _bars(_panel(fig, "driving torque"), "design")
    assert torque[0] == pytest.approx(-49.4, abs=0.05)  # docs/engines.md's −49.4 N·m
    orders = to_dict(a)["orders"]
    assert orders[0]["driving_torque"] == torque[0]
    assert orders[0]["mount_torque"] == _bars(_panel(fig, "mount torque"), "design")[0]
    # A force's order 0: the mean's magnitude, never negative.
    force = _panel(fig, "shaking force")
    assert _bars(force, "design, forward")[0] == pytest.approx(abs(np.mean(
        a.reactions.shaking_force)), rel=1e-12)


@pytest.mark.slow  # (the full suite's: the fast lane's minute)
def test_order_bars_on_a_log_axis(monkeypatch):
    """``log=True``: each panel with a bar above zero on a logarithmic axis in whole decades,
    every bar shown within them; a negative mean drawn by its magnitude and labelled with its
    sign; bars at rounding of the largest (≤ 1e-12 of it) left out even where the rounding
    floor of the load's natural scale would keep them, so that they cannot stretch the axis
    over decades of noise; a panel of zeros (a V8's shaking moment) stays linear."""
    from balancer.plots import orders as order_bars

    single = analyze(load_design(EXAMPLES / "single_cylinder.toml"))
    fig = plots.orders_figure(single, log=True)
    torque = _panel(fig, "driving torque")
    assert torque.get_yscale() == "log" and torque.get_ylabel().endswith(", log scale")
    heights = _bars(torque, "design")
    mean = single.orders[0].driving_torque
    assert mean < 0 and heights[0] == -mean
    assert [t.get_text() for t in torque.texts] == [style.number(mean).replace("-", "−")]
    low, high = torque.get_ylim()
    shown = heights[heights > 0]
    assert low <= shown.min() / 2 and shown.max() * 2 <= high
    assert np.log10(low) == round(np.log10(low)) and np.log10(high) == round(np.log10(high))

    v8 = analyze(load_design(EXAMPLES / "v8.toml"))
    monkeypatch.setattr(order_bars, "ROUNDING_SPAN", 0.0)  # only the log floor left
    fig = plots.orders_figure(v8, log=True)
    force = _panel(fig, "shaking force")
    forward = _bars(force, "design, forward")
    largest = max(o.shaking_force.forward for o in v8.orders)
    rounding = [o.shaking_force.forward <= 1e-12 * largest for o in v8.orders]
    assert any(rounding) and not np.any(forward[rounding])
    kept = [v for o in v8.orders for v in (o.shaking_force.forward, o.shaking_force.backward)
            if v > 1e-12 * largest]
    assert min(kept) == pytest.approx(0.174, rel=1e-2)  # the 8th order, the least real one
    assert force.get_yscale() == "log" and min(kept) / 20 <= force.get_ylim()[0]
    monkeypatch.undo()
    moment = _panel(plots.orders_figure(v8, log=True), "shaking moment")
    assert moment.get_yscale() == "linear" and not np.any(_bars(moment, "design"))


def test_plot_orders_log_flag(tmp_path, capsys, monkeypatch):
    drawn = []
    monkeypatch.setattr("balancer.cli.plot.save_figure", lambda fig, path: drawn.append(fig))
    spec = str(EXAMPLES / "single_cylinder.toml")
    assert main(["plot", spec, "--orders", str(tmp_path / "o.png"), "--log"]) == 0
    (fig,) = drawn
    assert _panel(fig, "driving torque").get_yscale() == "log"
    assert main(["plot", spec, "--orders", str(tmp_path / "o.png")]) == 0
    assert _panel(drawn[1], "driving torque").get_yscale() == "linear"
    capsys.readouterr()
    assert main(["plot", spec, "--cycle", str(tmp_path / "c.png"), "--log"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--log" in err and "--orders PATH" in err
    assert len(drawn) == 2 and list(tmp_path.iterdir()) == []


# --- the animation: a design, pistons, engines' counterweights (issue 40) ------------------


@pytest.mark.slow
def test_animate_takes_a_design_as_every_other_call_does(tmp_path):
    """``animate(design, path)``: its mechanism, its title and (a balanced spec) the bodies
    added to its original's links, as ``plot --animate`` draws them; a model or a mechanism
    as before; anything else refused by a message that names what is accepted."""
    from matplotlib.patches import Circle

    import balancer

    engine = balancer.example("single_cylinder")
    assert isinstance(engine.mechanism, balancer.Engine)  # the name the refusals give
    out = balancer.animate(engine, tmp_path / "engine.gif", frames=4)
    assert out.read_bytes()[:6] == b"GIF89a"
    assert balancer.animate(engine.mechanism, tmp_path / "model.gif", frames=4).exists()
    fig, _ = plots.animation_figure(engine, frames=4)
    assert fig.get_suptitle() == engine.title
    design = balancer.example("pb1_counterweights")
    result = balancer.optimize(design, backend="convex")
    balanced = result.balanced_design(design)
    fig, _ = plots.animation_figure(balanced, frames=4)  # no counterweights given: its own
    discs = [p for p in fig.axes[0].patches if isinstance(p, Circle)]
    assert len(discs) == len([w for w in result.counterweights.values() if w.kind == "add"])
    assert len(discs) == 2
    for wrong in ("examples/v8.toml", None, result):
        with pytest.raises(balancer.SpecError) as caught:
            balancer.animate(wrong, tmp_path / "x.gif", frames=4)
        message = str(caught.value)
        assert message.count("\n") == 0 and type(wrong).__name__ in message
        for accepted in ("Design", "FourBar", "SliderCrank", "Linkage", "Engine", "Mechanism"):
            assert accepted in message
    assert not (tmp_path / "x.gif").exists()
    # Where a mechanism's model is asked for and a Design given, the message says so.
    with pytest.raises(balancer.SpecError, match=r"Engine: a Design's is its \.mechanism"):
        mechanism_of(engine)
    with pytest.raises(balancer.SpecError, match="or an Engine"):
        balancer.Design(mechanism=engine)


def _block_frame(polygon):
    """A rectangle's centre, its side along its first edge and across it (m), and the first
    edge's direction (complex unit)."""
    xy = polygon.get_xy()[:4]
    z = xy[:, 0] + 1j * xy[:, 1]
    along, across = z[1] - z[0], z[3] - z[0]
    return z.mean(), abs(along), abs(across), along / abs(along)


@pytest.mark.parametrize(("name", "size"), [
    ("single_cylinder", (0.7 * 0.092, 0.092)),        # the bore
    ("v8", (0.7 * 0.0995, 0.0995)),
    ("engine", (0.7 * 2 * 0.0196, 2 * 0.0196)),       # a slider-crank: the stroke
    ("quick_return", (0.6 * 0.1, 0.35 * 0.1)),        # blocks: of the crank's reach
])
def test_pistons_and_blocks_are_rectangles_along_their_sliders(name, size):
    """Each sliding block (an engine's piston) is a rectangle centred on its point, its length
    along its slider's line and its width across, carried with it frame by frame; an
    engine's piston as wide as its bore (the stroke where there is none)."""
    from matplotlib.patches import Polygon

    design = load_design(EXAMPLES / f"{name}.toml")
    mech = mechanism_of(design.mechanism)
    frames = 6
    fig, update = plots.animation_figure(design, frames=frames)
    blocks = [p for p in fig.axes[0].patches if isinstance(p, Polygon)]
    sliders = [s for s in mech.linkage.sliders
               if len(dict((b.name, b.points) for b in mech.linkage.bodies)[s.link]) == 1]
    assert len(blocks) == len(sliders) > 0
    length, width = size
    mo = mech.motion(cycle.sample_angles(frames), 1.0)
    points = geometry.points(mech, mo)
    guides = dict(zip((s.link for s in mech.linkage.sliders), geometry.guides(mech, mo),
                      strict=True))
    for k in (0, 2, 5):
        update(k)
        for block, slider in zip(blocks, sliders, strict=True):
            centre, along, across, direction = _block_frame(block)
            assert abs(centre - points[slider.point][k]) <= 1e-12
            assert along == pytest.approx(length, rel=1e-12)
            assert across == pytest.approx(width, rel=1e-12)
            line = guides[slider.link][1][k]  # the slider's line's direction at this frame
            assert abs((direction * np.conj(line)).imag) <= 1e-12
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    assert ("sliding blocks" if name == "quick_return" else "pistons") in labels


@pytest.mark.parametrize("name", ["single_cylinder", "inline_four"])
def test_an_engines_counterweights_and_eccentrics_turn_with_their_shafts(name):
    """The crankshaft's masses labelled ``counterweight`` and each balance shaft's eccentrics
    are sectors on their axes pointing at ``ratio·θ1 + phase`` in every frame; sectors of one
    thickness, radius as the cube root of mass·radius, the largest the crank radius."""
    from matplotlib.patches import Wedge

    design = load_design(EXAMPLES / f"{name}.toml")
    engine = design.mechanism
    expected = [(0j, 1, m.phase_deg, m.mr) for m in engine.crankshaft.masses
                if m.label == "counterweight"]
    expected += [(complex(*s.at), s.ratio, m.phase_deg, m.mr) for s in engine.balance_shafts
                 for m in s.eccentrics]
    frames = 8
    fig, update = plots.animation_figure(design, frames=frames)
    wedges = [p for p in fig.axes[0].patches if isinstance(p, Wedge)]
    assert len(wedges) == len(expected) > 0
    largest = max(mr for *_, mr in expected)
    crank = engine.cylinders[0].crank
    for k in (0, 3):
        update(k)
        theta1 = 360.0 * k / frames
        for wedge, (axis, ratio, phase, mr) in zip(wedges, expected, strict=True):
            assert complex(*wedge.center) == axis
            assert wedge.r == pytest.approx(crank * np.cbrt(mr / largest), rel=1e-12)
            middle = 0.5 * (wedge.theta1 + wedge.theta2)
            assert (middle - (ratio * theta1 + phase) + 180) % 360 - 180 == pytest.approx(
                0.0, abs=1e-9)
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    assert "crankshaft counterweights" in labels
    assert ("balance shafts' eccentrics" in labels) == bool(engine.balance_shafts)


def test_an_optimised_engines_animation_draws_the_counterweights_it_chose(flat_single,
                                                                          tmp_path):
    """``optimize`` writes an engine's counterweights into its crankshaft's masses: the
    animation of the balanced spec draws them where the optimiser put them."""
    from matplotlib.patches import Wedge

    import balancer

    design, balanced = flat_single
    chosen = [m for m in balanced.mechanism.crankshaft.masses if m.label == "counterweight"]
    assert chosen and all(m.z in (-0.024, 0.03) for m in chosen)
    spec = tmp_path / "balanced.toml"
    balancer.save_design(balanced, spec)
    fig, update = plots.animation_figure(load_design(spec), frames=4)
    update(0)
    wedges = [p for p in fig.axes[0].patches if isinstance(p, Wedge)]
    assert sorted(0.5 * (w.theta1 + w.theta2) % 360 for w in wedges) == pytest.approx(
        sorted(m.phase_deg % 360 for m in chosen), abs=1e-9)
    # With its original named beside it ([original]), the same: an engine's balancing adds
    # masses on its shafts, not bodies to its links (no link-by-link counterweights asked).
    from balancer.plots import animation

    def asked(*_):
        raise AssertionError("an engine's links are not rebuilt by its balancing")

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(animation, "link_counterweights", asked)
        fig, _ = plots.animation_figure(replace(balanced, original=design.mechanism), frames=4)
    assert len([p for p in fig.axes[0].patches if isinstance(p, Wedge)]) == len(chosen)


def test_a_figure_that_is_rounding_reads_zero_in_its_panels_title(tmp_path, capsys):
    """PB2's complete balance leaves a shaking force and moment of rounding (1e-13 and the
    like): the cycle figure draws them as zero and its titles say 0, as the text report does,
    while the original's figures beside them keep their digits."""
    out = tmp_path / "balanced.toml"
    assert main(["optimize", str(EXAMPLES / "pb2.toml"), "--out", str(out), "--no-verify",
                 "--backend", "convex", "--json"]) == 0
    capsys.readouterr()
    after, before = api.cycle_analyses(load_design(out))
    force = float(np.sqrt(np.mean(np.abs(after.reactions.shaking_force) ** 2)))
    scale = cycle.natural_scales(after)["force"]
    assert 0 < force <= cycle.ROUNDING_SPAN * scale  # (rounding, not an exact zero)
    fig = plots.cycle_figure(after, before)
    titles = {ax.get_title().split("\n")[0]: ax.get_title() for ax in fig.axes}
    force_title = next(t for k, t in titles.items() if k.startswith("shaking force"))
    moment_title = next(t for k, t in titles.items() if k.startswith("shaking moment"))
    for title in (force_title, moment_title):
        assert "→ 0 N" in title and title.count("→ 0 ") == 2, title  # RMS and max
        assert "e-1" not in title, title
