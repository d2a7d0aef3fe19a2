"""A far surface pair whose couple lies on a declared edge, where the linked edge pair is in
contact, is carried by that pair (`hybrid.after_seek` with ``carried``): its clearance is half
``track_distance``, not the reseek floor. A seek converges onto the edge from inside its
domain, so the surface pair's couple is on the edge within `handover.SEEK_EDGE_RTOL` of the
parameter's span (`handover.reaches_edge`). The scene: sample 0 of the IDSS envelope campaign
(models/idss_envelope.yaml), where the target ring slides on the guide side C6 of chaser
petal 3 from about 1.0 s, with the petal's surface pair cs_Tring_C3 touching the ring at that
edge."""
import pytest

from drake_dock.campaign.plan import load_plan
from drake_dock.campaign.sample import sample_scenario
from drake_dock.campaign.points import sample_specs
from drake_dock.core import handover
from drake_dock.core.hybrid import Mode
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.models_dir import MODELS_DIR

EDGE, SURFACE, T_END = "cc_Tring_C6", "cs_Tring_C3", 1.45


def _run_to(t_end):
    plan, base, fields = load_plan(MODELS_DIR / "idss_envelope.yaml")
    (_, _, values), = sample_specs(plan, fields, [0])
    s = sample_scenario(base, values)
    r = simulate(s, place(s), duration=t_end)
    names = [p.name for p in r.dd.contact.pairs]
    states = r.record.modes[-1].pairs
    opt = r.dd.contact.options
    return (states[names.index(EDGE)], states[names.index(SURFACE)], opt,
            r.timing["seeks_per_pair"][SURFACE])


def test_reaches_edge_within_the_seek_tolerance():
    """Closed form on a domain [0, 1] x [0, 0.2], the edge a0 = 1: a couple 1e-10 of the span
    inside lies on it with the seek's tolerance and not without; 1e-6 inside lies on neither."""
    edge = handover.SurfaceEdge(0, True, lambda e: e, lambda f: f)
    lo, hi = [0.0, 0.0], [1.0, 0.2]
    assert handover.reaches_edge(edge, lo, hi, [1.0 - 1e-10, 0.1], handover.SEEK_EDGE_RTOL)
    assert not handover.reaches_edge(edge, lo, hi, [1.0 - 1e-10, 0.1])
    assert not handover.reaches_edge(edge, lo, hi, [1.0 - 1e-6, 0.1], handover.SEEK_EDGE_RTOL)
    assert handover.reaches_edge(edge, lo, hi, [1.0, 0.1])
    assert not handover.reaches_edge(edge, lo, hi, [1.0, 0.25], handover.SEEK_EDGE_RTOL)


@pytest.fixture(scope="module")
def carried():
    return _run_to(T_END)


def test_a_surface_pair_touching_at_a_carried_edge_keeps_half_the_track_distance(carried):
    edge, surface, opt, _ = carried
    assert edge.mode.in_contact
    assert surface.mode == Mode.FAR
    assert surface.distance < 1e-9                    # touching the ring, at the edge
    assert surface.clearance == pytest.approx(0.5 * opt.track_distance, rel=1e-12)


def test_without_the_seek_tolerance_the_pair_is_sought_at_the_floor(carried, monkeypatch):
    """The same run with the edge tested exactly (neither the seek's tolerance nor that of a
    contact held by the linked pair, `handover.SEEK_HELD_TOL`): the surface pair's couple, a
    hair inside the edge, is not carried; its clearance is the reseek floor and it is sought
    many times more often."""
    seeks = carried[3]
    monkeypatch.setattr(handover, "SEEK_EDGE_RTOL", 0.0)
    monkeypatch.setattr(handover, "SEEK_HELD_TOL", 0.0)
    _, surface, opt, seeks_exact = _run_to(T_END)
    assert surface.mode == Mode.FAR and surface.distance < 1e-9
    assert surface.clearance == pytest.approx(opt.reseek_floor, rel=1e-12)
    assert seeks_exact > 5 * seeks
