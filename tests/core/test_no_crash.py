"""Seeking and tracking never crash (docs/model.md, "Degenerate couples").

Every pair type of the docking scene (`apds_pairs`: guide side against guide side, ring circle
against guide surface) and of the small scenes (segment against segment, circle against plane,
circle against cone) is driven through seeded random poses and degenerate ones (a ring coaxial
with a cone, parallel curves, couples at domain ends and corners, parameters far outside their
domains) through the seek (Sect. 5.1), its contact-form finish, the couple evaluation and the
tracking rate (Eq. 47). Only drake_dock's typed errors may be raised. A couple that is returned
lies inside its domain; a usable one solves the contact form (Eq. 37-38), recomputed here; a
rate that is returned solves J u' = -dF/dt with dF/dt taken by central differences along the
motion.
"""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from drake_dock.core.couple import closest_point_conditions, evaluate_couple
from drake_dock.core.kernels.jets import jet, patch_spec, position
from drake_dock.core.patches import Circle, Cone, PlaneRect, Segment, posed
from drake_dock.core.seeking import contact_couple, seek_couple
from drake_dock.core.couple_rate import couple_rate
from drake_dock.docking.geometry.apds import apds_patches
from drake_dock.docking.geometry.pairs import R_MATCHED
from drake_dock.docking.geometry.rotations import rot_vec, rot_x, rot_z
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.scenario.dimensions import ApdsGeometry
from drake_dock.errors import DrakeDockError, SingularCoupleError

COND_MIN = 1e-6          # the contact system's default conditioning_min
G = ApdsGeometry()
PAIRS = DockingScene(G, "paper").pairs
# Every C-C, C-S and point-surface pair of the complete set (the point-curve corners:
# tests/core/test_point_curve.py).
COMPLETE = [p for p in DockingScene(G, "complete").pairs if p.kind != "PC"]
TARGET = (np.eye(3), np.zeros(3))


def _in_domain(patch, u):
    u = np.asarray(u, dtype=float)
    bounded = ~np.array(patch.periodic, dtype=bool)
    return bool(np.all(np.isfinite(u))
                and np.all((u >= patch.lower) | ~bounded) and np.all((u <= patch.upper) | ~bounded))


def _moved(X, twist, t):
    """The pose X = (R, p) after time t of the rigid motion with world twist (w, v), v the
    velocity of the frame origin."""
    (R, p), (w, v) = X, twist
    return rot_vec(np.asarray(w) * t) @ R, p + np.asarray(v) * t


def _check_rate(kind, p1, X1, V1, p2, X2, V2, u):
    """Eq. (47) at u, or `SingularCoupleError` where J is singular; returns True if a rate
    was returned (and checked against central differences of F along the motion)."""
    P1, P2 = posed(p1, *X1), posed(p2, *X2)
    n1 = p1.dim
    try:
        udot = couple_rate(P1, P2, u[:n1], u[n1:], V1, V2, kind=kind, name="pair", time=0.5)
    except SingularCoupleError as e:
        assert "pair" in str(e) and "t = 0.5" in str(e)
        _, _, cond = closest_point_conditions(kind, p1, X1, p2, X2, u, conditioning=True)
        assert cond <= 1e-10
        return False
    assert np.all(np.isfinite(udot))
    h = 1e-6
    Fp, _ = closest_point_conditions(kind, p1, _moved(X1, V1, h), p2, _moved(X2, V2, h), u)
    Fm, _ = closest_point_conditions(kind, p1, _moved(X1, V1, -h), p2, _moved(X2, V2, -h), u)
    Ft = (Fp - Fm) / (2 * h)
    _, Fu = closest_point_conditions(kind, p1, X1, p2, X2, u)
    scale = np.abs(Ft).max() + np.abs(Fu).max() * np.abs(udot).max() + 1e-12
    np.testing.assert_allclose(Fu @ udot, -Ft, rtol=0, atol=1e-6 * scale)
    return True


def _outside(patch, rng, k=3):
    """Parameters beyond the domain: up to ten spans out, and at the far ends of the formulas
    (a guide surface's zeta at and beyond where Eq. 13 has no solution, a guide side's theta
    where its sine form divides by zero)."""
    lo, hi, span = patch.lower, patch.upper, patch.span
    out = [lo - span * rng.uniform(0.0, 10.0, patch.dim) for _ in range(k)]
    out += [hi + span * rng.uniform(0.0, 10.0, patch.dim) for _ in range(k)]
    out += [lo - 0.5 * span, hi + 0.5 * span, hi + 1.5 * span, lo - 1.5 * span]
    return out


def exercise(kind, p1, X1, p2, X2, rng):
    """The seek, its finish, the evaluation at the couple and at parameters outside the
    domains, and the tracking rate, for one pose; returns the `ContactCouple` (None if the
    seek raised its typed error)."""
    V1 = (rng.normal(0, 0.5, 3), rng.normal(0, 0.5, 3))
    V2 = (rng.normal(0, 0.5, 3), rng.normal(0, 0.5, 3))
    try:
        c = seek_couple(posed(p1, *X1), posed(p2, *X2), distance_rtol=1e-7, rtol_beyond=0.02)
    except DrakeDockError:
        return None
    assert _in_domain(p1, c.u1) and _in_domain(p2, c.u2)
    assert c.distance == pytest.approx(np.linalg.norm(posed(p1, *X1).position(c.u1)
                                                      - posed(p2, *X2).position(c.u2)),
                                       rel=1e-12, abs=1e-15)
    f = contact_couple(kind, p1, X1, p2, X2, c, conditioning_min=COND_MIN)
    n1 = p1.dim
    if f.usable:
        assert np.all(p1.margin(f.u[:n1]) > 0) and np.all(p2.margin(f.u[n1:]) > 0)
        F, Fu = closest_point_conditions(kind, p1, X1, p2, X2, f.u)
        assert np.abs(F).max() <= 1e-12 * (1.0 + np.abs(Fu).max())
        _check_rate(kind, p1, X1, V1, p2, X2, V2, f.u)
    else:
        assert f.reason and np.array_equal(f.u, c.u)
    # Drift-corrected evaluation at the couple and far outside both domains: finite, no error.
    samples = [f.u] + [np.concatenate([a, f.u[n1:]]) for a in _outside(p1, rng)] \
        + [np.concatenate([f.u[:n1], b]) for b in _outside(p2, rng)]
    for u in samples:
        ev = evaluate_couple(kind, p1, X1, V1, p2, X2, V2, u, 1.0)
        values = [ev.u, ev.udot, ev.p1, ev.p2, ev.n, ev.ta, ev.tb, ev.v_rel, ev.vt, ev.bias_t,
                  [ev.gap, ev.vn, ev.bias_n, ev.conditioning, ev.residual]]
        assert all(np.all(np.isfinite(x)) for x in values), u
    return f


# ------------------------------------------------------------------------ poses of the scene
def chaser_pose(rng, tilt_deg=10.0, lateral=0.2, heights=(-0.05, 0.45)):
    """A random chaser APDS pose in the target APDS frame: rolled about the axis by up to
    15 deg from the matched facing (one pose in three: any roll), tilted by up to
    ``tilt_deg``, its ring centre up to ``lateral`` off the axis and between ``heights``."""
    tilt = np.radians(rng.uniform(-tilt_deg, tilt_deg, 2))
    roll = rng.uniform(0, 2 * np.pi) if rng.uniform() < 1 / 3 else np.radians(
        rng.uniform(-15.0, 15.0))
    R = rot_vec([*tilt, 0.0]) @ rot_z(roll) @ R_MATCHED
    return R, np.array([*rng.uniform(-lateral, lateral, 2), rng.uniform(*heights)])


def _unit(a):
    return a / np.linalg.norm(a)


def near_contact_pose(kind, p1, p2, rng, gap):
    """A pose of body 1 (body 2 at the origin) at which the interior couple u = (u1, u2) drawn
    at random solves the contact form with the gap ``gap``: the points are ``gap`` apart along
    a normal n of patch 2 (C-S, P-S) or of both tangents (C-C), and the curve's tangent is
    turned into the plane normal to n (a point, P-S, is turned at random). Returns (X1, u)."""
    u1 = p1.lower + p1.span * rng.uniform(0.05, 0.95, p1.dim)
    u2 = p2.lower + p2.span * rng.uniform(0.05, 0.95, p2.dim)
    T2 = p2.first(u2)
    if kind in ("CS", "PS"):
        n = _unit(np.cross(T2[:, 0], T2[:, 1]))
    else:
        n = _unit(np.cross(T2[:, 0], rng.normal(size=3)))
    R0 = rot_vec(rng.normal(0, 2.0, 3))
    if kind == "PS":                 # a point: any orientation
        return (R0, p2.position(u2) + gap * n - R0 @ p1.position(u1)), np.concatenate([u1, u2])
    t = _unit(R0 @ p1.first(u1)[:, 0])
    want = _unit(t - (t @ n) * n)
    axis = np.cross(t, want)
    R = rot_vec(_unit(axis) * math.atan2(np.linalg.norm(axis), t @ want)) @ R0
    p = p2.position(u2) + gap * n - R @ p1.position(u1)
    return (R, p), np.concatenate([u1, u2])


def _scene_poses(pair, X_chaser):
    poses = {"target_apds": TARGET, "chaser_apds": X_chaser}
    return poses[pair.body1], poses[pair.body2]


@pytest.mark.parametrize("pair", COMPLETE, ids=[p.name for p in COMPLETE])
def test_scene_pairs_random_poses(pair):
    """Random chaser poses about the docking axis (mostly couples at domain ends, far or
    intersecting), and random near-contact poses (gaps 0-5 mm, some touching exactly)."""
    rng = np.random.default_rng(sum(map(ord, pair.name)))
    for _ in range(10):
        X1, X2 = _scene_poses(pair, chaser_pose(rng))
        exercise(pair.kind, pair.patch1, X1, pair.patch2, X2, rng)
    _near_contact_sweep(pair.kind, pair.patch1, pair.patch2, rng)


def _near_contact_sweep(kind, p1, p2, rng, n=10):
    """Near-contact poses; the sweep must reach usable couples (else it would test only the
    refusals)."""
    usable = 0
    for k in range(n):
        X1, _ = near_contact_pose(kind, p1, p2, rng, 0.0 if k % 3 == 0 else rng.uniform(0, 5e-3))
        f = exercise(kind, p1, X1, p2, TARGET, rng)
        usable += f is not None and f.usable
    assert usable > 0


@pytest.mark.parametrize("h", [0.1, 0.15, G.H, 0.25, 0.4])
def test_ring_coaxial_with_guide_surface(h):
    """A ring coaxial with the petals at ring-face distance h: every point of the ring is as
    near the cone as any other, so the couple is not isolated and not usable. Below h = H the
    distance is the closed form (R - h cot(alpha1) - Rs) sin(alpha1); at and above it the
    nearest points are on the tip arcs, a domain end."""
    rng = np.random.default_rng(int(100 * h))
    X_chaser = (rot_z(math.radians(5.0)) @ R_MATCHED, np.array([0.0, 0.0, h]))
    for pair in (p for p in PAIRS if p.body1 == "chaser_apds" and p.kind == "CS"):
        X1, X2 = _scene_poses(pair, X_chaser)
        f = exercise(pair.kind, pair.patch1, X1, pair.patch2, X2, rng)
        assert not f.usable
        if h < G.H:
            assert "not isolated" in f.reason
            c = seek_couple(posed(pair.patch1, *X1), posed(pair.patch2, *X2))
            want = (G.R - h / math.tan(G.alpha1) - G.Rs) * math.sin(G.alpha1)
            assert c.distance == pytest.approx(want, rel=1e-9)


def _circle_to_arc(circle, X1, arc, n=200001):
    """Least distance of the posed circle X1 = (R, p) (`Circle`: radius, height) to the arc
    (in the target frame) by the point-to-circle closed form at n points of the arc and its
    ends."""
    R, p = X1
    nrm = R[:, 2]
    centre = p + circle.height * nrm
    q = arc.position(np.linspace(arc.lower, arc.upper, n).reshape(-1, 1)) - centre
    axial = q @ nrm
    radial = np.linalg.norm(q - axial[:, None] * nrm, axis=1) - circle.radius
    return float(np.sqrt(axial ** 2 + radial ** 2).min())


TIP_PAIRS = {int(p.name[-1]): p for p in COMPLETE if p.name.startswith("cc_Cring_Ttip")}
SURFACE_PAIRS = {int(p.name[-1]): p for p in COMPLETE if p.name.startswith("cs_Cring_T")}


@pytest.mark.parametrize("gap", [0.0196, 1e-3, 1e-5])
def test_ring_nearly_coaxial_over_tip_arcs(gap):
    """A ring's inside circle over the other APDS's tip arcs, of the same radius (Rs = R -
    H cot(alpha1)), coaxial to 0-1e-6 rad: a valley of couples at nearly one distance, whose
    bottom is at an arc end (a tilt of 2e-10 rad at 19.6 mm made the Newton creep along it,
    50 iterations short of the end). The seek converges to the closed-form distance, against
    the tip arc and against the guide surface it bounds (nearest at its tip arc: the cone
    falls away below it)."""
    rng = np.random.default_rng(int(gap * 1e6))
    yaw = math.radians(36.5)
    for tilt in (0.0, 1e-12, 1e-11, 1e-10, 2e-10, 1e-9, 1e-8, 1e-6):
        axis = rng.normal(size=3) * [1.0, 1.0, 0.0]
        R = rot_vec(tilt * axis / np.linalg.norm(axis)) @ rot_z(-yaw) @ R_MATCHED
        X_chaser = (R, np.array([*rng.normal(0.0, 1e-10, 2), G.H + gap]))
        for k in (1, 2, 3):
            arc = TIP_PAIRS[k].patch2
            for pair in (TIP_PAIRS[k], SURFACE_PAIRS[k]):
                X1, X2 = _scene_poses(pair, X_chaser)
                want = _circle_to_arc(pair.patch1, X1, arc)
                P1, P2 = posed(pair.patch1, *X1), posed(pair.patch2, *X2)
                assert seek_couple(P1, P2).distance == pytest.approx(want, abs=1e-12)


def _plane_normal(curve):
    pts = curve.position(np.linspace(curve.lower, curve.upper, 3))
    nrm = np.cross(pts[1] - pts[0], pts[2] - pts[0])
    return nrm / np.linalg.norm(nrm)


@pytest.mark.parametrize("i", range(1, 7))
def test_parallel_guide_sides(i):
    """A guide side against its own copy moved along the normal of its (planar) auxiliary
    plane: every couple (u, u) is at the same distance, J is singular (Eq. 39 fails)."""
    rng = np.random.default_rng(i)
    side = apds_patches(G).sides[i]
    nrm = _plane_normal(side)
    u = side.lower + side.span * rng.uniform(0.2, 0.8, 1)
    assert abs(nrm @ side.first(u)[:, 0]) < 1e-12          # the side lies in the plane
    X1 = (np.eye(3), 1e-3 * nrm)
    f = exercise("CC", side, X1, side, TARGET, rng)
    assert f is None or not f.usable
    assert not _check_rate("CC", side, X1, (np.zeros(3), np.zeros(3)), side, TARGET,
                           (np.zeros(3), [0.0, 0.0, 0.1]), np.concatenate([u, u]))


def test_ring_at_petal_tip_corners():
    """The ring circle passing within 0-1 mm of a petal's tip corner (s, zeta) = (0 or 1, H)
    in random directions: where a ring-surface contact hands over to an edge."""
    rng = np.random.default_rng(11)
    P = apds_patches(G)
    for _ in range(16):
        k, s = int(rng.integers(1, 4)), float(rng.integers(0, 2))
        surf = P.surfaces[k]
        corner = surf.position([s, G.H])
        R = rot_vec(rng.normal(0, 1.0, 3))
        th = rng.uniform(0, 2 * np.pi)
        offset = rng.normal(0, 1, 3)
        p = corner + 1e-3 * rng.uniform() * offset / np.linalg.norm(offset) \
            - R @ P.ring.position([th])
        exercise("CS", P.ring, (R, p), surf, TARGET, rng)


def test_guide_side_ends_meet():
    """Two guide sides whose tip ends (or start ends) meet: couples at domain corners."""
    rng = np.random.default_rng(12)
    P = apds_patches(G)
    for _ in range(16):
        i, j = (int(a) for a in rng.integers(1, 7, 2))
        a, b = P.sides[j], P.sides[i]
        ua = a.lower if rng.uniform() < 0.5 else a.upper
        ub = b.lower if rng.uniform() < 0.5 else b.upper
        R = rot_vec(rng.normal(0, 1.0, 3))
        p = b.position(ub) - R @ a.position(ua) + rng.normal(0, 1e-4, 3)
        exercise("CC", a, (R, p), b, TARGET, rng)


FAILED = Path(__file__).with_name("failed_seeks.json")


@pytest.mark.parametrize("case", json.loads(FAILED.read_text()), ids=lambda c: c["pair"])
def test_seeks_that_crashed(case):
    """The poses at which the ring-surface seek of the docking runs used to crash (a Newton
    finish taken far outside the domain; a singular J): the ring's circle passes through the
    petal. The seek's couple is at zero distance with the circle crossing the surface (points
    just before and after it lie on opposite sides of the tangent plane); the finish refuses."""
    pair = next(p for p in PAIRS if p.name == case["pair"])
    X1, X2 = ((np.array(R), np.array(p)) for R, p in (case["X1"], case["X2"]))
    f = exercise(pair.kind, pair.patch1, X1, pair.patch2, X2, np.random.default_rng(3))
    c = seek_couple(posed(pair.patch1, *X1), posed(pair.patch2, *X2), distance_rtol=1e-7,
                    rtol_beyond=0.02)
    assert not f.usable and f.finish_failed and c.distance < 1e-12
    P1, P2 = posed(pair.patch1, *X1), posed(pair.patch2, *X2)
    T = P2.first(c.u2)
    nrm = np.cross(T[:, 0], T[:, 1])
    sides = [nrm @ (P1.position(c.u1 + e) - P2.position(c.u2)) for e in (-1e-3, 1e-3)]
    assert sides[0] * sides[1] < 0


# The chaser ring against the T1 guide surface in the run of IDSS campaign sample 397
# (models/idss_envelope.yaml) at t = 0.479 s: body poses (R, p) of the two APDS.
CREEPING_X1 = ([[-0.4986210713425131, -0.8645174209558701, -0.06313997210210891],
                [-0.8619619624733339, 0.5022104665345811, -0.06932692516069916],
                [0.09164388938910882, 0.019856388567135303, -0.9955938536224034]],
               [-0.01566205985912082, 0.013665294832705616, 5.2281343022534426])
CREEPING_X2 = ([[0.9994844617295722, 0.028793339321968578, 0.014204026606468355],
                [-0.028922747571869523, 0.9995412136520327, 0.008990933428473853],
                [-0.013938630995947865, -0.00939711773424761, 0.9998586943884857]],
               [-0.02190690230232254, -0.010293806935701498, 5.011666244594425])


def test_seek_creeping_to_a_near_tangent_crossing():
    """The ring's circle cuts the guide surface next to its edge while nearly osculating it
    (J's smallest singular value 3e-6 of its largest): every Newton start creeps along the
    valley for about 90 iterations before it converges (more than a limit of 50). The seek
    finds a crossing: distance below 1e-12, the circle's points on either side of the couple
    on opposite sides of the surface's tangent plane."""
    pair = next(p for p in PAIRS if p.name == "cs_Cring_T1")
    X1, X2 = ((np.array(R), np.array(p)) for R, p in (CREEPING_X1, CREEPING_X2))
    P1, P2 = posed(pair.patch1, *X1), posed(pair.patch2, *X2)
    c = seek_couple(P1, P2, distance_rtol=1e-7, rtol_beyond=0.02)
    assert c.distance < 1e-12
    T = P2.first(c.u2)
    nrm = np.cross(T[:, 0], T[:, 1])
    sides = [nrm @ (P1.position(c.u1 + e) - P2.position(c.u2)) for e in (-1e-6, 1e-6)]
    assert sides[0] * sides[1] < 0


# ------------------------------------------------------------------- small scenes' patch types
def _random_rotation(rng):
    return rot_vec(rng.normal(0, 2.0, 3))


SMALL = {
    "segment_segment": ("CC", Segment([0.0, -1.0, 0.0], [0.0, 1.0, 0.0]),
                        Segment([-2.0, 0.0, 0.0], [2.0, 0.0, 0.0])),
    "circle_plane": ("CS", Circle(0.3), PlaneRect([-1.0, -1.0, 0.0], [1.0, 0.0, 0.0],
                                                  [0.0, 1.0, 0.0], size=(2.0, 2.0))),
    "circle_cone": ("CS", Circle(0.4), Cone(0.6, math.radians(45), (0.0, 2.0), (0.0, 0.2))),
}


@pytest.mark.parametrize("name", SMALL)
def test_small_scene_pairs_random_poses(name):
    kind, a, b = SMALL[name]
    rng = np.random.default_rng(sum(map(ord, name)))
    for _ in range(10):
        exercise(kind, a, (_random_rotation(rng), rng.uniform(-0.6, 0.6, 3)), b, TARGET, rng)
    _near_contact_sweep(kind, a, b, rng)


def test_small_scene_degenerate_poses():
    """Parallel segments, a hoop lying flat on the plane, a hoop coaxial with the cone, a hoop
    at the plane's corner and a segment end on a segment end: no error, and the couples that
    are not isolated (every rotation of the hoop, every shift along the segments, is as near)
    are not usable."""
    rng = np.random.default_rng(5)
    seg, edge = SMALL["segment_segment"][1:]
    hoop, plane = SMALL["circle_plane"][1:]
    ring, cone = SMALL["circle_cone"][1:]
    flat = [("CC", seg, (rot_z(np.pi / 2), np.array([0.0, 0.0, 0.05])), edge),
            ("CS", hoop, (np.eye(3), np.array([0.0, 0.0, 0.02])), plane),
            ("CS", ring, (np.eye(3), np.array([0.0, 0.0, 0.1])), cone)]
    for kind, a, X1, b in flat:
        f = exercise(kind, a, X1, b, TARGET, rng)
        assert f is None or not f.usable
    corners = [("CS", hoop, (rot_x(np.pi / 2), np.array([-1.0, -1.0, 0.3 + 1e-4])), plane),
               ("CC", seg, (rot_z(0.3), np.array([2.0, -1.0, 1e-4])), edge)]
    for kind, a, X1, b in corners:
        exercise(kind, a, X1, b, TARGET, rng)


def test_finish_at_round_off_far_from_the_origin():
    """A hoop resting on a large plane 50 m from the plane's origin: |F| stalls at its
    round-off above the 1e-15 test, the steps vanish, and the couple is usable at the hoop's
    lowest point (theta = 3 pi / 2 in its vertical plane)."""
    hoop = Circle(0.05)
    plane = PlaneRect([-50.0, -50.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], size=(100., 100.))
    rng = np.random.default_rng(9)
    for a in rng.uniform(0, 2 * np.pi, 4):
        X1 = (rot_z(a) @ rot_x(np.pi / 2), np.array([0.25 * np.cos(a), 0.25 * np.sin(a),
                                                      0.05 + 1e-10]))
        f = exercise("CS", hoop, X1, plane, TARGET, rng)
        assert f.usable
        assert f.u[0] == pytest.approx(1.5 * np.pi, abs=1e-7)
        np.testing.assert_allclose(f.u[1:] - 50.0, X1[1][:2], atol=1e-9)


def _kernel_jet(patch, u):
    """(r, T, K) of the compiled jet (`drake_dock.core.kernels.jets`) in the form of
    `Patch.jet`."""
    kind, prm = patch_spec(patch)
    r, t0, t1, k00, k01, k11 = jet(kind, prm, u[0], u[1] if patch.dim == 2 else 0.0)
    if patch.dim == 1:
        return r, (t0,), ((k00,),)
    return r, (t0, t1), ((k00, k01), (k01, k11))


def _kernel_position(patch, u):
    kind, prm = patch_spec(patch)
    return np.array(position(kind, prm, u[0], u[1] if patch.dim == 2 else 0.0))


@pytest.mark.parametrize("compiled", [False, True], ids=["patch", "kernel"])
def test_patch_continuation_beyond_the_domain(compiled):
    """Beyond their reach the guide surface holds theta_1 and the guide side holds rho, in the
    patches and in the compiled jets alike: values continuous across the reach, finite
    everywhere, and the derivatives there those of the held curve (central differences)."""
    P = apds_patches(G)
    surf, side = P.surfaces[1], P.sides[2]
    jet_of = _kernel_jet if compiled else (lambda patch, u: patch.jet(u))
    pos = _kernel_position if compiled else (lambda patch, u: patch.position(u))
    lo, hi = surf.phi.z_reach
    for z in (lo, hi):
        a, b = pos(surf, [0.3, z - 1e-9]), pos(surf, [0.3, z + 1e-9])
        assert np.linalg.norm(a - b) < 1e-8
    for s in ([0.3, hi + 0.05], [0.7, lo - 0.3], [-2.0, 0.3], [0.5, 0.6], [3.0, 50.0]):
        r, T, K = jet_of(surf, s)
        assert np.all(np.isfinite(r)) and np.all(np.isfinite(T)) and np.all(np.isfinite(K))
        np.testing.assert_allclose(r, surf.position(s), atol=1e-15)
        h = 1e-6
        for k in range(2):
            e = np.eye(2)[k] * h
            fd = (pos(surf, np.add(s, e)) - pos(surf, np.subtract(s, e))) / (2 * h)
            np.testing.assert_allclose(T[k], fd, atol=1e-6)
    # Side 2 (sigma = -1): w = alpha2 - (theta - pi/3) reaches 0 at theta = pi/3 + alpha2.
    for th in (math.pi / 3 + G.alpha2, math.pi / 3 + G.alpha2 + 0.1, math.pi / 3 - 2.0, -40.0):
        r, T, K = jet_of(side, [th])
        assert np.all(np.isfinite(r)) and np.all(np.isfinite(T)) and np.all(np.isfinite(K))
        np.testing.assert_allclose(r, side.position([th]), atol=1e-15)
        fd = (pos(side, [th + 1e-6]) - pos(side, [th - 1e-6])) / 2e-6
        np.testing.assert_allclose(T[0], fd, atol=1e-6)
