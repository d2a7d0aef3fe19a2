"""The seek (`drake_dock.core.seeking.seek_couple`, compiled) against references that share
nothing with it: on every pair of the complete set (C-C, C-S, point-curve, point-surface) at
several poses of two geometries (the last overlapping) and on small scenes (segments, a circle
over a plane and a cone), the distance of dense sampling + bounded L-BFGS
(tests/closest_reference.py) and the closest-point conditions at an interior couple (Eq. 22:
d perpendicular to the tangents); on small scenes, the closed-form couples of skew segments, a
tilted circle over a plane and a point over a plane; a patch without kernel description
refused; and a circle piercing a face near its edge taken as a touch at the closed-form
distance."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from closest_reference import brute_force_closest
from drake_dock.core.kernels.seek import CREEP_TOUCH
from drake_dock.core.patches import Circle, Cone, PlaneRect, Point, PolarCurve, Segment, posed
from drake_dock.core.seeking import seek_couple
from drake_dock.docking.geometry.pairs import R_MATCHED
from drake_dock.docking.geometry.rotations import rot_vec, rot_x
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.scenario.dimensions import ApdsGeometry

EYE = (np.eye(3), np.zeros(3))


def _check_couple(P1, P2, c, radius=0.0):
    """The couple's points and distance are the patches' at its parameters; an interior couple
    satisfies the closest-point conditions (d . T = 0 for every tangent, to 1e-7 of |T| |d|:
    the Newton finish stops on the distance, which is stationary there)."""
    np.testing.assert_allclose(c.p1, P1.position(c.u1), atol=1e-12)
    np.testing.assert_allclose(c.p2, P2.position(c.u2), atol=1e-12)
    d = c.p1 - c.p2
    assert c.distance == pytest.approx(np.linalg.norm(d) - radius, abs=1e-13)
    if c.interior:
        T = np.concatenate([P1.first(c.u1), P2.first(c.u2)], axis=1)
        assert np.abs(T.T @ d).max() <= 1e-7 * np.abs(T).max() * np.linalg.norm(d) + 1e-12


@pytest.mark.parametrize("g", [ApdsGeometry(), ApdsGeometry(R=0.9, Rs=0.55, H=0.3,
                                                            alpha1_deg=50.0, alpha2_deg=25.0)])
@pytest.mark.parametrize("d", [0.3, 0.12, 0.02, -0.05])
def test_complete_pairs_against_dense_sampling(g, d):
    """Every pair of the complete set, the chaser tilted, offset and at ring distance d: the
    distance equals that of dense sampling + L-BFGS to 1e-9 m (a point pair's: less the
    point's radius), the couple's points are the patches' and an interior couple solves the
    closest-point conditions."""
    poses = {"target_apds": (np.eye(3), np.zeros(3)),
             "chaser_apds": (rot_vec((0.03, -0.02, 0.01)) @ R_MATCHED,
                             np.array([0.01, -0.005, d]))}
    kinds = set()
    for pr in DockingScene(g, "complete").pairs:
        P1, P2 = posed(pr.patch1, *poses[pr.body1]), posed(pr.patch2, *poses[pr.body2])
        c = seek_couple(P1, P2)
        radius = getattr(pr.patch1, "radius", 0.0) if pr.kind in ("PC", "PS") else 0.0
        _check_couple(P1, P2, c, radius)
        want = np.linalg.norm(brute_force_closest(P1, P2, n_curve=200, n_surf=40)[2]) - radius
        assert c.distance == pytest.approx(want, abs=1e-9), pr.name
        kinds.add(pr.kind)
    assert kinds == {"CC", "CS", "PC", "PS"}


def test_small_scenes_against_dense_sampling():
    """Segments, a circle over a tilted plane and over a cone, at two poses: the distance of
    dense sampling + L-BFGS to 1e-9 m; with the shorter Newton finish of far pairs
    (``distance_rtol``) not below it and within 1e-4 of it."""
    R = rot_vec((0.2, -0.1, 0.4))
    cases = [(Segment((0.0, 0.0, 0.1), (1.0, 0.2, 0.1)), Segment((0.5, -1.0, 0.0),
                                                                (0.4, 1.0, 0.05))),
             (Circle(0.3, 0.1), PlaneRect((-1, -1, 0), (2, 0, 0.1), (0, 2, 0))),
             (Circle(0.2, 0.0), Cone(0.5, 0.9, (0.2, 1.4), (0.0, 0.3)))]
    for c1, c2 in cases:
        for p in ([0.0, 0.0, 0.2], [0.3, -0.1, 0.05]):
            P1, P2 = posed(c1, R, np.array(p)), posed(c2, *EYE)
            want = np.linalg.norm(brute_force_closest(P1, P2, n_curve=300, n_surf=60)[2])
            c = seek_couple(P1, P2)
            _check_couple(P1, P2, c)
            assert c.distance == pytest.approx(want, abs=1e-9), (type(c2).__name__, p)
            far = seek_couple(P1, P2, distance_rtol=1e-7, rtol_beyond=0.02)
            np.testing.assert_allclose(far.p1, P1.position(far.u1), atol=1e-12)
            assert want - 1e-9 <= far.distance <= want * (1 + 1e-4) + 1e-9


def test_skew_segments_in_closed_form():
    """Two skew segments: the couple is the common perpendicular of their lines where its feet
    lie inside both (interior), the shorter distance is at a clipped end otherwise."""
    a, b = np.array([0.0, -0.3, 0.2]), np.array([0.8, 0.5, 0.25])
    A, B = np.array([0.1, 0.6, 0.0]), np.array([0.6, -0.4, -0.1])
    e1, e2 = b - a, B - A
    w = a - A
    s, t = np.linalg.solve([[e1 @ e1, -(e1 @ e2)], [e1 @ e2, -(e2 @ e2)]], [-(w @ e1), -(w @ e2)])
    assert 0 < s < 1 and 0 < t < 1
    for kw in ({}, {"distance_rtol": 1e-7, "rtol_beyond": 0.02}):
        c = seek_couple(posed(Segment(a, b), *EYE), posed(Segment(A, B), *EYE), **kw)
        assert c.interior
        np.testing.assert_allclose(c.u, [s, t], atol=1e-9)
        assert c.distance == pytest.approx(np.linalg.norm(a + s * e1 - A - t * e2), abs=1e-12)
    # Shifted so that the perpendicular's foot on segment 1 lies beyond its end b.
    shift = (1.3 - s) * e1
    c = seek_couple(posed(Segment(a - shift, b - shift), *EYE), posed(Segment(A, B), *EYE))
    assert not c.interior and c.u1[0] == pytest.approx(1.0, abs=1e-12)
    seg2 = posed(Segment(A, B), *EYE)
    t_end = float(np.clip((b - shift - A) @ e2 / (e2 @ e2), 0.0, 1.0))
    assert c.distance == pytest.approx(np.linalg.norm(b - shift - seg2.position([t_end])),
                                       abs=1e-12)


@pytest.mark.parametrize("beta", [0.3, 1.0])
def test_circle_over_a_plane_in_closed_form(beta):
    """A circle tilted by beta over a plane: its lowest point, at h - R sin(beta), over its
    foot."""
    plane = PlaneRect((-1.0, -1.0, 0.0), (2.0, 0.0, 0.0), (0.0, 2.0, 0.0))
    R, h = 0.3, 0.4
    c0 = np.array([0.1, -0.2, h])
    low = c0 - R * np.array([0.0, math.cos(beta), math.sin(beta)])
    c = seek_couple(posed(Circle(R), rot_x(beta), c0), posed(plane, *EYE))
    assert c.interior
    assert c.distance == pytest.approx(h - R * math.sin(beta), abs=1e-12)
    np.testing.assert_allclose(c.p1, low, atol=1e-9)
    np.testing.assert_allclose(c.u2, (low[:2] + 1.0) / 2.0, atol=1e-9)


def test_point_over_a_plane_in_closed_form():
    """A point sphere of radius r over a tilted plane: the foot of the perpendicular, at the
    height less r; a foot beyond the plane's edge is not interior."""
    R = rot_vec((0.2, -0.1, 0.3))
    plane = PlaneRect((-1.0, -1.0, 0.0), (2.0, 0.0, 0.0), (0.0, 2.0, 0.0))
    nrm = R[:, 2]
    for q, inside in (((0.3, -0.2, 0.15), True), ((1.4, 0.2, 0.1), False)):
        x = R @ np.array(q)
        c = seek_couple(posed(Point(x, 0.004), *EYE), posed(plane, R, np.zeros(3)))
        assert c.interior == inside
        if inside:
            assert c.distance == pytest.approx(x @ nrm - 0.004, abs=1e-12)
            np.testing.assert_allclose(c.u2, (np.array(q[:2]) + 1.0) / 2.0, atol=1e-9)


def test_undescribed_patch_is_refused():
    """A polar curve without the sine form's parameters has no kernel: a ValueError naming it;
    a surface as patch 1 has no seek."""
    curve = PolarCurve(lambda th: (1.0 + 0 * th, 0 * th, 0 * th),
                       lambda th: (0 * th, 0 * th, 0 * th), (0.0, 1.0))
    seg = Segment((0, 0, 0), (1, 0, 0))
    with pytest.raises(ValueError, match="PolarCurve"):
        seek_couple(posed(curve, *EYE), posed(seg, *EYE))
    plane = PlaneRect((0, 0, 0), (1, 0, 0), (0, 1, 0))
    with pytest.raises(ValueError, match="no seek"):
        seek_couple(posed(plane, *EYE), posed(seg, *EYE))


CREEPING = json.loads(Path(__file__).with_name("creeping_seeks.json").read_text())


def _circle_to_annulus(P1, P2, s):
    """Distance (closed form) of the circle's point at s to the annulus: |z| over it, else to
    its nearer edge circle; in the annulus's frame."""
    x = P2.R.T @ (np.asarray(P1.position(np.array([s]))) - P2.p)
    rho, z = math.hypot(x[0], x[1]), x[2] - P2.patch.height
    lo, hi = P2.patch.lower[0], P2.patch.upper[0]
    return math.hypot(z, rho - min(max(rho, lo), hi))


def _least_circle_to_annulus(P1, P2):
    """The least `_circle_to_annulus` over the circle: a grid of 4001 points, then a bounded
    1-D minimisation around the best."""
    from scipy.optimize import minimize_scalar
    grid = np.linspace(0.0, 2 * math.pi, 4001)
    k = int(np.argmin([_circle_to_annulus(P1, P2, s) for s in grid]))
    return minimize_scalar(lambda s: _circle_to_annulus(P1, P2, s),
                           bounds=(grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]),
                           method="bounded", options={"xatol": 1e-12}).fun


@pytest.mark.parametrize("case", CREEPING, ids=lambda c: c["pair"])
def test_a_circle_through_a_face_near_its_edge_is_a_touch(case):
    """The target's rim piercing the chaser's face a few um from its inside edge (IDSS plan
    sample 0 on the paper's geometry): the minima form a curve and Newton creeps from one start.
    The seek takes it as a touch within CREEP_TOUCH, at the distance of a bounded 1-D
    minimisation of the closed-form point-to-annulus distance over the circle."""
    pair = next(p for p in DockingScene(ApdsGeometry(), "complete").pairs if p.name == case["pair"])
    P1 = posed(pair.patch1, np.array(case["R1"]), np.array(case["o1"]))
    P2 = posed(pair.patch2, np.array(case["R2"]), np.array(case["o2"]))
    rtol, beyond = case["kw"]
    got = seek_couple(P1, P2, distance_rtol=rtol, rtol_beyond=beyond)
    assert got.distance <= CREEP_TOUCH
    assert got.distance == pytest.approx(_least_circle_to_annulus(P1, P2), abs=1e-7)


VALLEY = json.loads(Path(__file__).with_name("creeping_valley_seeks.json").read_text())


@pytest.mark.parametrize("case", VALLEY, ids=lambda c: c["note"].split(",")[0].split()[-1])
def test_a_creeping_nearest_start_is_continued_to_the_minimum(case):
    """The target's rim nearly parallel to the chaser's face, its nearest point a few um to
    0.1 mm above it near the face's inside or outside edge (IDSS envelope plan samples 512,
    573, 634): the minima form a valley flat along the circle and curved in the parameters,
    and the nearest start's Newton has not converged in CLOSEST_MAX_ITER beyond CREEP_TOUCH
    (the seek raised SeekingError). With the starts that did not converge continued
    (CREEP_MAX_ITER), the nearest couple is at the distance of dense sampling + bounded L-BFGS
    and of the bounded 1-D minimisation of the closed-form point-to-annulus distance over the
    circle, to 1e-9 m, at points of both patches."""
    from drake_dock.core import seeking as S
    from drake_dock.core.couple import kernel_spec
    from drake_dock.core.kernels import seek as K
    pair = next(p for p in DockingScene(ApdsGeometry(), "complete").pairs if p.name == case["pair"])
    P1 = posed(pair.patch1, np.array(case["R1"]), np.array(case["o1"]))
    P2 = posed(pair.patch2, np.array(case["R2"]), np.array(case["o2"]))
    rtol, beyond = case["kw"]
    # The case is one the first CLOSEST_MAX_ITER iterations leave unconverged, nearest.
    _, _, status, X1, X2, _ = K.seek(K.Placed(*kernel_spec(P1.patch), *S._pose(P1)),
                                     K.Domain(*P1.patch.kernel_domain(12)),
                                     K.Placed(*kernel_spec(P2.patch), *S._pose(P2)),
                                     K.Domain(*P2.patch.kernel_domain(12)), 2, 21, 3, rtol, beyond)
    d = np.linalg.norm(X1 - X2, axis=1)
    assert status[np.argmin(d)] == 1 and d.min() > CREEP_TOUCH
    got = seek_couple(P1, P2, distance_rtol=rtol, rtol_beyond=beyond)
    # The couple's points are the patches' (sample 634's minimum lies on the face's outside
    # edge, the iteration ends 4e-8 m short of it: no closest-point conditions to 1e-7).
    np.testing.assert_allclose(got.p1, P1.position(got.u1), atol=1e-12)
    np.testing.assert_allclose(got.p2, P2.position(got.u2), atol=1e-12)
    assert got.distance == pytest.approx(np.linalg.norm(got.p1 - got.p2), abs=1e-13)
    want = np.linalg.norm(brute_force_closest(P1, P2)[2])
    assert got.distance == pytest.approx(want, abs=1e-9)
    assert got.distance == pytest.approx(_least_circle_to_annulus(P1, P2), abs=1e-9)
