"""A ring's outside circle (its rim) against the other APDS's guide surfaces and sides
(`drake_dock.docking.pairs.rim_pairs`): the seek against a closed form (a level rim behind a
petal's cone, Eq. 12) and against a converged brute-force minimum (a rim over a guide side,
Eq. 13-14), and the hand-overs between them at the petal's sides."""
import math

import numpy as np
import pytest
from scipy.optimize import minimize

from drake_dock.core.kernels import seek as compiled_seek
from drake_dock.core.patches import posed
from drake_dock.core.seeking import contact_couple, seek_couple
from drake_dock.docking.apds import side_phi
from drake_dock.docking.pairs import R_MATCHED, apds_pairs, pair_handovers, pair_type


def _pair(geom, name):
    return next(p for p in apds_pairs(geom, "complete") if p.name == name)


def _level_chaser(centre):
    """Poses of the two APDS: the target at the origin, the chaser at the matched facing (its
    rim level) with its ring centre at ``centre`` in the target's frame."""
    return {"target_apds": (np.eye(3), np.zeros(3)),
            "chaser_apds": (R_MATCHED, np.asarray(centre, dtype=float))}


def _seeks(pr, poses):
    P1, P2 = posed(pr.patch1, *poses[pr.body1]), posed(pr.patch2, *poses[pr.body2])
    return [seek_couple(P1, P2), compiled_seek.seek_couple(P1, P2)]


@pytest.mark.parametrize("k", (1, 2, 3))
@pytest.mark.parametrize("D, z", [(0.02, 0.10), (0.08, 0.10), (0.02, 0.15), (0.08, 0.15)])
def test_a_level_rim_behind_a_petal_is_the_closed_form_couple(geom, k, D, z):
    """The chaser's rim (radius R) level at height z, its centre D from the target's axis away
    from petal k's middle azimuth e: its point nearest the axis, (R - D) e + z e3, is its
    nearest to the cone rho = R - zeta cot(alpha1) (Eq. 12) and lies behind it (D < z
    cot(alpha1)): the gap is (z cot(alpha1) - D) sin(alpha1) and the foot is that point moved
    by the gap along the cone's outward normal (sin(alpha1) e + cos(alpha1) e3). Python and
    compiled seeks, the gap and the finished points to 1e-10."""
    a = geom.alpha1
    phi = side_phi(2 * k - 1) + math.pi / 6
    e = np.array([math.cos(phi), math.sin(phi), 0.0])
    pr = _pair(geom, f"cs_Crim_T{k}")
    assert pair_type(pr.name) == "ring outside circle / guide surface"
    gap = (z / math.tan(a) - D) * math.sin(a)
    p1 = (geom.R - D) * e + np.array([0.0, 0.0, z])
    normal = math.sin(a) * e + np.array([0.0, 0.0, math.cos(a)])
    poses = _level_chaser(-D * e + np.array([0.0, 0.0, z]))
    for c in _seeks(pr, poses):
        assert c.interior
        assert c.distance == pytest.approx(gap, abs=1e-10)
        # The rim is nearly parallel to the cone's circles: the seek stops at 1e-9 of the spans
        # in u; the contact-form finish (Eq. 37-38) takes the couple to its round-off.
        cc = contact_couple("CS", pr.patch1, poses[pr.body1], pr.patch2, poses[pr.body2], c,
                            conditioning_min=1e-10)
        assert cc.usable
        P1, P2 = posed(pr.patch1, *poses[pr.body1]), posed(pr.patch2, *poses[pr.body2])
        np.testing.assert_allclose(P1.position(cc.u[:1]), p1, atol=1e-10)
        np.testing.assert_allclose(P2.position(cc.u[1:]), p1 - gap * normal, atol=1e-10)


def _brute_force(pr, poses):
    """The least distance between the rim and the guide side by a dense sampling of both
    parameters, polished by Nelder-Mead (a converged minimum, independent of the seek)."""
    P1, P2 = posed(pr.patch1, *poses[pr.body1]), posed(pr.patch2, *poses[pr.body2])
    a = np.linspace(P1.patch.lower[0], P1.patch.upper[0], 721)
    b = np.linspace(P2.patch.lower[0], P2.patch.upper[0], 401)
    X1 = np.array([P1.position(np.array([x])) for x in a])
    X2 = np.array([P2.position(np.array([x])) for x in b])
    d = np.linalg.norm(X1[:, None, :] - X2[None, :, :], axis=-1)
    i, j = np.unravel_index(np.argmin(d), d.shape)
    lo, hi = P2.patch.lower[0], P2.patch.upper[0]

    def f(x):
        t = min(max(x[1], lo), hi)
        return np.linalg.norm(P1.position(np.array([x[0]])) - P2.position(np.array([t])))

    res = minimize(f, [a[i], b[j]], method="Nelder-Mead",
                   options={"xatol": 1e-13, "fatol": 1e-15, "maxiter": 20000})
    return res.fun


@pytest.mark.parametrize("i", range(1, 7))
def test_a_rim_over_a_guide_side_is_the_converged_minimum(geom, i):
    """The chaser's rim tilted 3 deg, its centre 0.08 m off the axis away from guide side i's
    mid-height azimuth and 0.13 m up: the seek's couple (Python and compiled) is interior and
    its distance is the brute-force minimum to 1e-9."""
    from drake_dock.docking.scene import rot_vec
    pr = _pair(geom, f"cc_Crim_T{i}")
    assert pair_type(pr.name) == "ring outside circle / guide side"
    side = pr.patch2
    mid = side.position(np.array([0.5 * (side.lower[0] + side.upper[0])]))
    e = np.array([mid[0], mid[1], 0.0]) / math.hypot(mid[0], mid[1])
    poses = {"target_apds": (np.eye(3), np.zeros(3)),
             "chaser_apds": (rot_vec((0.05 * e[1], -0.05 * e[0], 0.0)) @ R_MATCHED,
                             -0.08 * e + np.array([0.0, 0.0, 0.13]))}
    want = _brute_force(pr, poses)
    for c in _seeks(pr, poses):
        assert c.interior
        assert c.distance == pytest.approx(want, abs=1e-9)


def test_the_rim_pairs_and_their_handovers(geom):
    """Each APDS's rim against the other's three guide surfaces and six sides (18 pairs,
    Body 1 the rim: radius R, height 0), and a hand-over from each rim/surface pair to the
    rim/side pairs of its two sides, over the surface's edges s = 0 and s = 1."""
    pairs = {p.name: p for p in apds_pairs(geom, "complete")}
    for x, y, b1 in (("C", "T", "chaser_apds"), ("T", "C", "target_apds")):
        for name in [f"cs_{x}rim_{y}{k}" for k in (1, 2, 3)] + [f"cc_{x}rim_{y}{i}"
                                                                 for i in range(1, 7)]:
            pr = pairs[name]
            assert pr.body1 == b1 and (pr.patch1.radius, pr.patch1.height) == (geom.R, 0.0)
    hand = {(e, s): edge for e, s, edge in pair_handovers(geom, list(pairs.values()))}
    for x, y in (("C", "T"), ("T", "C")):
        for k in (1, 2, 3):
            lo = hand[(f"cc_{x}rim_{y}{2 * k - 1}", f"cs_{x}rim_{y}{k}")]
            hi = hand[(f"cc_{x}rim_{y}{2 * k}", f"cs_{x}rim_{y}{k}")]
            assert (lo.fixed, lo.upper, hi.fixed, hi.upper) == (0, False, 0, True)
