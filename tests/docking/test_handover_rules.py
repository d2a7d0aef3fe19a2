"""The rules that keep a hand-over from going to and fro (`Transitions._accepts`): on the
paper example with `contact.pairs: complete` and the edge/surface hand-overs declared, the
ring's circles stay clear of the petals while the rings are coaxial, where a circle has no
isolated couple with a cone and the edge guard of a symmetric motion sits at zero. Every
hand-over that falls due there is refused, and the run equals the run without hand-overs
(second implementation: no pair can be handed over) to the integrator's tolerance; without
the rules the same run hands couples to and fro and ends in a `DriftError`."""
import pytest

from drake_dock.docking.diagram import build_docking_diagram
from drake_dock.docking.scenario import load_scenario
from drake_dock.docking.scene import initial_state
from drake_dock.docking.simulate import simulate
from drake_dock.errors import DriftError
from drake_dock.systems.transitions import Transitions

COMPLETE = "contact: {pairs: complete}"


@pytest.fixture(scope="module")
def scenario():
    s = load_scenario(data=COMPLETE)
    return s, initial_state(s)


def _run(scenario, handovers):
    s, state = scenario
    return simulate(s, state=state, dd=build_docking_diagram(s, handovers=handovers))


def test_refused_handovers_leave_the_run_unchanged(scenario, monkeypatch):
    decided = []
    accepts = Transitions._accepts

    def counted(self, *args):
        decided.append(accepts(self, *args))
        return decided[-1]

    monkeypatch.setattr(Transitions, "_accepts", counted)
    r = _run(scenario, True)
    ref = _run(scenario, False)
    assert len(decided) > 0 and not any(decided)
    assert r.outcome == ref.outcome == "captured"
    assert abs(r.capture_time - ref.capture_time) <= 1e-8
    assert len(r.impacts) == len(ref.impacts)


def test_without_the_rules_the_couples_go_to_and_fro(scenario, monkeypatch):
    monkeypatch.setattr(Transitions, "_accepts", lambda self, *args: True)
    with pytest.raises(DriftError):
        _run(scenario, True)
