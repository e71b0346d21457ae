"""Progress on stderr: a bar on a terminal for long work, nothing on a pipe or with --json."""

from __future__ import annotations

import io
import sys
from pathlib import Path

import pytest

from balancer import progress as progress_module
from balancer.cli import main
from balancer.progress import Progress, is_terminal

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


class Tty(io.StringIO):
    """A stream that says it is a terminal."""

    def isatty(self):
        return True


class Closed(io.StringIO):
    def isatty(self):
        raise ValueError("I/O operation on closed file")


def test_a_bar_is_drawn_on_a_terminal_only_and_cleared_at_the_end():
    tty, pipe = Tty(), io.StringIO()
    for stream in (tty, pipe):
        with Progress("simulating", stream=stream, delay=0.0, refresh=0.0) as p:
            p(2.5, 5.0)
    text = tty.getvalue()
    assert "simulating:  50.0 %" in text and "2.5 of 5 s" in text
    assert text.endswith("\r")  # cleared: the last thing written returns to the line's start
    assert pipe.getvalue() == ""


def test_no_bar_when_disabled_or_before_the_delay_or_on_an_odd_stream():
    quiet = Tty()
    with Progress("x", stream=quiet, enabled=False, delay=0.0) as p:
        assert not p.active
        p(1.0, 2.0)
    assert quiet.getvalue() == ""
    slow = Tty()
    with Progress("x", stream=slow, delay=60.0) as p:
        p(1.0, 2.0)  # within the first minute: nothing yet
    assert slow.getvalue() == ""
    assert not is_terminal(Closed()) and not is_terminal(None) and is_terminal(Tty())


def test_the_total_may_grow_while_the_work_goes_on():
    tty = Tty()
    with Progress("verifying", stream=tty, delay=0.0, refresh=0.0) as p:
        p(1.0, 2.0)
        p(1.5, 4.0)
    assert "1.5 of 4 s" in tty.getvalue()


@pytest.mark.parametrize(("json", "terminal", "shown"),
                         [(False, True, True), (True, True, False), (False, False, False)])
def test_simulate_shows_progress_on_a_terminal_unless_json(monkeypatch, capsys, json, terminal,
                                                           shown):
    monkeypatch.setattr(progress_module, "DELAY", 0.0)
    stream = Tty() if terminal else io.StringIO()
    monkeypatch.setattr(sys, "stderr", stream)
    args = ["simulate", str(EXAMPLES / "meijaard2020.toml"), "--duration", "0.2"]
    assert main(args + (["--json"] if json else [])) == 0
    assert ("simulating:" in stream.getvalue()) is shown
    capsys.readouterr()


@pytest.mark.parametrize(("json", "shown"), [(False, True), (True, False)])
def test_verify_shows_the_progress_of_its_simulations(monkeypatch, capsys, json, shown):
    monkeypatch.setattr(progress_module, "DELAY", 0.0)
    stream = Tty()
    monkeypatch.setattr(sys, "stderr", stream)
    args = ["verify", str(EXAMPLES / "meijaard2020.toml"), "--duration", "0.2"]
    assert main(args + (["--json"] if json else [])) == 0
    assert ("verifying by simulation:" in stream.getvalue()) is shown
    capsys.readouterr()
