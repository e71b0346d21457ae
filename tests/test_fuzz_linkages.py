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
