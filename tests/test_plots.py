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

from balancer import plots
from balancer.api import analyze
from balancer.cli import main
from balancer.spec import load_design

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
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


def _check_cycle_figure(fig, after, before):
    force, moment, torque = fig.axes
    curves = [a for a in (before, after) if a is not None]
    # The polar diagram: the shaking force's tip, x against y, closed over the revolution.
    lines = _lines(force)
    assert len(lines) == len(curves)
    for line, a in zip(lines, curves, strict=True):
        f = _closed(a.reactions.shaking_force)
        np.testing.assert_array_equal(line.get_xdata(), f.real)
        np.testing.assert_array_equal(line.get_ydata(), f.imag)
    for ax, key in ((moment, "shaking_moment"), (torque, "driving_torque")):
        lines = _lines(ax)
        assert len(lines) == len(curves)
        for line, a in zip(lines, curves, strict=True):
            np.testing.assert_allclose(line.get_xdata(), np.degrees(_closed(a.theta1)) +
                                       np.r_[np.zeros(a.samples), 360.0])
            np.testing.assert_array_equal(line.get_ydata(), _closed(getattr(a.reactions, key)))
        assert ax.get_xlabel() == "crank angle θ1 (°)" and ax.get_ylabel().endswith("(N·m)")
    assert force.get_xlabel().endswith("(N)") and force.get_ylabel().endswith("(N)")


@pytest.mark.parametrize("name", SPECS)
def test_the_cycle_figure_draws_the_cycle_analysis_of_every_mechanism(name):
    design = load_design(EXAMPLES / f"{name}.toml")
    after, before = plots.cycle_analyses(design)
    assert before is None
    # At least the spec's samples, and the arrays are those of the design's own analysis at
    # that many angles (the same route, speed, gravity and loads as `analyze`).
    assert after.samples >= max(design.operation.samples, plots.PLOT_SAMPLES[0])
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
    after, _ = plots.cycle_analyses(design)
    n = after.samples
    mid = analyze(replace(design, operation=replace(design.operation, samples=2 * n)))
    for key in ("shaking_force", "shaking_moment", "driving_torque"):
        drawn, between = getattr(after.reactions, key), getattr(mid.reactions, key)[1::2]
        chord = 0.5 * (drawn + np.roll(drawn, -1))
        span = max(np.ptp(drawn.real), np.ptp(drawn.imag))
        assert np.max(np.abs(between - chord)) <= plots.DRAWING_TOLERANCE * span


def test_a_curve_with_a_sharp_feature_is_sampled_more_finely_than_a_smooth_one():
    # The engine's gas force rises steeply after top dead centre; the paper's four-bar is smooth.
    engine = plots.cycle_analyses(load_design(EXAMPLES / "engine.toml"))[0]
    smooth = plots.cycle_analyses(load_design(EXAMPLES / "meijaard2020.toml"))[0]
    coarse = plots.cycle_analyses(load_design(EXAMPLES / "engine.toml"), samples=16)[0]
    assert coarse.samples == 16
    assert engine.samples >= smooth.samples
    fine_spec = load_design(EXAMPLES / "meijaard2020.toml")
    fine_spec = replace(fine_spec, operation=replace(fine_spec.operation, samples=5000))
    assert plots.cycle_analyses(fine_spec)[0].samples >= 5000


def test_before_and_after_are_the_original_and_the_balanced_design(pb1_balanced):
    balanced = load_design(pb1_balanced)
    original = load_design(EXAMPLES / "pb1.toml")
    after, before = plots.cycle_analyses(balanced)
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
    assert "--cycle PATH or --animate PATH" in capsys.readouterr().err
    assert main(["plot", spec, "--cycle", str(tmp_path / "a.png"), "--animate",
                 str(tmp_path / "a.png")]) == 2
    assert "same file" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_plot_cycle_of_a_crank_that_cannot_turn_is_bad_input(tmp_path, capsys):
    text = (EXAMPLES / "meijaard2020.toml").read_text().replace("crank = 1.0", "crank = 2.9")
    spec = tmp_path / "rocking.toml"
    spec.write_text(text)
    out = tmp_path / "c.png"
    assert main(["plot", str(spec), "--cycle", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "a cycle plot needs a crank that turns a full revolution" in err
    assert not out.exists()


def test_cycle_and_animation_in_one_call(tmp_path, capsys):
    cycle, gif = tmp_path / "c.pdf", tmp_path / "a.gif"
    assert main(["plot", str(EXAMPLES / "engine.toml"), "--cycle", str(cycle), "--animate",
                 str(gif), "--frames", "4"]) == 0
    assert cycle.read_bytes()[:4] == b"%PDF" and gif.read_bytes()[:3] == b"GIF"
    capsys.readouterr()


needs_ffmpeg = pytest.mark.skipif(plots.ffmpeg() is None,
                                  reason="no ffmpeg (pip install imageio-ffmpeg)")


@needs_ffmpeg
def test_an_mp4_animation_has_one_frame_per_crank_angle(tmp_path, capsys):
    import subprocess

    out = tmp_path / "run.mp4"
    assert main(["plot", str(EXAMPLES / "watt_sixbar.toml"), "--animate", str(out),
                 "--frames", "10"]) == 0
    assert out.read_bytes()[4:8] == b"ftyp"  # an ISO media file
    # ffmpeg decodes it back: 10 frames.
    probe = subprocess.run([plots.ffmpeg(), "-i", str(out), "-map", "0:v:0", "-f", "null", "-"],
                           capture_output=True, text=True, check=True)
    assert "frame=   10" in probe.stderr.replace("frame=10", "frame=   10")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.mp4"]
    capsys.readouterr()


def test_an_mp4_without_ffmpeg_is_refused_before_any_work(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(plots, "ffmpeg", lambda: None)
    out = tmp_path / "run.mp4"
    assert main(["plot", str(EXAMPLES / "pb1.toml"), "--animate", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--animate" in err and "needs ffmpeg" in err
    assert ".gif" in err and list(tmp_path.iterdir()) == []


def test_a_failing_ffmpeg_leaves_nothing_behind(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(plots, "ffmpeg", lambda: "/bin/false")
    out = tmp_path / "run.mp4"
    assert main(["plot", str(EXAMPLES / "pb1.toml"), "--animate", str(out), "--frames",
                 "3"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "ffmpeg could not write the MP4" in err
    assert list(tmp_path.iterdir()) == []


def test_every_animation_extension_is_checked(tmp_path):
    assert set(plots.ANIMATION_TYPES) == {".gif", ".mp4"}
    assert set(plots.FIGURE_TYPES) == {".png", ".svg", ".pdf"}
    for name in ("a.GIF", "a.Mp4"):
        assert plots.figure_type(tmp_path / name, types=plots.ANIMATION_TYPES) in {"gif", "mp4"}


# --- verify's figure: before and after on every panel, legends outside, no aliasing -------


def _verify(path, **kw):
    from balancer.verification import verify

    return verify(load_design(path), **kw)


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
    from balancer.plots import counterweight_paths

    design = balancer.example("pb1_counterweights")
    result = balancer.optimize(design, backend="convex")
    balanced = result.balanced_design(design)
    frames = 16
    paths = counterweight_paths(balanced.mechanism, result.counterweights, frames)
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
