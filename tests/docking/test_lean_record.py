"""A lean record (`simulate(..., lean=True)`, a campaign's) keeps of each step-end sample the
values that `Record.derive` gives without couples, read from the run's own evaluation there,
and the run computes no more evaluations than a full one; what it derives is bitwise what a
full record derives by evaluating every sample again, at step-end samples and on an output
grid, with impacts."""
import copy

import numpy as np
import pytest

from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place

KEYS = ("lambda_n_max", "energy", "bushings", "ring_distance")


@pytest.mark.parametrize("period", [None, 0.01])
def test_lean_record_derives_what_the_full_one_does(paper_scenario, period):
    scenario = copy.deepcopy(paper_scenario)
    scenario.simulation.output_period = period
    state = place(scenario)
    full = simulate(scenario, state, duration=0.3)
    lean = simulate(scenario, state, duration=0.3, lean=True)
    assert len(full.impacts) >= 2           # the samples after impacts are covered
    assert np.array_equal(full.record.x, lean.record.x)
    assert lean.evaluations == full.evaluations   # the run evaluates nothing for its record
    a, b = full.record.derive(False), lean.record.derive(False)
    for k in KEYS:
        assert a[k].shape == b[k].shape and a[k].dtype == b[k].dtype, k
        assert np.array_equal(a[k], b[k]), k
    assert lean.record.lean and not full.record.lean
    # Couples are still there when asked: evaluated again, as a full record does.
    assert np.array_equal(full.record.couples, lean.record.couples)
