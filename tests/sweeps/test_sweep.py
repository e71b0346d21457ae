"""Design-space sweeps (balancer/sweeps/, ``balancer sweep``), on Dask and in process."""

from __future__ import annotations

import json
import logging
import math
import os
import re
import tomllib
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from balancer.balance.optimizer import optimize
from balancer.cli import main
from balancer.errors import OutputError, SpecError
from balancer.spec import design_from_dict, load_design
from balancer.sweeps import Vary, design_points, sweep, with_values
from balancer.sweeps.cluster import _silenced

ROOT = Path(__file__).resolve().parents[2]
PB1 = ROOT / "examples" / "pb1.toml"
COUPLER = "mechanism.lengths.coupler"
FRAME = "mechanism.lengths.frame"


def _rows(path) -> list[dict]:
    return pq.read_table(path).to_pylist()


def test_varied_keys_are_parsed_and_placed():
    v = Vary.parse(f"{COUPLER}=2.5:3.5:3")
    assert (v.key, v.low, v.high, v.count) == (COUPLER, 2.5, 3.5, 3)
    grid = design_points([v, Vary.parse(f"{FRAME}=3.0:3.2:2")])
    assert grid == [{COUPLER: c, FRAME: f} for c in (2.5, 3.0, 3.5) for f in (3.0, 3.2)]
    for method in ("lhs", "sobol"):
        pts = design_points([Vary.parse(f"{COUPLER}=2.5:3.5"), Vary.parse(f"{FRAME}=3:4")],
                            method, samples=16, seed=3)
        assert len(pts) == 16
        assert all(2.5 <= p[COUPLER] <= 3.5 and 3.0 <= p[FRAME] <= 4.0 for p in pts)
        again = design_points([Vary.parse(f"{COUPLER}=2.5:3.5"), Vary.parse(f"{FRAME}=3:4")],
                              method, samples=16, seed=3)
        assert pts == again  # seeded
    # A Latin hypercube puts one point in each of the 16 strata of every key.
    strata = sorted(int((p[COUPLER] - 2.5) / 1.0 * 16) for p in
                    design_points([Vary.parse(f"{COUPLER}=2.5:3.5")], "lhs", 16, 3))
    assert strata == list(range(16))


@pytest.mark.parametrize("text", ["coupler", "k=1", "k=a:2:3", "k=2:1:3", "k=1:2:0",
                                  "k=nan:1:2"])
def test_bad_varied_keys_are_refused(text):
    with pytest.raises(SpecError) as info:
        Vary.parse(text)
    assert info.value.key == "--vary"


def test_a_key_must_name_a_number_of_the_spec():
    data = tomllib.loads(PB1.read_text())
    assert with_values(data, {COUPLER: 2.75})["mechanism"]["lengths"]["coupler"] == 2.75
    assert data["mechanism"]["lengths"]["coupler"] == 3.0  # a copy
    for key in ("mechanism.lengths.coupling", "mechanism.type", "links.crank.com.s.x"):
        with pytest.raises(SpecError) as info:
            with_values(data, {key: 1.0})
        assert info.value.key == key


def test_rows_equal_single_optimize_runs_and_name_bad_geometry(tmp_path):
    out = tmp_path / "sweep.parquet"
    result = sweep(PB1, [Vary.parse(f"{COUPLER}=2.0:4.0:3"), Vary.parse(f"{FRAME}=2.5:3.5:2")],
                   out, workers=0, batch=2)
    rows = _rows(out)
    assert [r["point"] for r in rows] == list(range(6)) and result.points == 6
    data = tomllib.loads(PB1.read_text())
    for row in rows:
        values = {COUPLER: row[COUPLER], FRAME: row[FRAME]}
        design = design_from_dict(with_values(data, values))
        if row["status"] == "bad-geometry":
            # The crank cannot turn fully (a Grashof crank-rocker no longer).
            assert "revolution" in row["message"] or "assemble" in row["message"]
            assert row["shaking_moment_after"] is None
            continue
        single = optimize(design, "convex")
        assert row["status"] == str(single.status)
        assert row["shaking_moment_after"] == single.after.summary.shaking_moment.rms
        assert row["shaking_moment_before"] == single.before.summary.shaking_moment.rms
        assert row["shaking_force_after"] == single.after.summary.shaking_force.rms
        assert row["lower_bound"] == single.rms_lower_bound
    assert result.statuses == {"optimal": 4, "bad-geometry": 2}


def test_an_interrupted_sweep_resumes_and_equals_an_uninterrupted_one(tmp_path):
    varies = [Vary.parse(f"{COUPLER}=2.6:3.4:5")]
    whole = tmp_path / "whole.parquet"
    sweep(PB1, varies, whole, workers=0, batch=1)
    out = tmp_path / "sweep.parquet"

    def stop(done, client):
        if done == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sweep(PB1, varies, out, workers=0, batch=1, on_batch=stop)
    assert not out.exists()
    parts = tmp_path / "sweep.parquet.parts"
    assert len(list(parts.glob("batch-*.parquet"))) == 2
    with pytest.raises(OutputError):  # computed work is not thrown away silently
        sweep(PB1, varies, out, workers=0, batch=1)
    with pytest.raises(OutputError):  # nor resumed with other points
        sweep(PB1, [Vary.parse(f"{COUPLER}=2.6:3.4:6")], out, workers=0, batch=1, resume=True)
    # (Resumed without --batch: the interrupted sweep's batches, not ones sized anew.)
    result = sweep(PB1, varies, out, workers=0, resume=True)
    assert result.resumed == 2 and not parts.exists()
    assert _rows(out) == _rows(whole)


def test_batches_are_sized_to_the_workers():
    """25 points a task, fewer where a worker would get fewer than 8 tasks; in process 25."""
    from balancer.sweeps import batch_size

    assert batch_size(10_000, 2) == 25 and batch_size(10_000, 64) == 20
    assert batch_size(100, 2) == 7 and batch_size(5, 2) == 1 and batch_size(0, 2) == 1
    assert batch_size(100, 0) == 25


def test_a_resumed_sweep_rates_only_the_points_it_computed(tmp_path):
    """Two of five points computed before the interruption: the resumed run computed three,
    and its rate is theirs over its own time; the summary says how many came from before."""
    from balancer.report import sweep_text

    varies = [Vary.parse(f"{COUPLER}=2.6:3.4:5")]
    out = tmp_path / "sweep.parquet"

    def stop(done, client):
        if done == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sweep(PB1, varies, out, workers=0, batch=1, on_batch=stop)
    result = sweep(PB1, varies, out, workers=0, batch=1, resume=True)
    assert (result.points, result.resumed, result.computed) == (5, 2, 3)
    assert result.as_dict()["points_per_second"] == 3 / result.seconds
    line = sweep_text(result).splitlines()[1]
    assert line.startswith("5 points: 2 from the interrupted run before (2 batches), 3 "
                           "computed in "), line
    rate = float(re.search(r"\(([0-9.e+-]+) points/s", line)[1])
    assert rate == pytest.approx(3 / result.seconds, rel=5e-3)


def test_resume_with_nothing_to_resume_runs_the_sweep_from_the_start(tmp_path, capsys,
                                                                      monkeypatch):
    """A sweep interrupted before any point finished keeps nothing; a scheduler that restarts
    the job runs the same command line, --resume included: it runs the sweep whole, with a
    note, and its table is the uninterrupted sweep's."""
    import balancer.sweeps.run

    varies = [Vary.parse(f"{COUPLER}=2.6:3.4:3")]
    out, reference = tmp_path / "sweep.parquet", tmp_path / "reference.parquet"

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    with monkeypatch.context() as patch:
        patch.setattr(balancer.sweeps.run, "run_batch", interrupted)
        with pytest.raises(KeyboardInterrupt, match="nothing kept"):
            sweep(PB1, varies, out, workers=0, batch=3)
    args = ["sweep", str(PB1), "--vary", f"{COUPLER}=2.6:3.4:3", "--out", str(out),
            "--workers", "0", "--resume"]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert "note: no interrupted sweep to resume" in err and "ran it from the start" in err
    sweep(PB1, varies, reference, workers=0)
    assert _rows(out) == _rows(reference)


@pytest.mark.slow
def test_on_a_dask_cluster_a_killed_worker_loses_no_point(tmp_path):
    """Two local worker processes; after the first batch one of them is killed (os._exit).
    The scheduler reruns what it held, its nanny starts it again, and the table has every
    point exactly once, equal to the same sweep run in process. The workers' environment
    keeps Dask's one BLAS thread each, without its memory trimming (which makes a point cost
    1.3–1.5 times as much)."""
    varies = [Vary.parse(f"{COUPLER}=2.4:3.6:4"), Vary.parse(f"{FRAME}=2.8:3.4:4")]
    killed, environments = [], []

    def environment():
        return {k: os.environ.get(k) for k in ("MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS")}

    def kill(done, client):
        if done == 1 and not killed:
            environments.extend(client.run(environment).values())
            victim = sorted(client.scheduler_info()["workers"])[0]
            killed.append(victim)
            try:
                client.run(os._exit, 1, workers=[victim], wait=False)
            except Exception:  # noqa: BLE001 - the connection dies with the worker
                pass

    out = tmp_path / "dask.parquet"
    result = sweep(PB1, varies, out, workers=2, batch=1, on_batch=kill)
    assert killed and result.workers == 2
    assert environments == [{"MALLOC_TRIM_THRESHOLD_": None, "OMP_NUM_THREADS": "1"}] * 2
    rows = _rows(out)
    assert [r["point"] for r in rows] == list(range(16))
    reference = tmp_path / "local.parquet"
    sweep(PB1, varies, reference, workers=0, batch=4)
    assert rows == _rows(reference)


def test_sweep_command(tmp_path, capsys):
    out, png = tmp_path / "atlas.parquet", tmp_path / "atlas.png"
    code = main(["sweep", str(PB1), "--vary", f"{COUPLER}=2.6:3.4:3", "--vary",
                 f"{FRAME}=3.0:3.4:2", "--out", str(out), "--workers", "0", "--plot",
                 str(png), "--json"])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["points"] == 6 and doc["statuses"] == {"optimal": 6}
    rows = _rows(out)
    assert set(rows[0]) >= {COUPLER, FRAME, "status", "shaking_moment_before",
                            "shaking_moment_after", "shaking_force_before",
                            "shaking_force_after"}
    assert all(math.isfinite(r["shaking_moment_after"]) for r in rows)
    assert png.read_bytes()[:4] == b"\x89PNG"
    # Bad input: one line, exit 2, nothing written.
    for args in (["--vary", "nonsense"], ["--vary", f"{COUPLER}=1:2:3", "--out", "x.csv"],
                 ["--vary", "mechanism.lengths.nope=1:2:2"],
                 ["--perturb", "links.crank.mass=-1", "--samples", "5"],
                 ["--perturb", "links.crank.mass=0.1"],
                 ["--perturb", "links.crank.mass=0.1", "--samples", "5", "--vary",
                  f"{COUPLER}=2.6:3.4:3"],
                 ["--vary", f"{COUPLER}=2:4:100000", "--vary", f"{FRAME}=2:4:100000"],
                 ["--vary", f"{COUPLER}=2:4", "--method", "sobol", "--samples", "10000000"]):
        argv = ["sweep", str(PB1), *args]
        if "--out" not in args:
            argv += ["--out", str(tmp_path / "bad.parquet")]
        assert main([*argv, "--workers", "0"]) == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1
    # A spec without [balance] has nothing to balance at any point.
    no_balance = ROOT / "examples" / "meijaard2020.toml"
    assert main(["sweep", str(no_balance), "--vary", f"{COUPLER}=2.8:3.2:2", "--out",
                 str(tmp_path / "bad.parquet"), "--workers", "0"]) == 2
    assert "[balance]" in capsys.readouterr().err
    assert not (tmp_path / "bad.parquet").exists()
    assert not (tmp_path / "bad.parquet.parts").exists()


def test_perturbed_designs_have_the_residual_force_that_linearity_predicts(tmp_path):
    """Around a force-balanced design (PB1's optimum) the shaking force is linear in the
    crank's mass at its fixed centre of mass: F(θ) = δm·f(θ), f the force per kilogram. So every
    perturbed design's RMS shaking force is |δm|·RMS(f), with RMS(f) found here by one cycle
    analysis of the balanced design with 1 kg more (exact, by linearity; the balanced design's
    own residual is rounding, 1e-12 of its terms)."""
    import numpy as np

    from balancer.cycle import cycle_analysis
    from balancer.spec import dumps_design, loads_design
    from balancer.sweeps import Perturb

    design = load_design(PB1)
    balanced = optimize(design, "convex").balanced_design(design)
    spec = tmp_path / "balanced.toml"
    spec.write_text(dumps_design(balanced))
    data = tomllib.loads(spec.read_text())
    heavier = loads_design(dumps_design(balanced).replace(
        f"mass = {balanced.mechanism.crank.mass!r}",
        f"mass = {balanced.mechanism.crank.mass + 1.0!r}", 1))
    assert heavier.mechanism.crank.mass == balanced.mechanism.crank.mass + 1.0
    per_kg = cycle_analysis(heavier.mechanism, 10.0, 360, loads=False).summary.shaking_force.rms
    out = tmp_path / "perturbed.parquet"
    result = sweep(spec, [], out, perturbs=[Perturb.parse("links.crank.mass=0.01")],
                   samples=40, seed=7, workers=0)
    rows = _rows(out)
    assert result.statuses == {"analysed": 40}
    base = data["links"]["crank"]["mass"]
    for row in rows:
        delta = row["links.crank.mass"] - base
        assert row["shaking_force_before"] == pytest.approx(abs(delta) * per_kg, rel=1e-9)
    # The draws are normal with the deviation asked for (40 draws: within 3 standard errors).
    deltas = np.array([r["links.crank.mass"] - base for r in rows])
    assert abs(deltas.std(ddof=1) / 0.01 - 1) < 3 / np.sqrt(2 * 39)
    assert set(result.residual_force) >= {"mean", "p95", "max"}


def test_an_infeasible_point_keeps_its_own_figures():
    """A counterweight too light to balance: status infeasible, the message says which bound,
    and the row still holds the design's own figures (its inertial cycle analysis)."""
    from balancer.cycle import cycle_analysis
    from balancer.sweeps import evaluate_point

    data = tomllib.loads((ROOT / "examples" / "pb1_counterweights.toml").read_text())
    data["balance"]["crank"]["counterweight"]["mass"] = [0.01, 0.02]
    row = evaluate_point(data, {COUPLER: 3.0}, 0)
    assert row["status"] == "infeasible" and "counterweight" in row["message"]
    design = design_from_dict(with_values(data, {COUPLER: 3.0}))
    own = cycle_analysis(design.mechanism, 10.0, 360, loads=False).summary
    assert row["shaking_moment_before"] == own.shaking_moment.rms
    assert row["shaking_force_before"] == own.shaking_force.rms
    assert row["shaking_moment_after"] is None


@pytest.mark.parametrize(("option", "text", "close"), [
    ("--vary", "links.crank.mas=1:2:3", "links.crank.mass"),
    ("--perturb", "links.crank.mas=0.1", "links.crank.mass"),
    ("--vary", "mechanism.lengths.coupling=2:3:2", COUPLER),
])
def test_an_unknown_key_suggests_the_closest_naming_the_option(tmp_path, capsys, option, text,
                                                               close):
    """`--vary links.crank.mas` said 'no such number in the spec' under the key itself: now
    the option, the key given and the spec's closest keys."""
    argv = ["sweep", str(PB1), option, text, "--out", str(tmp_path / "x.parquet"),
            "--workers", "0", *(["--samples", "3"] if option == "--perturb" else [])]
    assert main(argv) == 2
    err = capsys.readouterr().err
    key = text.partition("=")[0]
    assert err.count("\n") == 1 and err.startswith(f"balancer: error: {option}: ")
    assert f"'{close}'" in err and f"(got '{key}')" in err
    assert list(tmp_path.iterdir()) == []


def test_a_sweep_task_runs_its_cycles_on_its_own_thread(monkeypatch):
    """A long cycle's chunks go to a pool of threads — but not within a sweep's task, whose
    worker shares the machine's cores with the others (cycles cut into chunks of 100 here)."""
    import concurrent.futures

    import balancer.cycle as cycle_module
    from balancer.sweeps import run_batch

    pools = []

    class Counting(concurrent.futures.ThreadPoolExecutor):
        def __init__(self, *args, **kwargs):
            pools.append(self)
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(concurrent.futures, "ThreadPoolExecutor", Counting)
    monkeypatch.setattr(cycle_module, "CHUNK", 100)
    monkeypatch.setattr(cycle_module, "WORKERS", 2)
    data = tomllib.loads((ROOT / "examples" / "pb1.toml").read_text())
    design = design_from_dict(data)
    cycle_module.cycle_analysis(design.mechanism, design.operation.speed, 360)
    assert len(pools) == 1  # (outside a task: a pool)
    rows = run_batch(data, [(0, {})], analyse_only=True)
    assert rows[0]["status"] == "analysed" and len(pools) == 1
    cycle_module.cycle_analysis(design.mechanism, design.operation.speed, 360)
    assert len(pools) == 2  # (and again after it)


def test_an_interrupted_sweep_silences_the_loggers_dask_configures_under_a_name(caplog):
    """Dask's config gives ``tornado.application`` its own level (ERROR), which ``tornado``'s
    does not override: its race on Ctrl-C (a cancel callback's NameError, logged by tornado)
    reached a designer's terminal. Every logger under a silenced name is silenced, and each
    gets its level back after."""
    child = logging.getLogger("balancer-test-parent.application")
    child.setLevel(logging.ERROR)
    with _silenced("balancer-test-parent"):
        child.error("a callback failed")
    assert not [r for r in caplog.records if r.name == child.name]
    assert child.level == logging.ERROR
    child.error("after the block")
    assert [r.getMessage() for r in caplog.records if r.name == child.name] == ["after the block"]
