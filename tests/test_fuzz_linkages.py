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


@pytest.mark.parametrize(("index", "message", "named"), [
    (28, "balancer: error: spec.toml: springs[1].stiffness: must be a number (got 'stiff')",
     True),
    (28, "balancer: error: spec.toml: springs[0].stiffness: must be a number (got 'stiff')",
     False),  # the first spring is springs[1] in a message
    (306, "balancer: error: spec.toml: mechanism.sliders[1].direction[0]: must be a finite "
          "number (got nan)", True),
])
def test_an_item_of_an_array_of_tables_is_named_as_the_docs_count_it(index, message, named):
    """Seed 40 (issue 40's runs): the messages count springs and sliders from 1 (commit
    f96e5e0, validate.item), the generator's keys from 0, and the campaign called 92 exit-2
    messages that name the first spring ``springs[1]`` 'without the key named'."""
    from fuzz.linkage_campaign import Run, classify

    case = make_case(40, index)
    run = Run(verb="analyze", argv=("analyze", "spec.toml", "--json"), rc=2, stderr=message)
    classify(case, run)
    assert any(d.startswith("exit 2 without the key named") for d in run.defects) != named
