"""The DOP853 integrator (balancer.simulation.integrator) against SciPy's, its oracle."""

from __future__ import annotations

import numpy as np
import pytest

from balancer.simulation.integrator import DOP853, TimeOnlyDOP853


def _forced_pendulum(t, y):
    return np.array([y[1], -np.sin(y[0]) + 0.3 * np.cos(1.7 * t), y[0] * y[1]])


@pytest.mark.parametrize(("rtol", "atol"), [
    (1e-3, np.array([1e-6, 1e-6, 1e-3])),
    (1e-6, 1e-9),
    (1e-11, 1e-13),
])
def test_steps_and_dense_outputs_are_scipys(rtol, atol):
    # The same tableau, initial step, error norm, controller and interpolant, in the same
    # order of operations: SciPy's DOP853 step for step, bit for bit.
    from scipy.integrate import DOP853 as Reference

    y0 = np.array([1.0, 0.0, 0.0])
    ref = Reference(_forced_pendulum, 0.0, y0, 20.0, rtol=rtol, atol=atol)
    run = DOP853(_forced_pendulum, 0.0, y0, 20.0, rtol=rtol, atol=atol)
    steps = 0
    while ref.status == "running":
        ref.step()
        run.step()
        steps += 1
        assert (run.t, run.t_old, run.status, run.nfev) == (ref.t, ref.t_old, ref.status,
                                                            ref.nfev)
        assert np.array_equal(run.y, ref.y)
        assert np.array_equal(run.f, ref.f)
        times = np.linspace(ref.t_old, ref.t, 5)
        mine, theirs = run.dense_output(), ref.dense_output()
        assert np.array_equal(mine(times), theirs(times))  # all of a step's times in one call
        assert np.array_equal(mine(times[2]), theirs(times[2]))
    assert run.status == "finished" and run.t == 20.0 and steps > 10


def test_a_given_first_step_and_an_empty_interval():
    run = DOP853(_forced_pendulum, 0.0, np.array([1.0, 0.0, 0.0]), 1.0, rtol=1e-8, atol=1e-10,
                 first_step=1e-3)
    run.step()
    assert run.t == 1e-3
    with pytest.raises(ValueError, match="first step"):
        DOP853(_forced_pendulum, 0.0, np.zeros(3), 1.0, rtol=1e-8, atol=1e-10, first_step=2.0)
    still = DOP853(_forced_pendulum, 0.0, np.zeros(3), 0.0, rtol=1e-8, atol=1e-10)
    assert still.step() is None and still.status == "finished"
    assert np.array_equal(still.dense_output()(np.array([0.0, 0.0])), np.zeros((3, 2)))


def test_a_right_hand_side_of_the_time_alone_takes_the_same_steps():
    # A motor's work over a prescribed motion: the stages need no combination of the earlier
    # ones, and the steps are DOP853's, bit for bit.
    def power(t, y):
        return np.array([np.sin(3 * t) ** 2 * np.cos(t), 0.5 + np.cos(7 * t)])

    runs = [kind(power, 0.0, np.zeros(2), 5.0, rtol=1e-9, atol=1e-11)
            for kind in (DOP853, TimeOnlyDOP853)]
    while runs[0].status == "running":
        for run in runs:
            run.step()
        plain, quick = runs
        assert (quick.t, quick.nfev, quick.status) == (plain.t, plain.nfev, plain.status)
        assert np.array_equal(quick.y, plain.y)
        mid = 0.5 * (plain.t_old + plain.t)
        assert np.array_equal(quick.dense_output()(mid), plain.dense_output()(mid))
