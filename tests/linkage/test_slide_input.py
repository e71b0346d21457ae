"""A link driven along a ground slide as one input of a linkage with several (DESIGN.md).

The core's figures for it (rates by finite differences, the actuator's power against the
kinetic energy's rate, the momentum theorems, the groups against the global solve) are the
several-input tests' "crank and slide" case (``test_several_inputs.py``), and its simulation
in two formulations ``tests/simulation/test_motions.py``'s; here the verbs end to end: its
load named and measured as a force (N), its balance for every motion proved by simulation,
and a slide as the only input refused.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json

import numpy as np
import pytest
from linkage.several_inputs_specs import crank_slider

from balancer.cli import main
from balancer.errors import SpecError
from balancer.spec.reader import design_from_dict
from balancer.spec.writer import dumps_design


def _spec() -> dict:
    spec = crank_slider()
    spec["workspace"] = {"crank": [-0.3, 0.3], "block": [-0.05, 0.05], "samples": 11}
    spec["motion"] = [{"name": "press", "times": [0.0, 0.5, 1.0],
                       "path": [[0.0, 0.0], [0.25, 0.04], [0.0, 0.0]], "law": "quintic",
                       "samples": 101}]
    spec["balance"] = {"force_balance": True, "objective": {"shaking_moment": 1.0},
                       **{name: {"mass": [0.1, 3.0], "com_radius": 1.0}
                          for name in ("crank", "upper", "lower")}}
    return spec


def _run(*args: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return code, out.getvalue(), err.getvalue()


@pytest.fixture
def spec_file(tmp_path):
    path = tmp_path / "crank_slide.toml"
    path.write_text(dumps_design(design_from_dict(_spec())))
    return path


def test_the_slides_load_is_a_force(spec_file, tmp_path):
    code, out, err = _run("analyze", str(spec_file), "--csv", str(tmp_path / "a.csv"))
    assert code == 0, err
    assert "force on block" in out and "torque on crank" in out
    line = next(x for x in out.splitlines() if x.startswith("force on block"))
    assert line.split()[-1] == "N"
    rows = list(csv.reader(io.StringIO((tmp_path / "a.csv").read_text())))
    header = rows[0]
    assert header[:3] == ["t", "crank", "block"] and "torque_block" in header
    block = np.array([float(r[2]) for r in rows[1:]])  # the block's change along its slide, m
    assert abs(block.max() - 0.04) <= 1e-12 and abs(block[0]) <= 1e-15


def test_a_crank_and_slide_balanced_for_every_motion_is_proved_by_simulation(spec_file, tmp_path):
    out_spec = tmp_path / "balanced.toml"
    code, out, err = _run("optimize", str(spec_file), "--json", "--out", str(out_spec))
    assert code == 0, err
    doc = json.loads(out)
    assert doc["status"] == "optimal" and doc["force_balanced"]
    check = doc["verification"]["motions"]["press"]
    assert check["force_level"] <= 1e-12 and check["formulations_agree_to"] <= 1e-10
    assert check["original_max_shaking_force"] > 1.0  # (the unbalanced one shakes: 2.25 N)
    assert set(check["max_torques"]) == {"crank", "block"}
    code, out, err = _run("analyze", str(out_spec), "--json")
    assert code == 0, err
    again = json.loads(out)
    assert again["force_balanced"] and again["workspace"]["centre_of_mass_excursion"] <= 1e-12


def test_a_slide_alone_is_not_an_input():
    spec = crank_slider()
    spec["mechanism"]["inputs"] = ["block"]
    with pytest.raises(SpecError) as caught:
        design_from_dict(spec)
    assert caught.value.key in ("mechanism", "mechanism.input", "mechanism.inputs")


def test_a_slider_force_of_the_crank_angle_needs_a_crank():
    # A slider's gas force is a table of the crank's angle (a spec gives one to a slider-crank
    # alone; a model made in Python may put one on any slider): a linkage with several inputs
    # has no crank to read it at, and is refused naming it.
    import dataclasses

    from balancer.model import GasForce

    linkage = design_from_dict(crank_slider()).mechanism
    pushed = dataclasses.replace(linkage.sliders[0], force=GasForce(angles=(0.0, 3.0),
                                                                    values=(-1.0, 0.0)))
    with pytest.raises(SpecError, match="a linkage with several inputs has no crank") as caught:
        dataclasses.replace(linkage, sliders=(pushed,))
    assert caught.value.key == "links.block.gas_force"
