"""The outputs' own spacing (`simulation.output_period`): the record of a run whose step is
capped at 0.01 s holds its samples at the multiples of a 2 ms period, interpolated within the
steps (`simulate._Grid`), and the states just before and after each impact. Checked on the
paper's example against a converged run (accuracy 1e-10, steps of at most 0.2 ms, a sample
at every step end): the interpolated positions and velocities equal the converged ones at the
grid times to the integration's accuracy, the impacts are the converged run's, and the
capture time is within 1e-7 s of it."""
import numpy as np
import pytest

from drake_dock.docking.model.simulate import POST_IMPACT, PRE_IMPACT, STEP, simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import MODELS_DIR

PERIOD, CAP = 0.002, 0.01


def _run(**config):
    s = load_scenario(MODELS_DIR / "paper_example.yaml")
    period = config.pop("output_period", None)
    s.simulation.output_period = period
    for k, v in config.items():
        setattr(s.simulator_config, k, v)
    return simulate(s, place(s))


@pytest.fixture(scope="module")
def runs():
    return (_run(max_step_size=CAP, output_period=PERIOD),
            _run(max_step_size=CAP),
            _run(max_step_size=2e-4, accuracy=1e-10))


def _at(ref, t):
    """The converged run's [q, v] at the times t, by linear interpolation of its step ends
    (steps of at most 0.2 ms: an error far below the runs' own), away from its impacts (t not
    within a step of one); and the indices of t kept."""
    T, X = np.array(ref.record.t), ref.record.x
    kind = np.array(ref.record.kind)
    out, keep = [], []
    for j, tk in enumerate(t):
        i = int(np.searchsorted(T, tk))
        if 0 < i < len(T) and kind[i] == STEP and kind[i - 1] == STEP:
            a = (tk - T[i - 1]) / (T[i] - T[i - 1])
            out.append((1 - a) * X[i - 1] + a * X[i])
            keep.append(j)
    return np.array(out), keep


def test_samples_at_the_period_and_at_the_impacts(runs):
    grid, steps, ref = runs
    t, kind = np.array(grid.record.t), np.array(grid.record.kind)
    inner = t[kind == STEP][1:-1]
    k = np.round(inner / PERIOD)
    np.testing.assert_array_equal(inner, k * PERIOD)
    np.testing.assert_array_equal(np.diff(k), 1.0)          # every multiple, none twice
    assert np.all(np.diff(t) >= 0.0)
    assert np.count_nonzero(kind == PRE_IMPACT) == np.count_nonzero(kind == POST_IMPACT) \
        == len(grid.impacts) == len(ref.impacts)
    np.testing.assert_allclose(t[kind == PRE_IMPACT], [i.t for i in grid.impacts], rtol=0,
                               atol=0)
    # The step is the error control's, not the period's: far fewer steps than samples.
    assert len(steps.record.t) < 0.5 * len(grid.record.t)
    assert grid.end_time == t[-1]


def test_interpolated_samples_equal_the_converged_run(runs):
    grid, steps, ref = runs
    t, kind = np.array(grid.record.t), np.array(grid.record.kind)
    sel = np.flatnonzero(kind == STEP)[1:-1]
    X_ref, keep = _at(ref, t[sel])
    assert len(keep) > 0.8 * len(sel)
    err = np.abs(grid.record.x[sel[keep]] - X_ref).max()
    assert err < 2e-6
    assert abs(grid.capture_time - ref.capture_time) < 1e-7
    # Linear interpolation of the step ends of the same integration misses by much more:
    # the samples are the steps' interpolants, not their chords.
    Ts, Xs = np.array(steps.record.t), steps.record.x
    lin = np.array([np.interp(t[sel[keep]], Ts, Xs[:, c]) for c in range(Xs.shape[1])]).T
    assert np.abs(lin - X_ref).max() > 5 * err
