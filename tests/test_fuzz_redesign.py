"""The redesign campaign in its quick mode: a few problems of every family, both backends.

The problems come from ``tests/fuzz/redesign_campaign.py`` (seeded, reproducible one by one:
``python -m tests.fuzz.redesign_campaign --seed SEED --family FAMILY --only PID`` runs one and
``--keep DIR`` writes its spec); each is solved by ``optimize`` with both backends and checked
against the campaign's independent program and maps, and the designer's report
(``optimization_json``) against the design. Any defect class fails the test with the problem's
spec. The long campaign is ``python -m tests.fuzz.redesign_campaign --problems N --seed S``.
"""

from __future__ import annotations

import pytest
from fuzz.redesign_campaign import CLASSES, MAKERS, make_case, run_problem

#: The whole module is of the full suite, not of the fast lane (`pytest -m "not slow"`).
pytestmark = pytest.mark.slow

SEED = 2611200
#: Problems of each family: the counterweights' families (new in issue 25) get more.
COUNTS = {"random": 12, "complete": 8, "zero-force": 6, "borderline": 12, "infeasible": 6,
          "scale": 10, "counterweight": 30, "cw-none": 30, "cw-borderline": 24}
#: Defects known and not fixed in the package, by (family, problem): the classes each shows.
#: The test fails when one of them is no longer seen (remove it then).
KNOWN: dict[tuple[str, int], set[str]] = {}


@pytest.mark.slow
@pytest.mark.parametrize("family", sorted(MAKERS))
def test_no_defect_in_a_quick_campaign(family):
    assert set(COUNTS) == set(MAKERS)
    found = []
    for pid in range(COUNTS[family]):
        case = make_case(SEED, pid, family=family)
        runs, meta = run_problem(case, ("convex", "nlp"), None)
        flagged = {cls for run in runs for cls in run.flags if cls in CLASSES}
        known = KNOWN.get((family, pid), set())
        if flagged != known:
            detail = "\n".join(f"  {run.backend}: {cls}: {run.flags[cls].strip()[:600]}"
                               for run in runs for cls in run.flags)
            found.append(f"problem {pid} ({family}, seed {SEED}): flagged {sorted(flagged)}, "
                         f"known {sorted(known)}\n{detail}\n--- spec ---\n{meta['text']}")
    if found:
        pytest.fail("\n\n".join(found), pytrace=False)
