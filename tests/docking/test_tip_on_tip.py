"""Two petal tips meeting coaxially at a large relative roll (complete set): the line contact
of two coaxial tip arcs carried by the corners at the ends of their overlap, each on the other
APDS's tip land (`corner_land_pairs`, docs/model.md "Tip on tip"). Against closed forms: the
roll beyond which the tips overlap (2 theta_end), the ring distance of the meeting (2H), the
corners that close (the overlap's ends), the first impact (two bodies along the axis with
Newton's restitution: the impulses are axial and equal by symmetry), and the tips never passing
each other (the ring distance stays >= 2H while the chaser stays coaxial); the independent
interpenetration checks (analytic and mesh) find nothing."""
import math

import numpy as np
import pytest

from drake_dock.docking.checks.mesh_check import deepest_penetration_mesh
from drake_dock.docking.checks.penetration import deepest_penetration
from drake_dock.docking.geometry.apds import tip_arc
from drake_dock.docking.geometry.pairs import CHASER_APDS, TARGET_APDS
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import contact_approach, place
from drake_dock.docking.placement.search import pair_couples
from drake_dock.docking.report.results import summary, timeseries
from drake_dock.docking.scenario.loading import load_scenario


def _coaxial(yaw, **simulation):
    s = load_scenario()
    s.contact.pairs = "complete"
    s.initial.target_yaw_deg = yaw
    for k, v in simulation.items():
        setattr(s.simulation, k, v)
    return s


def _in_span(az, arc):
    lo, hi = float(arc.lower[0]), float(arc.upper[0])
    return (az - lo) % (2 * math.pi) <= (hi - lo)


@pytest.mark.parametrize("yaw", [40.0, -59.9])
def test_the_overlap_ends_close_on_the_tip_lands_at_2H(yaw):
    """The six corner-land pairs that close are those whose corner lies over the other tip
    arc's span (closed form from the azimuths), at ring distance 2H, each couple touching
    (distance afresh from the geometry) inside its land."""
    s = _coaxial(yaw)
    g = s.geometry
    a, lam_c, names = contact_approach(s)
    assert lam_c == pytest.approx(2 * g.H, abs=1e-9)
    lands = [n for n in names if "tip" in n and n.startswith("ps_")]
    pose = {TARGET_APDS: (np.eye(3), np.zeros(3)), CHASER_APDS: a.pose(lam_c)}
    expected = set()
    for x, (R, p) in (("C", pose[CHASER_APDS]), ("T", pose[TARGET_APDS])):
        Ro, po = pose[TARGET_APDS] if x == "C" else pose[CHASER_APDS]
        for i in range(1, 7):
            arc_i = tip_arc(g, (i + 1) // 2)
            c = arc_i.position(arc_i.lower if i % 2 else arc_i.upper)
            q = Ro.T @ (R @ c + p - po)            # in the other APDS's frame
            for k in (1, 2, 3):
                if _in_span(math.atan2(q[1], q[0]), tip_arc(g, k)):
                    assert q[2] == pytest.approx(g.H, abs=1e-9)
                    r_tip = g.R - g.H / math.tan(g.alpha1)          # Eq. (12) at zeta = H
                    assert math.hypot(q[0], q[1]) == pytest.approx(r_tip, abs=1e-9)
                    expected.add(f"ps_{x}corner{i}_{'T' if x == 'C' else 'C'}tip{k}")
    assert len(expected) == 6 and set(lands) == expected
    specs = [p for p in DockingScene(g, "complete").pairs if p.name in expected]
    for c in pair_couples(specs, pose):
        assert c.interior and abs(c.distance) < 1e-9


def test_the_lands_close_only_beyond_a_roll_of_2_theta_end():
    s = _coaxial(0.0)
    edge = math.degrees(2 * s.geometry.theta_end)
    for yaw, lands in ((edge - 0.05, 0), (edge + 0.05, 6), (-edge - 0.05, 6)):
        s.initial.target_yaw_deg = yaw
        closing = place(s).closing_pairs
        assert sum(n.startswith("ps_") and "tip" in n for n in closing) == lands


def test_the_first_impact_is_the_two_body_closed_form():
    """Chaser (m_c, closing speed v) onto the target APDS (m_a, at rest; its Stewart spring
    gives no impulse) with restitution e: v_c' = v (m_c - e m_a) / (m_c + m_a) towards the
    target, v_a' = v_c' + e v; the six land pairs share the impulse m_a v_a' equally, axially."""
    s = _coaxial(40.0, duration=0.02)
    r = simulate(s, place(s))
    ts = timeseries(r)
    m_c, m_a = s.bodies.chaser.mass, s.bodies.target_apds.mass
    v, e = s.initial.chaser_speed, s.contact.restitution
    t1 = ts["impact_t"][0]
    assert t1 == pytest.approx(s.initial.approach_travel / v, abs=1e-7)
    names = ts["couple_names"]
    hit = names[ts["impact_couples"][0]]
    assert len(hit) == 6 and all(n.startswith("ps_") and "tip" in n for n in hit)
    P = ts["impact_normal_impulse"][0][ts["impact_couples"][0]]
    vc = v * (m_c - e * m_a) / (m_c + m_a)
    va = vc + e * v
    # To the LZB integration's tolerance (its energetic restitution is Newton's in one dimension).
    np.testing.assert_allclose(P, m_a * va / 6, rtol=1e-8)
    after = np.flatnonzero((ts["t"] == t1) & (ts["sample_kind"] == 2))[-1]
    bodies = list(ts["body_names"])
    V = ts["v_WB"][after]
    # The chaser moves along -z of the world towards the target (closed form above).
    assert V[bodies.index("chaser")][2] == pytest.approx(-vc, rel=1e-8)
    assert V[bodies.index("target_apds")][2] == pytest.approx(-va, rel=1e-8)
    assert np.abs(V[:, :2]).max() < 1e-12 and np.abs(ts["w_WB"][after]).max() < 1e-12


@pytest.mark.parametrize("yaw", [-45.0, 59.9])
def test_a_coaxial_tip_on_tip_run_ends_in_a_named_outcome(yaw):
    """The run ends jammed (the chaser held on the tips, no progress for jam_time): the ring
    distance never falls below 2H (the tips cannot pass while coaxial; less the witness
    window), neither independent check finds interpenetration, momentum and the energy ledger
    close."""
    s = _coaxial(yaw, duration=3.0, jam_time=0.5)
    r = simulate(s, place(s))
    ts = timeseries(r)
    sm = summary(r, ts)
    assert sm["outcome"] == "jammed"
    # Less the overlap an impact is found at: the witness isolation window (1e-2 accuracy s)
    # times the closing speed.
    window = 1e-2 * s.simulator_config.accuracy * s.initial.chaser_speed
    assert ts["ring_distance"].min() >= 2 * s.geometry.H - window
    for check in (deepest_penetration, deepest_penetration_mesh):
        pen = check(s.geometry, ts["t"], ts["R_WA"], ts["p_WA"], ts["apds_names"].tolist())
        assert pen.depth == 0.0, pen.describe()
    assert sm["momentum_drift_relative"]["linear"] < 1e-9
    assert sm["energy_ledger"]["closure_error_relative"] < 1e-6
