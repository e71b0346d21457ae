"""Messages a designer reads (issue 40): hints, list items counted from 1, what to write.

- The did-you-mean of a typo prefers the key the typed word begins (``bank`` → ``bank_deg``,
  not ``crank``), then one of its stem, then the closest spelling.
- An item of an array of tables is named by its number from 1, as the docs count cylinders.
- An engine without ``[balance]`` is told what its balancing needs.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from balancer.cli import main
from balancer.errors import SpecError
from balancer.mechanisms.engine.model import Engine
from balancer.spec import load_design, loads_design
from balancer.spec.tables import meant

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


@pytest.mark.parametrize(("typed", "known", "expected"), [
    ("bank", ("z", "phase_deg", "bank_deg", "crank", "rod", "offset", "bore"), "bank_deg"),
    ("phase", ("z", "phase_deg", "bank_deg", "crank"), "phase_deg"),
    ("phase_rad", ("z", "phase_deg", "bank_deg"), "phase_deg"),
    ("mas", ("mass", "inertia", "com"), "mass"),
    ("inerta", ("mass", "inertia", "com"), "inertia"),
    ("Mass", ("mass", "inertia"), "mass"),
    ("sigmaa", ("s", "sigma", "e", "f"), "sigma"),
    ("xyz", ("mass", "inertia"), None),
])
def test_the_hint_prefers_the_key_the_typed_word_begins(typed, known, expected):
    assert meant(typed, known) == expected


def test_a_cylinder_key_typo_is_named_in_its_cylinder_counted_from_one(tmp_path, capsys):
    """`bank = 45.0` in the second cylinder got "mechanism.cylinders[1].bank: unknown key
    'bank'; did you mean 'crank'?"."""
    text = (EXAMPLES / "v8.toml").read_text()
    first, rest = text.split("bank_deg = 45.0", 1)
    spec = tmp_path / "typo.toml"
    spec.write_text(first + "bank = 45.0" + rest)
    assert main(["analyze", str(spec)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert ("mechanism.cylinders[2].bank: unknown key 'bank'; did you mean 'bank_deg'?"
            in err)


def test_every_list_item_in_a_message_is_counted_from_one():
    text = (EXAMPLES / "inline_four.toml").read_text()
    bad = text.replace("bore = 0.086\n", "", 1)  # no bore for any cylinder, with gas
    with pytest.raises(SpecError) as caught:
        loads_design(bad)
    assert caught.value.key == "mechanism.cylinders[1].bore"
    shaft = text.replace("ratio = -2", "ratio = 0", 1)
    with pytest.raises(SpecError) as caught:
        loads_design(shaft)
    assert caught.value.key == "balance_shafts[2].ratio"
    engine = load_design(EXAMPLES / "inline_four.toml").mechanism
    assert "mechanism.cylinders[4].crank" in engine.sizes
    assert "mechanism.cylinders[0].crank" not in engine.sizes
    with pytest.raises(SpecError) as caught:
        Engine(cylinders=(*engine.cylinders, "x"), rod=engine.rod, piston=engine.piston)
    assert caught.value.key == "mechanism.cylinders[5]"


def test_an_engine_without_balance_is_told_what_to_write(capsys, tmp_path):
    for verb in (["optimize", "--no-verify"], ["pareto", "--against", "added-mass"],
                 ["sweep", "--vary", "operation.speed=100:200:2", "--workers", "0", "--out",
                  str(tmp_path / "s.parquet")]):
        assert main([verb[0], str(EXAMPLES / "v8.toml"), *verb[1:]]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Traceback" not in err
        assert "balance: missing required table" in err
        assert "[balance.counterweights]" in err and "max_mr" in err
        assert "[[balance.shafts]]" in err
    assert main(["optimize", str(EXAMPLES / "meijaard2020.toml"), "--no-verify"]) == 2
    err = capsys.readouterr().err
    assert "the redesign problem ([balance])" in err and "counterweights" not in err
