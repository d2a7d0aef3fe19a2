"""A ring's outside circle (its rim) against the other APDS's guide surfaces
(`drake_dock.docking.pairs.rim_pairs`): the seek against a closed form (a level rim behind a
petal's cone, Eq. 12), and the pairs' patches."""
import math

import numpy as np
import pytest

from drake_dock.core.kernels import seek as compiled_seek
from drake_dock.core.patches import posed
from drake_dock.core.seeking import contact_couple, seek_couple
from drake_dock.docking.apds import side_phi
from drake_dock.docking.pairs import R_MATCHED, apds_pairs, pair_type


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


def test_the_rim_pairs(geom):
    """Each APDS's rim against the other's three guide surfaces (6 pairs, Body 1 the rim:
    radius R, height 0; Body 2 the other APDS's guide surface k)."""
    pairs = {p.name: p for p in apds_pairs(geom, "complete")}
    surfaces = {k: _pair(geom, f"cs_Cring_T{k}").patch2 for k in (1, 2, 3)}
    for x, y, b1, b2 in (("C", "T", "chaser_apds", "target_apds"),
                         ("T", "C", "target_apds", "chaser_apds")):
        for k in (1, 2, 3):
            pr = pairs[f"cs_{x}rim_{y}{k}"]
            assert (pr.kind, pr.body1, pr.body2) == ("CS", b1, b2)
            assert (pr.patch1.radius, pr.patch1.height) == (geom.R, 0.0)
            u = np.array([[0.1, 0.02], [0.5, 0.1], [0.9, 0.18]])
            np.testing.assert_array_equal(pr.patch2.position(u), surfaces[k].position(u))
    assert not [n for n in pairs if n.startswith(("cc_Crim_T", "cc_Trim_C"))
                and n != "cc_Crim_Trim"]
