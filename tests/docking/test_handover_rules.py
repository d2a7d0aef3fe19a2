"""The rules that keep a hand-over from going to and fro
(`drake_dock.systems.handover_links.accepts`): on the paper example with
`contact.pairs: complete` and the edge/surface hand-overs declared, the ring's circles stay
clear of the petals while the rings are coaxial, where a circle has no isolated couple with a
cone and the edge guard of a symmetric motion sits at zero. Every hand-over that falls due
there is refused, and the run equals the run without hand-overs (second implementation: no
pair can be handed over) to the integrator's tolerance; without the rules the same run hands
couples to and fro."""
import math

import pytest

from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import contact_approach, place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.errors import NumericalError
from drake_dock.systems import handover_links
from drake_dock.systems.simulator import tolerances

COMPLETE = "contact: {pairs: complete}"


@pytest.fixture(scope="module")
def scenario():
    s = load_scenario(data=COMPLETE)
    return s, place(s)


def _run(scenario, handovers):
    s, state = scenario
    return simulate(s, state, dd=build_docking_diagram(DiagramSpec.of(s, handovers=handovers)))


def test_refused_handovers_leave_the_run_unchanged(scenario, monkeypatch):
    decided = []
    accepts = handover_links.accepts

    def counted(*args):
        decided.append(accepts(*args))
        return decided[-1]

    monkeypatch.setattr(handover_links, "accepts", counted)
    r = _run(scenario, True)
    ref = _run(scenario, False)
    assert len(decided) > 0 and not any(decided)
    assert r.outcome == ref.outcome == "captured"
    assert abs(r.capture_time - ref.capture_time) <= 1e-8
    assert len(r.impacts) == len(ref.impacts)


def test_without_the_rules_the_couples_go_to_and_fro(scenario, monkeypatch):
    """Every hand-over that falls due taken: more are taken than twice the declared hand-overs
    (each could go once each way), so couples go to and fro. That run is not the physical run:
    a couple handed where the rules refuse it (singular, or not the same pair of points) can
    meet a patch the run without hand-overs never touches. It either captures later, after
    more impacts, or stops on a typed numerical failure naming its time and couples."""
    taken = []

    def take(*args):
        taken.append(args)
        return True

    monkeypatch.setattr(handover_links, "accepts", take)
    s, _ = scenario
    declared = DockingScene.of(s).handovers
    ref = _run(scenario, False)
    try:
        r = _run(scenario, True)
    except NumericalError as e:
        assert e.time is not None and e.time > 0 and e.couples
        r = None
    assert len(taken) > 2 * len(declared) > 0
    assert ref.outcome == "captured"
    if r is not None:
        assert r.outcome == "captured"
        # Not earlier than the witness can tell apart (Drake isolates the capture's zero to
        # within its window).
        window = tolerances(s.simulator_config).witness_window
        assert r.capture_time >= ref.capture_time - window
        assert len(r.impacts) >= len(ref.impacts)


def test_the_complete_set_shifts_the_paper_example_by_its_first_contact(scenario):
    """With the complete set the first contact of the paper example's approach is the rings'
    inside circles grazing the other APDS's tip arcs, at the ring-face distance H (closed form:
    the inside circle's radius is R - H cot(alpha1), the tip arcs' radius). The paper's pairs
    close later, at their own first-contact distance, and nothing acts in between: every impact
    and the capture are the paper pairs' run shifted by the difference of the two distances
    over the closing speed (to 1e-6 s)."""
    s, _ = scenario
    g = s.geometry
    assert abs(g.R - g.H / math.tan(g.alpha1) - g.Rs) <= 1e-12
    paper = load_scenario()
    _, lam_complete, closing = contact_approach(s)
    _, lam_paper, _ = contact_approach(paper)
    assert abs(lam_complete - g.H) <= 1e-9 and all("tip" in name for name in closing)
    shift = (lam_complete - lam_paper) / s.initial.chaser_speed
    r, ref = simulate(s, place(s)), simulate(paper, place(paper))
    assert r.outcome == ref.outcome == "captured" and len(r.impacts) == len(ref.impacts) > 0
    assert abs(r.capture_time - ref.capture_time - shift) <= 1e-6
    for a, b in zip(r.impacts, ref.impacts):
        assert a.couples == b.couples and abs(a.t - b.t - shift) <= 1e-6
