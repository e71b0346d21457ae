"""The general-linkage fuzz generator's expectations (``tests/fuzz/linkages.py``)."""

from __future__ import annotations

import pytest
from fuzz.linkages import _huge_expectation, make_case

MOVING = {"operation": {"speed": 10.0}}
AT_REST = {"links": {}}
AT_REST_WITH_GRAVITY = {"simulation": {"gravity": [0.0, -9.81]}}


@pytest.mark.parametrize(("leaf", "doc", "expect"), [
    ("mass", MOVING, "error"),
    ("inertia", MOVING, "error"),
    ("force", AT_REST, "error"),  # a force is a force at rest too
    ("moment", AT_REST, "error"),
    ("mass", AT_REST, "edge"),  # m·R·ω² = 0 and no weight: nothing leaves double precision
    ("inertia", AT_REST, "edge"),
    ("mass", AT_REST_WITH_GRAVITY, "error"),  # its weight does
    ("inertia", AT_REST_WITH_GRAVITY, "edge"),
])
def test_a_huge_mass_property_is_bad_input_only_where_it_enters_a_force(leaf, doc, expect):
    assert _huge_expectation(("links", "coupler", leaf), doc) == expect


def test_seed_4242_case_463_is_undecided():
    """``links.coupler.mass = 1e200`` on a spec without a speed or gravity: ``simulate``
    accepted it (exit 0), which the campaign called 'bad input accepted'."""
    case = make_case(4242, 463)
    assert b"mass = 1e+200" in case.spec
    assert case.expect == "edge"


@pytest.mark.parametrize(("stderr", "defect"), [
    ("balancer: note: operation.speed = 4.93778 rad/s (47.15 rpm) moves a point 82.61 m from "
     "the crank's pivot at 407.9 m/s, faster than sound (340 m/s): the speed is in rad/s (rpm "
     "written as rad/s?) and lengths in metres (mm written as m?)\n", False),
    ("", False),
    ("RuntimeWarning: overflow encountered in multiply\n", True),
])
def test_a_plausibility_note_on_success_is_no_defect(stderr, defect):
    """Seed 4040, case 1 (a slider 72 m from the crank's pivot at 4.9 rad/s): the command
    notes the speed, exit 0, as it must; the campaign called every line on stderr after a
    success a defect, where the CLI campaign (and its own check on failure) allows a note."""
    from fuzz.linkage_campaign import Run, classify

    case = make_case(4040, 1)
    run = Run(verb="analyze", argv=("analyze", "spec.toml", "--json"), rc=0, stdout="{}",
              stderr=stderr)
    classify(case, run)
    assert ("stderr output on success" in run.defects) == defect
