"""The edge and face pairs (`contact.pairs: complete`) in closed form (tests/edge_scenes.py): a
ring's circle over a straight edge and over a tip arc, a straight edge over a skew straight edge
and over an arc (C-C: a guide side against another side or a tip arc), a tilted rim over a ring
face (C-S), a tip arc over a guide-surface cone (C-S) and the hand-over at a petal-like tip,
tracked by Eq. (47) through prescribed motions to 1e-8; the couple's projection, frame, both
orientations, relative velocity and Eq. (52) terms against the closed form and its differences
along the motion."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from drake_dock.core.couple import evaluate_couple
from drake_dock.core.kernels.jets import jet, patch_spec
from drake_dock.core.patches import posed
from drake_dock.core.seeking import contact_couple, seek_couple
from drake_dock.docking.geometry.apds import apds_patches, corner_point
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.scenario.dimensions import ApdsGeometry
from motions import PosedMotion, check_rates_by_finite_differences
from edge_scenes import (CORNER, arc_over_cone, rim_over_face, ring_over_arc, ring_over_segment,
                         segment_over_arc, segment_over_segment, tip_handover)

SCENES = {"ring_over_segment": ring_over_segment, "ring_over_arc": ring_over_arc,
          "segment_over_segment": segment_over_segment, "segment_over_arc": segment_over_arc,
          "rim_over_face": rim_over_face, "arc_over_cone": arc_over_cone}
TIMES = np.linspace(0.0, 1.0, 11)


def _wrap(du, scene):
    """Parameter differences with the periodic ones taken modulo 2 pi."""
    per = list(scene.patch1.periodic) + list(scene.patch2.periodic)
    return np.array([(d + math.pi) % (2 * math.pi) - math.pi if p else d
                     for d, p in zip(du, per)])


def _evaluate(scene, t, u, sigma=1.0, project=True):
    X1, V1, X2, V2 = scene.poses(t)
    return evaluate_couple(scene.kind, scene.patch1, X1, V1, scene.patch2, X2, V2, u, sigma,
                           project=project)


def _track(scene, t_span, u0, events=None):
    def rhs(t, u):
        return _evaluate(scene, t, u, project=False).udot

    ts = [t for t in TIMES if t_span[0] <= t <= t_span[1]]
    sol = solve_ivp(rhs, t_span, u0, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=ts,
                    events=events)
    assert sol.success
    return sol


@pytest.mark.parametrize("name", SCENES)
def test_seek_finds_the_closed_form_couple(name):
    """At t = 0 the seek finds the closed-form couple, interior, and the
    contact-form finish keeps it (a ring over a straight edge crosses it twice at the same
    distance: either couple)."""
    s = SCENES[name]()
    exact = [s.exact(0.0, b) for b in s.branches]
    X1, _, X2, _ = s.poses(0.0)
    P1, P2 = posed(s.patch1, *X1), posed(s.patch2, *X2)
    c = seek_couple(P1, P2)
    assert c.interior
    u, gap = min(exact, key=lambda e: np.abs(_wrap(c.u - e[0], s)).max())[:2]
    assert c.distance == pytest.approx(gap, abs=1e-12)
    np.testing.assert_allclose(_wrap(c.u - u, s), 0.0, atol=1e-8)
    cc = contact_couple(s.kind, s.patch1, X1, s.patch2, X2, c, conditioning_min=1e-10)
    assert cc.usable
    np.testing.assert_allclose(_wrap(cc.u - u, s), 0.0, atol=1e-12)


@pytest.mark.parametrize("name", SCENES)
def test_eq47_tracks_the_closed_form_couple(name):
    """u* integrated by Eq. (47) over 1 s equals the closed-form couple to 1e-8; the gap, the
    points and the normal (+z of Body 2, from Body 2 to Body 1) to 1e-10 once projected, and
    the normal velocity equals the rate of the closed-form gap. sigma is fixed at t = 0 by the
    side Body 1 lies on (docs/model.md, "Signed gap")."""
    s = SCENES[name]()
    u0 = s.exact(0.0)[0]
    sigma = float(np.sign(_evaluate(s, 0.0, u0).gap))
    sol = _track(s, (0.0, 1.0), u0)
    errors = []
    for k, t in enumerate(sol.t):
        u, gap, p1, p2, n = s.exact(t)
        errors.append(np.abs(_wrap(sol.y[:, k] - u, s)).max())
        ev = _evaluate(s, t, sol.y[:, k], sigma)
        assert ev.gap == pytest.approx(gap, abs=1e-10)
        np.testing.assert_allclose(ev.p1, p1, atol=1e-10)
        np.testing.assert_allclose(ev.p2, p2, atol=1e-10)
        np.testing.assert_allclose(ev.n, n, atol=1e-10)
        h = 1e-6
        rate = (s.exact(t + h)[1] - s.exact(t - h)[1]) / (2 * h)
        assert ev.vn == pytest.approx(rate, abs=1e-8)
    assert max(errors) < 1e-8
    print(f"{name}: max |u* - u_exact| = {max(errors):.2e}")


def test_handover_at_the_tip_corner():
    """The ring's crossing runs up the straight side to the corner Q and on along the tip arc.
    The side's couple reaches its domain end u2 = 1 at the closed-form time t_h (|Q - c| = r)
    by Eq. (47), where the arc's couple starts at its first end; the gap is continuous (both
    equal the ring's height) and the normal is +z on both with the orientation
    sigma = sign((t1 x t2) . z) of each pair, which the corner leaves unchanged (the edge
    turns by less than the crossing angle)."""
    side, arc, t_h = tip_handover()
    end = lambda t, u: u[1] - 1.0
    end.terminal = True
    sol = _track(side, (0.0, 1.0), side.exact(0.0)[0], events=end)
    assert sol.t_events[0][0] == pytest.approx(t_h, abs=1e-8)
    for k, t in enumerate(sol.t):
        np.testing.assert_allclose(_wrap(sol.y[:, k] - side.exact(t)[0], side), 0, atol=1e-8)
    u_side = sol.y_events[0][0]
    u_arc = arc.exact(t_h)[0]
    assert u_arc[1] == pytest.approx(arc.patch2.lower[0], abs=1e-12)
    np.testing.assert_allclose(arc.patch2.position(u_arc[1:]), CORNER, atol=1e-12)
    sigmas = []
    for s, u in ((side, u_side), (arc, u_arc)):
        raw = _evaluate(s, t_h, u, project=False)
        sigmas.append(float(np.sign(raw.n[2])))
        ev = _evaluate(s, t_h, u, sigmas[-1], project=False)
        assert ev.gap == pytest.approx(side.c[2](t_h), abs=1e-8)
        np.testing.assert_allclose(ev.n, [0, 0, 1], atol=1e-8)
    t1 = side.patch1.first(u_side[:1])[:, 0]
    assert sigmas == [float(np.sign(np.cross(t1, side.patch2.b - side.patch2.a)[2])),
                      float(np.sign(np.cross(t1, [-math.sin(0.3), math.cos(0.3), 0.0])[2]))]
    sol = _track(arc, (t_h, 1.0), u_arc)
    for k, t in enumerate(sol.t):
        np.testing.assert_allclose(_wrap(sol.y[:, k] - arc.exact(t)[0], arc), 0, atol=1e-8)


@pytest.mark.parametrize("name", SCENES)
def test_projection_frame_and_rates_against_the_closed_form(name):
    """From the closed-form couple 1e-3 off, one projection lands within 5e-5 of it and a second
    within 1e-8 (Newton: quadratic), drift = u - u_state; at the couple both orientations give the closed-form gap
    and normal (negated with sigma), an orthonormal right-handed frame with ta along patch 2's
    tangent, the material points' relative velocity (the twists at the points), and u'
    (Eq. 47), g' = v_n, g'' and (t . v_rel)' (Eq. 52; the points' accelerations by differences
    of the poses) equal the differences along the motion of the closed-form couples."""
    s = SCENES[name]()
    rng = np.random.default_rng(3)
    sigma0 = float(np.sign(_evaluate(s, 0.0, s.exact(0.0)[0]).gap))
    for t in (0.1, 0.6):
        X1, V1, X2, V2 = s.poses(t)
        u0, gap, p1, p2, n = s.exact(t)
        du = 1e-3 * rng.normal(size=len(u0))
        ev = _evaluate(s, t, u0 + du, -sigma0)
        np.testing.assert_allclose(_wrap(ev.u - u0, s), 0.0, atol=5e-5)
        np.testing.assert_allclose(ev.drift, ev.u - (u0 + du), atol=1e-15)
        again = _evaluate(s, t, ev.u, -sigma0)
        np.testing.assert_allclose(_wrap(again.u - u0, s), 0.0, atol=1e-8)
        for sigma in (sigma0, -sigma0):
            ev = _evaluate(s, t, u0, sigma)
            assert ev.gap == pytest.approx(sigma * sigma0 * gap, abs=1e-10)
            np.testing.assert_allclose(ev.n, sigma * sigma0 * n, atol=1e-10)
            Rf = ev.frame
            np.testing.assert_allclose(Rf.T @ Rf, np.eye(3), atol=1e-12)
            assert np.linalg.det(Rf) > 0
            T2 = X2[0] @ s.patch2.first(ev.u[s.patch1.dim:])[:, 0]
            np.testing.assert_allclose(ev.ta, T2 / np.linalg.norm(T2), atol=1e-12)
            v_rel = (V1[1] + np.cross(V1[0], ev.p1 - X1[1])
                     - V2[1] - np.cross(V2[0], ev.p2 - X2[1]))
            np.testing.assert_allclose(ev.v_rel, v_rel, atol=1e-12)
    m1 = PosedMotion(lambda t: s.poses(t)[0])
    m2 = PosedMotion(lambda t: s.poses(t)[2])
    check_rates_by_finite_differences(lambda t: _evaluate(s, t, s.exact(t)[0], sigma0), m1, m2,
                                      times=(0.1, 0.6))


def test_complete_set_names_and_patches(geom):
    """`paper` is the 12 pairs; `complete` adds, per APDS, its ring's inside circle against the
    other's 6 sides and 3 tip arcs, its rim against the other's face and its tip arcs against
    the other's guide surfaces they can face (32 pairs), its ring's inside circle against
    the other's 6 petal corners, each the top end of its guide side (12 point-curve pairs),
    the guide sides against the non-partner sides and the tip arcs they can reach (36
    pairs), the chaser's tip arcs against the target's tip arcs they can reach (6 pairs),
    the petal corners against the other's guide surfaces they can reach (24
    point-surface pairs, each corner a bare point), the petal corners against the other's tip
    lands they come over (12 point-surface pairs); no rim on rim (the faces reach past the
    rims)."""
    paper, complete = DockingScene(geom, "paper").pairs, DockingScene(geom, "complete").pairs
    assert [p.name for p in complete[:12]] == [p.name for p in paper] and len(paper) == 12
    new = {p.name: p for p in complete[12:]}
    assert len(new) == len(complete) - 12 == 122
    P = apds_patches(geom)
    for x, y, bx, by in (("C", "T", "chaser_apds", "target_apds"),
                         ("T", "C", "target_apds", "chaser_apds")):
        for i in range(1, 7):
            pc = new[f"pc_{y}corner{i}_{x}ring"]
            assert (pc.kind, pc.body1, pc.body2) == ("PC", by, bx)
            assert (pc.patch2.radius, pc.patch2.height) == (geom.Rs, 0.0)
            side = P.sides[i]
            ends = side.position(np.array([side.lower, side.upper]))
            corner = ends[np.argmax(ends[:, 2])]      # the side's top, on the tip arc
            np.testing.assert_allclose(corner_point(geom, i), corner, atol=1e-15)
            r = pc.patch1.radius
            assert r > 0 and pc.patch1.p[2] == pytest.approx(geom.H, abs=1e-15)
            # The sphere's centre r outward: the sphere passes through the corner, and a
            # coaxial ring circle of radius R - H cot(alpha1) has its centre on the convex side.
            rho = math.hypot(*pc.patch1.p[:2])
            assert rho == pytest.approx(math.hypot(*corner[:2]) + r, abs=1e-15)
            (a, b), (c, d) = pc.patch1.p[:2], corner[:2]
            assert a * d - b * c == pytest.approx(0.0, abs=1e-15)
            for k in (1, 2, 3):
                ps = new.get(f"ps_{y}corner{i}_{x}{k}")
                if ps is not None:
                    assert (ps.kind, ps.body1, ps.body2) == ("PS", by, bx)
                    assert ps.patch1.radius == 0.0
                    np.testing.assert_allclose(ps.patch1.p, corner, atol=1e-15)
                    assert ps.patch2 is P.surfaces[k] or np.array_equal(
                        ps.patch2.position(np.array([0.3, 0.1])),
                        P.surfaces[k].position(np.array([0.3, 0.1])))
    side = new["cc_Cring_T3"]
    assert side.kind == "CC" and type(side.patch2) is type(P.sides[3])
    for patch, expected in ((side.patch2, P.sides[3]), (side.patch1, P.ring)):
        for u in np.linspace(patch.lower, patch.upper, 5):
            assert np.array_equal(patch.position(u), expected.position(u))
    assert new["cc_Tring_Ctip2"].body1 == "target_apds"
    assert new["cs_Crim_Tface"].kind == "CS" and new["cs_Crim_Tface"].body2 == "target_apds"
    face = new["cs_Crim_Tface"]
    assert (face.patch1.radius, face.patch1.height) == (geom.R, 0.0) and face.sigma == 1.0
    # The face's contact annulus reaches past the rim (a rounded edge); no rim-on-rim pair.
    assert face.patch2.lower[0] == geom.Rs and face.patch2.upper[0] > geom.R
    assert not [n for n in new if n.startswith("cc_") and n.count("rim") == 2]
    for name, b1, c1, b2, c2 in (("cc_T4_C1", "chaser_apds", P.sides[1], "target_apds",
                                  P.sides[4]),
                                 ("cc_T2_Ctip3", "target_apds", P.sides[2], "chaser_apds",
                                  P.tips[3])):
        pr = new[name]
        assert (pr.kind, pr.body1, pr.body2) == ("CC", b1, b2)
        for patch, expected in ((pr.patch1, c1), (pr.patch2, c2)):
            u = np.linspace(expected.lower, expected.upper, 5)
            assert np.array_equal(patch.lower, expected.lower)
            assert np.array_equal(patch.position(u), expected.position(u))
    # The tip arc is where the guide surface meets zeta = H, between its two sides' ends.
    for k in (1, 2, 3):
        tip, surf = P.tips[k], P.surfaces[k]
        np.testing.assert_allclose(tip.position(tip.lower), surf.position([0.0, geom.H]),
                                   atol=1e-15)
        np.testing.assert_allclose(tip.position(tip.upper), surf.position([1.0, geom.H]),
                                   atol=1e-15)
    with pytest.raises(ValueError, match="contact.pairs"):
        DockingScene(geom, "all").pairs


def test_tip_arcs_face_the_surfaces_their_pairs_name(geom):
    """A tip arc has a pair with a guide surface of the other APDS exactly when, at some
    relative roll in the scenario's range (-60 to 60 deg), a point of the arc lies over the
    surface's angular span at its base, the widest (Eq. 13): sampled rolls and arc points."""
    from drake_dock.docking.placement.search import coaxial_pose
    P = apds_patches(geom)
    names = {p.name for p in DockingScene(geom, "complete").pairs if p.name.startswith("cs_") and
             "tip" in p.name}
    reach = set()
    for yaw in np.radians(np.linspace(-60.0, 60.0, 241)):
        R = coaxial_pose(yaw, 0.0)[0]               # chaser APDS frame in the target's
        for x, y, turn in (("C", "T", R), ("T", "C", R.T)):
            for j in (1, 2, 3):
                tip = P.tips[j]
                pts = tip.position(np.linspace(tip.lower, tip.upper, 50)) @ turn.T
                az = np.arctan2(pts[:, 1], pts[:, 0])
                for k in (1, 2, 3):
                    lo = (k - 1) * 2 * math.pi / 3
                    if (((az - lo) % (2 * math.pi)) <= math.pi / 3).any():
                        reach.add(f"cs_{x}tip{j}_{y}{k}")
    assert names == reach and len(names) == 12


def test_corners_reach_the_surfaces_their_pairs_name(geom):
    """A petal corner has a point-surface pair with a guide surface of the other APDS exactly
    when, at some relative roll in the scenario's range (-60 to 60 deg), the corner lies over
    the surface's angular span at its base (sampled rolls): a second rule beside the code's
    (the corner's azimuth at the matched facing within 70 deg of the span)."""
    from drake_dock.docking.placement.search import coaxial_pose
    P = apds_patches(geom)
    names = {p.name for p in DockingScene(geom, "complete").pairs if p.kind == "PS"
             and "tip" not in p.name}
    reach = set()
    for yaw in np.radians(np.linspace(-60.0, 60.0, 241)):
        R = coaxial_pose(yaw, 0.0)[0]               # chaser APDS frame in the target's
        for x, y, turn in (("C", "T", R), ("T", "C", R.T)):
            for i in range(1, 7):
                c = turn @ corner_point(geom, i)
                for k in (1, 2, 3):
                    lo = (k - 1) * 2 * math.pi / 3
                    if (math.atan2(c[1], c[0]) - lo) % (2 * math.pi) <= math.pi / 3:
                        reach.add(f"ps_{x}corner{i}_{y}{k}")
    assert names == reach and len(names) == 24


def test_corners_come_over_the_tip_lands_their_pairs_name(geom):
    """A petal corner has a pair with a tip land of the other APDS exactly when, at some
    relative roll strictly inside the scenario's range (sampled rolls, -59.9 to 59.9 deg), the
    corner lies over the tip arc's span: a second rule beside the code's (`LAND_REACH`). Each
    corner comes over one tip, from a roll of 2 theta_end on (closed form)."""
    from drake_dock.docking.placement.search import coaxial_pose
    P = apds_patches(geom)
    names = {p.name for p in DockingScene(geom, "complete").pairs
             if p.kind == "PS" and "tip" in p.name}
    reach, first = set(), {}
    for yaw in np.radians(np.linspace(-59.9, 59.9, 1199)):
        R = coaxial_pose(yaw, 0.0)[0]               # chaser APDS frame in the target's
        for x, y, turn in (("C", "T", R), ("T", "C", R.T)):
            for i in range(1, 7):
                c = turn @ corner_point(geom, i)
                for k in (1, 2, 3):
                    tip = P.tips[k]
                    if ((math.atan2(c[1], c[0]) - tip.lower[0]) % (2 * math.pi)
                            <= tip.upper[0] - tip.lower[0]):
                        name = f"ps_{x}corner{i}_{y}tip{k}"
                        reach.add(name)
                        first[name] = min(first.get(name, np.inf), abs(yaw))
    assert names == reach and len(names) == 12
    np.testing.assert_allclose(list(first.values()), 2 * geom.theta_end, atol=math.radians(0.1))


def _azimuths(curve, R, n=40):
    """The directions about the axis (rad) of n points along a guide side or tip arc turned by
    R."""
    pts = curve.position(np.linspace(curve.lower, curve.upper, n)) @ R.T
    return np.arctan2(pts[:, 1], pts[:, 0])


def test_sides_reach_the_edges_their_pairs_name(geom):
    """A guide side has a pair with a non-partner guide side or a tip arc of the other APDS
    exactly when, at some relative roll in the scenario's range (-60 to 60 deg), a point of the
    one comes within 10 deg of a point of the other about the axis (the margin for tilt and
    offset): sampled rolls and curve points. These are the sides 60 deg from the partner and
    the tip arcs 30 and 90 deg from the side's root."""
    from drake_dock.docking.geometry.pairs import CC_SIDE_PAIRS
    from drake_dock.docking.placement.search import coaxial_pose
    P = apds_patches(geom)
    names = {p.name for p in DockingScene(geom, "complete").pairs[12:]
             if p.name.startswith("cc_") and "ring" not in p.name and "rim" not in p.name
             and not p.name.startswith("cc_Ctip")}
    margin = math.radians(10.0)
    rolls = np.radians(np.linspace(-60.0, 60.0, 241))
    R = {roll: coaxial_pose(roll, 0.0)[0] for roll in rolls}    # the chaser's frame
    near = lambda a, b: bool((np.abs((a[:, None] - b[None, :] + math.pi) % (2 * math.pi)
                                     - math.pi) < margin).any())
    reach = set()
    for roll in rolls:
        az = {("C", "side", j): _azimuths(P.sides[j], R[roll]) for j in range(1, 7)}
        az |= {("T", "side", i): _azimuths(P.sides[i], np.eye(3)) for i in range(1, 7)}
        az |= {("C", "tip", k): _azimuths(P.tips[k], R[roll]) for k in (1, 2, 3)}
        az |= {("T", "tip", k): _azimuths(P.tips[k], np.eye(3)) for k in (1, 2, 3)}
        for i in range(1, 7):
            for j in range(1, 7):
                if (i, j) not in CC_SIDE_PAIRS and near(az["C", "side", j], az["T", "side", i]):
                    reach.add(f"cc_T{i}_C{j}")
        for x, y in (("C", "T"), ("T", "C")):
            for j in range(1, 7):
                for k in (1, 2, 3):
                    if near(az[x, "side", j], az[y, "tip", k]):
                        reach.add(f"cc_{x}{j}_{y}tip{k}")
    assert names == reach and len(names) == 36


def test_the_reach_sweep_finds_no_undeclared_side_pair(geom):
    """Over 2000 seeded random poses (roll -60..60 deg, tilt up to 10 deg, offset up to 0.15 m,
    ring faces -0.2..0.45 m apart; `drake_dock.docking.geometry.reach`), every candidate side pair
    whose closest couple comes interior within 2 cm is declared by `complete`; the declared pairs
    whose azimuth spans come within 50 deg (the sides 60 deg from the partner, the tip arcs 30
    deg from the side's root) are all reached. bench/edge_reach.py runs the sweep at 20000."""
    from drake_dock.docking.geometry.apds import azimuth_span, spans_within
    from drake_dock.docking.geometry.pairs import R_MATCHED
    from drake_dock.docking.geometry.reach import reach_sweep, side_candidates
    declared = {p.name: p for p in DockingScene(geom, "complete").pairs}
    rows = reach_sweep(geom, side_candidates(geom), 2000)
    reached = {k for k, (hits, _, _) in rows.items() if hits}
    assert reached <= set(declared), sorted(reached - set(declared))
    close = set()
    for k in set(rows) & set(declared):
        pr = declared[k]
        turn = {"chaser_apds": R_MATCHED, "target_apds": np.eye(3)}
        if spans_within(azimuth_span(pr.patch1, turn[pr.body1]),
                        azimuth_span(pr.patch2, turn[pr.body2]), math.radians(50.0)):
            close.add(k)
    assert len(close) == 24 and close <= reached, sorted(close - reached)


def _tip_tip_exact(geom, tips, j, k, R, p):
    """The closed-form couples of chaser tip arc j (frame (R, p), level: R e3 = -e3) over
    target tip arc k: both are circles of radius Rs, the target's at z = H about the axis, the
    chaser's at z = p_z - H about (p_x, p_y); their projections cross at ell e +- h e_perp
    (ell = |c| / 2, h = sqrt(Rs^2 - ell^2), c = (p_x, p_y)), where the couple lies, the points
    one above the other, gap p_z - 2H. Returns the interior couples (u, distance)."""
    c = p[:2]
    ell = 0.5 * np.linalg.norm(c)
    e = c / np.linalg.norm(c)
    h = math.sqrt(geom.Rs ** 2 - ell ** 2)
    out = []
    for b in (1.0, -1.0):
        x = ell * e + b * h * np.array([-e[1], e[0]])
        th_t = math.atan2(x[1], x[0])
        q = R.T @ (np.array([x[0], x[1], p[2] - geom.H]) - p)      # in the chaser's frame
        th_c = math.atan2(q[1], q[0])
        u = []
        for th, arc in ((th_c, tips[j]), (th_t, tips[k])):
            th = arc.lower[0] + (th - arc.lower[0]) % (2 * math.pi)
            if th >= arc.upper[0]:
                break
            u.append(th)
        if len(u) == 2:
            out.append((np.array(u), abs(p[2] - 2 * geom.H)))
    return out


def test_tip_tip_pairs_follow_the_closed_form(geom):
    """Each tip-tip pair (C-C, `tip_tip_pairs`) with the chaser level, rolled and offset so
    that its tip arc crosses the target's over both arcs (seeded search): the seek finds the
    closed-form couple and distance to 1e-12, the normal is along the
    axis, and u* integrated by Eq. (47) along a motion (the chaser closing at 0.05 m/s and
    drifting sideways at 0.02 m/s) equals the closed form to 1e-8."""
    from drake_dock.docking.placement.search import coaxial_pose
    P = apds_patches(geom)
    pairs = [p for p in DockingScene(geom, "complete").pairs if p.name.startswith("cc_Ctip")]
    assert len(pairs) == 6
    rng = np.random.default_rng(7)
    for pr in pairs:
        j, k = int(pr.name[7]), int(pr.name[-1])
        while True:
            roll = math.radians(rng.uniform(-60.0, 60.0))
            c0 = rng.uniform(-0.1, 0.1, 2)
            R, _ = coaxial_pose(roll, 0.0)
            pose = lambda t: (R, np.array([c0[0] + 0.02 * t, c0[1], 0.43 - 0.05 * t]))
            if all(len(_tip_tip_exact(geom, P.tips, j, k, *pose(t))) == 1
                   for t in np.linspace(0.0, 0.5, 6)):
                break
        target = (np.eye(3), np.zeros(3))
        (u0, dist), = _tip_tip_exact(geom, P.tips, j, k, *pose(0.0))
        P1, P2 = posed(pr.patch1, *pose(0.0)), posed(pr.patch2, *target)
        c = seek_couple(P1, P2)
        assert c.interior and c.distance == pytest.approx(dist, abs=1e-12), pr.name
        np.testing.assert_allclose(c.u, u0, atol=1e-8)
        twist1 = (np.zeros(3), np.array([0.02, 0.0, -0.05]))
        still = (np.zeros(3), np.zeros(3))
        ev = evaluate_couple("CC", pr.patch1, pose(0.0), twist1, pr.patch2, target, still, u0,
                             1.0)
        np.testing.assert_allclose(np.abs(ev.n), [0.0, 0.0, 1.0], atol=1e-12)
        assert abs(ev.gap) == pytest.approx(dist, abs=1e-12)
        assert ev.vn * np.sign(ev.gap) == pytest.approx(-0.05, abs=1e-12)
        sol = solve_ivp(lambda t, u: evaluate_couple("CC", pr.patch1, pose(t), twist1,
                                                     pr.patch2, target, still, u, 1.0,
                                                     project=False).udot,
                        (0.0, 0.5), u0, method="DOP853", rtol=1e-12, atol=1e-14,
                        t_eval=np.linspace(0.0, 0.5, 6))
        for t, u in zip(sol.t, sol.y.T):
            (want, _), = _tip_tip_exact(geom, P.tips, j, k, *pose(t))
            np.testing.assert_allclose(u, want, atol=1e-8)


def test_declared_handovers_map_each_edge_onto_its_surface(geom):
    """Every hand-over of the complete set (`DockingScene.handovers`, 24): the two pairs are the
    scene's, share Body 1's curve, and along the edge curve (the edge pair's patch 2) the
    surface point at the mapped parameters (`surface_params`) is the edge's point, 21 samples
    to 1e-12 m, and maps back."""
    from drake_dock.core.handover import surface_params
    scene = DockingScene(geom, "complete")
    assert len(scene.handovers) == 24
    for h in scene.handovers:
        e, s, edge = h.edge_pair, h.surface_pair, h.edge
        assert scene.pair(e.name) is e and scene.pair(s.name) is s
        assert (e.kind, s.kind) == ("CC", "CS") and e.patch1 is s.patch1
        assert (e.body1, e.body2) == (s.body1, s.body2)
        E, S = e.patch2, s.patch2
        for t in np.linspace(E.lower[0], E.upper[0], 21):
            a = surface_params(edge, S.lower, S.upper, t)
            np.testing.assert_allclose(S.position(np.array(a)), E.position(np.array([t])),
                                       atol=1e-12)
            assert edge.to_edge(a[edge.free]) == pytest.approx(t, abs=1e-12)
