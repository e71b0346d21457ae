"""Every verb's outputs on every shipped example, as recorded before a restructuring.

A guard, not a check of correctness (see ``tests/golden/record.py``): a change meant to move
code without changing results must leave the outputs as they were — the same text, every figure
the same to another machine's rounding (:func:`golden.record.difference`), wall-clock times
masked. A change meant to alter outputs records them again (``python -m tests.golden.record``)
in the same commit, which then shows what moved.
"""

from __future__ import annotations

import pytest
from golden.record import STORE, commands, difference, examples, mask, output

CASES = [(name, key) for name in examples() for key in commands(name)]


@pytest.mark.parametrize(("name", "key"), CASES, ids=[f"{n}-{k}" for n, k in CASES])
def test_outputs_are_as_recorded(name, key):
    # Recorded in one checkout, compared in another: the paths are masked on both sides.
    problem = difference(mask((STORE / name / key).read_text()), output(name, key),
                         table=key.endswith(".txt"))
    if problem is not None:
        pytest.fail(f"{name} {key}: {problem}")


def test_the_comparison_sees_a_change_and_forgives_rounding():
    text = '{"rms": 101.59012345678901, "max": 4.3e-14, "iterations": 48}\nRMS 101.59 N·m'
    assert difference(text, text) is None
    assert difference(text, text.replace("101.59012345678901", "101.59012345678912")) is None
    assert difference(text, text.replace("4.3e-14", "9.1e-14")) is None  # rounding-level
    assert difference(text, text.replace('"iterations": 48', '"iterations": 47')) is None
    assert difference(text, text.replace("101.59012345678901", "101.5902")) is not None
    assert difference(text, text.replace("RMS 101.59", "RMS 101.58")) is not None
    table = "quantity  RMS\nshaking moment  101.59  N·m"
    assert difference(table, table.replace("101.59", "101.58"), table=True) is None
    assert difference(table, table.replace("101.59", "101.57"), table=True) is not None
    assert difference(text, text.replace("N·m", "N")) is not None
