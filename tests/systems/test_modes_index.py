"""The contact modes held by a context are sealed: what evaluations read of them (`ModesIndex`)
is computed once, copies share the pair states, and a change raises instead of going unseen."""
import copy
import math
import pickle

import numpy as np
import pytest

from drake_dock.core.hybrid import Mode
from drake_dock.systems.contact_types import ContactModes, ModesIndex, PairState


def _states(rng, k=40):
    out = []
    for _ in range(k):
        mode = Mode(int(rng.integers(0, 4)))
        ref = None if rng.uniform() < 0.3 else (np.eye(3), rng.normal(size=3))
        out.append(PairState(mode, sigma=float(rng.choice([-1.0, 1.0])),
                             clearance=float(rng.uniform()), ref_X21=ref,
                             distance=float(rng.uniform())))
    return out


def test_index_reads_the_states():
    """Each field of the index against a pass over the pairs."""
    rng = np.random.default_rng(3)
    for _ in range(20):
        states = _states(rng)
        ix = ContactModes(states).seal().index()
        far = [i for i, st in enumerate(states) if st.mode == Mode.FAR]
        assert ix.near == tuple(i for i in range(len(states)) if i not in far)
        assert ix.far.tolist() == far
        assert ix.clearance.tolist() == [states[i].clearance for i in far]
        assert ix.distance.tolist() == [states[i].distance for i in far]
        assert ix.sought.tolist() == [states[i].ref_X21 is not None for i in far]
        assert ix.sigma.tolist() == [st.sigma for st in states]


def test_sealed_modes_are_shared_by_copies_and_refuse_changes():
    modes = ContactModes([PairState(Mode.FAR), PairState(Mode.TRACKED)]).seal()
    clone = copy.deepcopy(modes)
    assert clone.pairs[0] is modes.pairs[0] and clone.index() is modes.index()
    with pytest.raises(AttributeError, match="sealed"):
        clone.pairs[0].mode = Mode.TRACKED
    work = modes.working_copy()
    work.pairs[0].mode, work.pairs[0].clearance = Mode.TRACKED, 0.5
    assert modes.pairs[0].mode == Mode.FAR and modes.pairs[0].clearance == 0.0
    assert work.index().near == (0, 1)                # not sealed: read afresh
    assert modes.index().near == (1,)
    again = copy.deepcopy(work)                        # an unsealed copy is a deep one
    assert again.pairs[0] is not work.pairs[0] and again.pairs[0] == work.pairs[0]
    with pytest.raises(TypeError):                     # sealed pairs are a tuple
        clone.pairs[0] = PairState(Mode.TRACKED)
    with pytest.raises(AttributeError, match="sealed"):
        clone.mode_changes = 3
    with pytest.raises(ValueError):                    # and the index's arrays read-only
        modes.index().far[0] = 1


def test_a_single_state_copied_or_pickled_is_not_sealed():
    """Only the context's modes are sealed: a state copied by any means, or modes pickled,
    can be changed, and their index is read afresh."""
    modes = ContactModes([PairState(Mode.FAR, ref_X21=(np.eye(3), np.zeros(3))),
                          PairState(Mode.TRACKED)]).seal()
    for st in (copy.copy(modes.pairs[0]), copy.deepcopy(modes.pairs[0]),
               pickle.loads(pickle.dumps(modes.pairs[0]))):
        st.mode = Mode.TRACKED
        assert modes.pairs[0].mode == Mode.FAR
    back = pickle.loads(pickle.dumps(modes))
    back.pairs[0].mode = Mode.SLIDING
    assert back.index().near == (0, 1) and modes.index().near == (1,)


def test_far_bounds_from_the_index_equal_the_pair_by_pair_ones():
    """`FarPairs.bounds_of` (the sealed index's stacked references) against `FarPairs.bounds`
    (each pair's reference read from its state), exactly, with pairs not far and never
    sought among them."""
    from drake_dock.studies.small_scenes import stool
    system = stool().system
    far = system.far
    rng = np.random.default_rng(5)
    k = len(system.pairs)
    for _ in range(10):
        poses = [(np.linalg.qr(rng.normal(size=(3, 3)))[0], rng.normal(size=3))
                 for _ in system.frames]
        states = [PairState(Mode(int(rng.integers(0, 2))),
                            ref_X21=None if rng.uniform() < 0.3 else
                            (np.linalg.qr(rng.normal(size=(3, 3)))[0], rng.normal(size=3)))
                  for _ in range(k)]
        ix = ContactModes(states).seal().index()
        got = far.bounds_of(ix, states, poses)
        want = far.bounds(ix.far.tolist(), poses, states)
        assert np.array_equal(got, want)
        assert all(math.isinf(b) for b, s in zip(got, ix.sought) if not s)
    assert isinstance(ix, ModesIndex)
