"""Sealed contact modes (`ContactModes.seal`) change nothing: second implementation, every
`ModesIndex` read afresh from the pair states at each use. A complete-set run with far pairs
sought again, impacts and sliding is bitwise the same."""
import numpy as np

from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.systems.contact_types import ContactModes, ModesIndex

SCENE = "contact: {pairs: complete}\ninitial: {target_yaw_deg: -8.0}\nsimulation: {duration: 0.5}"


def _run():
    s = load_scenario(data=SCENE)
    r = simulate(s, place(s))
    return r, (r.end_time, r.evaluations, r.mode_changes, len(r.impacts), np.array(r.record.x),
               np.array(r.record.couples))


def test_sealed_index_equals_the_pairs_read_afresh(monkeypatch):
    kept, a = _run()
    monkeypatch.setattr(ContactModes, "index", lambda self: ModesIndex.of(self.pairs))
    fresh, b = _run()
    assert kept.mode_changes > 5 and len(kept.impacts) > 0        # events happened
    for x, y in zip(a, b):
        assert np.array_equal(x, y)
