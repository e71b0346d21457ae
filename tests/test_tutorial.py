"""docs/tutorial.md runs as written: its Python blocks, in order, in one namespace."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

#: The whole module is of the full suite, not of the fast lane (`pytest -m "not slow"`).
pytestmark = pytest.mark.slow

TUTORIAL = Path(__file__).resolve().parent.parent / "docs" / "tutorial.md"


def test_tutorial_runs_as_written(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # the pictures it saves land here
    blocks = re.findall(r"```python\n(.*?)```", TUTORIAL.read_text(encoding="utf-8"), re.S)
    assert len(blocks) >= 6
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, str(TUTORIAL), "exec"), namespace)  # noqa: S102 - our own docs
    for picture in ("pb1_cycle.png", "pb1_verify.pdf", "pb1_orders.png", "pb1.gif",
                    "front.png"):
        assert (tmp_path / picture).stat().st_size > 1000
    printed = capsys.readouterr().out
    assert "CycleAnalysis(four-bar" in printed and "BalanceResult(optimal" in printed


def test_the_api_is_one_import_with_one_signature_style():
    import inspect

    import balancer

    for name in balancer.__all__:
        assert getattr(balancer, name) is not None, name
    # Importing the modules behind the names does not shadow them (a submodule named like a
    # function would replace it on the package).
    import balancer.simulation  # noqa: F401
    import balancer.sweeps  # noqa: F401
    import balancer.verification  # noqa: F401

    for name in ("analyze", "optimize", "simulate", "verify", "pareto"):
        function = getattr(balancer, name)
        assert inspect.isfunction(function), name
        params = list(inspect.signature(function).parameters.values())
        assert params[0].name == "design"
        assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in params[1:]), name


def test_results_describe_themselves_in_a_line():
    import balancer

    design = balancer.example("pb1")
    results = [balancer.analyze(design), balancer.optimize(design, backend="convex"),
               balancer.simulate(design, duration=0.2),
               balancer.pareto(design, against="driving-torque", points=3)]
    for result in results:
        text = repr(result)
        assert "\n" not in text and len(text) < 400, text
        assert "array(" not in text
