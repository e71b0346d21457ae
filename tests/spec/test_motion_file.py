"""A motion read from a CSV file (``[[motion]] file = …``): the same motion as written inline.

Second route: the same table given as ``times`` and ``path`` in the spec, whose analysis the
file's must equal to the last bit; the spec written back holds the table inline and reads
back equal.
"""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest
from linkage.several_inputs_specs import fivebar

from balancer.cli import main
from balancer.errors import SpecError
from balancer.spec.reader import design_from_dict, load_design
from balancer.spec.writer import dumps_design

TIMES = np.linspace(0.0, 1.0, 26)
#: Each input's change from the reference pose (rad): a smooth swing out and back.
PATH = np.column_stack([0.2 * np.sin(np.pi * TIMES) ** 2, -0.15 * np.sin(np.pi * TIMES)])


def _csv(rows=None, header="t,left,right") -> str:
    body = "\n".join(",".join(repr(float(x)) for x in (t, *p))
                     for t, p in zip(TIMES, PATH, strict=True)) if rows is None else rows
    return f"{header}\n{body}\n"


def _spec_text(motion: str) -> str:
    design = design_from_dict(fivebar())
    return dumps_design(design) + f"\n[[motion]]\nname = \"swing\"\n{motion}samples = 64\n"


def test_a_file_motion_is_the_inline_one(tmp_path):
    (tmp_path / "swing.csv").write_text(_csv())
    (tmp_path / "file.toml").write_text(_spec_text('file = "swing.csv"\n'))
    rows = ", ".join("[" + ", ".join(repr(float(x)) for x in p) + "]" for p in PATH)
    times = ", ".join(repr(float(t)) for t in TIMES)
    (tmp_path / "inline.toml").write_text(
        _spec_text(f'times = [{times}]\npath = [{rows}]\nlaw = "spline"\n'))
    from_file, inline = (load_design(tmp_path / n) for n in ("file.toml", "inline.toml"))
    assert from_file.motions == inline.motions  # the law a file's motion defaults to: spline
    # Written back, the table is the spec's own (a file beside the spec need not follow it).
    again = design_from_dict(__import__("tomllib").loads(dumps_design(from_file)))
    assert again.motions == from_file.motions


def test_a_file_motion_is_found_beside_its_spec_wherever_it_is_run(tmp_path, monkeypatch):
    folder = tmp_path / "robot"
    folder.mkdir()
    (folder / "swing.csv").write_text(_csv())
    (folder / "spec.toml").write_text(_spec_text('file = "swing.csv"\n'))
    monkeypatch.chdir(tmp_path)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["analyze", "robot/spec.toml", "--json"])
    assert code == 0, err.getvalue()
    assert '"swing"' in out.getvalue()


@pytest.mark.parametrize(("content", "words"), [
    (None, "cannot be read"),
    (_csv(header="t,right,left"), "its header must be t,left,right"),
    (_csv(rows="0.0,0.0,0.0\n0.5,0.1\n1.0,0.0,0.0"), "line 3 has 2 values, not 3"),
    (_csv(rows="0.0,0.0,0.0\n0.5,x,0.1\n1.0,0.0,0.0"), "line 3 is not numbers"),
    (_csv(rows="0.0,0.0,0.0\n0.5,nan,0.1\n1.0,0.0,0.0"), "line 3 is not finite"),
    (_csv(rows="0.0,0.0,0.0\n1.0,0.1,0.1\n0.5,0.0,0.0"), "line 4's time 0.5 s does not increase"),
])
def test_a_bad_file_is_refused_naming_the_key(tmp_path, capsys, content, words):
    if content is not None:
        (tmp_path / "swing.csv").write_text(content)
    spec = tmp_path / "spec.toml"
    spec.write_text(_spec_text('file = "swing.csv"\n'))
    code = main(["analyze", str(spec)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "motion[1].file: " in err and words in err and "Traceback" not in err, err


def test_a_points_path_from_a_file(tmp_path):
    # With `point`, the file gives the point's x and y (m): the same motion as written inline.
    rows = [(0.0, 0.1, 0.35), (0.4, 0.115, 0.36), (0.7, 0.12, 0.345), (1.0, 0.1, 0.35)]
    (tmp_path / "apex.csv").write_text("t,x,y\n" + "\n".join(
        ",".join(repr(x) for x in r) for r in rows) + "\n")
    (tmp_path / "file.toml").write_text(_spec_text('point = "E"\nfile = "apex.csv"\n'))
    inline = _spec_text('point = "E"\ntimes = [0.0, 0.4, 0.7, 1.0]\npath = [[0.1, 0.35], '
                        '[0.115, 0.36], [0.12, 0.345], [0.1, 0.35]]\nlaw = "spline"\n')
    (tmp_path / "inline.toml").write_text(inline)
    from_file, written = (load_design(tmp_path / n) for n in ("file.toml", "inline.toml"))
    assert from_file.motions == written.motions and from_file.motions[-1].closed
    (tmp_path / "apex.csv").write_text("t,left,right\n0.0,0.0,0.0\n1.0,0.1,0.1\n")
    with pytest.raises(SpecError, match="its header must be t,x,y") as caught:
        load_design(tmp_path / "file.toml")
    assert caught.value.key == "motion[1].file"


def test_a_file_motion_takes_no_times_or_path(tmp_path):
    (tmp_path / "swing.csv").write_text(_csv())
    spec = tmp_path / "spec.toml"
    spec.write_text(_spec_text('file = "swing.csv"\ntimes = [0.0, 1.0]\n'))
    with pytest.raises(SpecError, match="takes its times and path from it") as caught:
        load_design(spec)
    assert caught.value.key == "motion[1].times"  # (after the spec's own motion)
