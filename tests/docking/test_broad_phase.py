"""The broad phase (`ContactOptions.broad_phase`, `Transitions.screen`) never keeps from a seek a
pair that makes contact. Second implementation: the narrow phase decides every pair, i.e. each
pair the broad phase would screen is sought, and sought for real whenever the seek would not
leave it far; the runs of `contact.pairs: complete` scenes are bitwise the same and every seek
distance of a screened pair is at least its covers' gap."""
import copy

import numpy as np
import pytest

from drake_dock.core.hybrid import Mode
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.systems.transitions import Transitions

SCENES = {"paper example": "contact: {pairs: complete}",
          "roll -8 deg": "contact: {pairs: complete}\n"
                        "initial: {target_yaw_deg: -8.0}"}


def _narrow_phase(checks):
    screen = Transitions.screen

    def checked(self, i, poses, states):
        gap = self.ev.far.cover_gap(i, poses)
        if not gap >= self.options.track_distance:
            return screen(self, i, poses, states)
        sought = copy.deepcopy(states)
        self._seek(i, poses, sought, np.zeros(self.ev.nu), 0.0, False, False)
        checks.append((gap, sought[i].distance))
        if sought[i].mode != Mode.FAR:
            return False                   # the narrow phase tracks it: seek for real
        return screen(self, i, poses, states)

    return checked


def _run(data):
    s = load_scenario(data=data)
    r = simulate(s, place(s))
    return (r.capture_time, r.end_time, r.evaluations, r.mode_changes, np.array(r.record.x),
            np.array(r.record.couples), [(imp["t"], imp["couples"]) for imp in r.impacts],
            r.timing["screens_per_pair"])


@pytest.mark.parametrize("name", SCENES)
def test_broad_phase_equals_the_narrow_phase_bitwise(name, monkeypatch):
    fast = _run(SCENES[name])
    checks = []
    monkeypatch.setattr(Transitions, "screen", _narrow_phase(checks))
    ref = _run(SCENES[name])
    assert sum(fast[-1].values()) > 0 and len(checks) == sum(ref[-1].values())
    assert all(d >= gap for gap, d in checks)
    for a, b in zip(fast[:-1], ref[:-1]):
        if isinstance(a, np.ndarray):
            assert np.array_equal(a, b)
        else:
            assert a == b


@pytest.mark.parametrize("pairs, screens", [("complete", True), ("paper", False)])
def test_options_a_caller_passes_take_the_scenes_broad_phase_policy(pairs, screens):
    """Options passed to `build_docking_diagram` with other fields changed and broad_phase left
    at its default: the complete set's far pairs are screened (the run's screening counters),
    the paper's are all sought; an explicit False is kept."""
    from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
    from drake_dock.systems.contact_types import ContactOptions
    s = load_scenario(data=f"contact: {{pairs: {pairs}}}")
    dd = build_docking_diagram(DiagramSpec.of(
        s, options=ContactOptions(reseek_early=0.8, impact_rtol=1e-9)))
    assert dd.contact.options.broad_phase is screens
    assert dd.contact.options.reseek_early == 0.8 and dd.contact.options.impact_rtol == 1e-9
    r = simulate(s, place(s), dd=dd, duration=0.01)
    assert (sum(r.timing["screens_per_pair"].values()) > 0) is screens
    off = build_docking_diagram(DiagramSpec.of(
        s, options=ContactOptions(reseek_early=0.8, broad_phase=False)))
    assert off.contact.options.broad_phase is False
