"""The compiled seek (`drake_dock.core.kernels.seek`) against the Python reference
`drake_dock.core.seeking.seek_couple`: the same distance to 1e-12 and the same interior flag on
the APDS pairs at several poses and on small scenes. The couple itself agrees to the seek's own
tolerance (1e-6 of the domain span here): where the distance is flat along a valley, a grid tie
broken the other way ends the Newton finish at another point of the same valley."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from drake_dock.core.kernels import seek as compiled
from drake_dock.core.patches import Circle, Cone, PlaneRect, PolarCurve, Segment, posed
from drake_dock.core.seeking import seek_couple
from drake_dock.docking.geometry.pairs import R_MATCHED
from drake_dock.docking.geometry.rotations import rot_vec
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.scenario.dimensions import ApdsGeometry


def _check(P1, P2, **kw):
    assert compiled.supported(P1, P2)
    ref, got = seek_couple(P1, P2, **kw), compiled.seek_couple(P1, P2, **kw)
    assert got.distance == pytest.approx(ref.distance, rel=0, abs=1e-12)
    assert got.interior == ref.interior
    span = np.concatenate([P1.patch.span, P2.patch.span])
    np.testing.assert_allclose(got.u, ref.u, rtol=0, atol=1e-6 * span.max())
    np.testing.assert_allclose(got.p1, P1.position(got.u1), rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.p2, P2.position(got.u2), rtol=0, atol=1e-12)


@pytest.mark.parametrize("g", [ApdsGeometry(), ApdsGeometry(R=0.9, Rs=0.55, H=0.3,
                                                            alpha1_deg=50.0, alpha2_deg=25.0)])
@pytest.mark.parametrize("d", [0.3, 0.12, 0.02, -0.05])
def test_apds_pairs_equal_the_python_seek(g, d):
    """All 12 pairs, the chaser tilted, offset and at ring distance d (the last overlapping)."""
    poses = {"target_apds": (np.eye(3), np.zeros(3)),
             "chaser_apds": (rot_vec((0.03, -0.02, 0.01)) @ R_MATCHED,
                             np.array([0.01, -0.005, d]))}
    for pr in DockingScene(g, "paper").pairs:
        _check(posed(pr.patch1, *poses[pr.body1]), posed(pr.patch2, *poses[pr.body2]))


def test_small_scenes_equal_the_python_seek():
    """Segments, a circle over a plane and a cone, with a shorter Newton finish
    (``distance_rtol``) as the contact system asks for far pairs."""
    R = rot_vec((0.2, -0.1, 0.4))
    cases = [(Segment((0.0, 0.0, 0.1), (1.0, 0.2, 0.1)), Segment((0.5, -1.0, 0.0),
                                                                (0.4, 1.0, 0.05))),
             (Circle(0.3, 0.1), PlaneRect((-1, -1, 0), (2, 0, 0.1), (0, 2, 0))),
             (Circle(0.2, 0.0), Cone(0.5, 0.9, (0.2, 1.4), (0.0, 0.3)))]
    for c1, c2 in cases:
        for p in ([0.0, 0.0, 0.2], [0.3, -0.1, 0.05]):
            _check(posed(c1, R, np.array(p)), posed(c2, np.eye(3), np.zeros(3)))
            _check(posed(c1, R, np.array(p)), posed(c2, np.eye(3), np.zeros(3)),
                   distance_rtol=1e-7, rtol_beyond=0.02)


def test_undescribed_patch_is_not_supported():
    curve = PolarCurve(lambda th: (1.0 + 0 * th, 0 * th, 0 * th),
                       lambda th: (0 * th, 0 * th, 0 * th), (0.0, 1.0))
    seg = Segment((0, 0, 0), (1, 0, 0))
    assert not compiled.supported(posed(curve, np.eye(3), np.zeros(3)),
                                  posed(seg, np.eye(3), np.zeros(3)))


CREEPING = json.loads(Path(__file__).with_name("creeping_seeks.json").read_text())


def _circle_to_annulus(P1, P2, s):
    """Distance (closed form) of the circle's point at s to the annulus: |z| over it, else to
    its nearer edge circle; in the annulus's frame."""
    x = P2.R.T @ (np.asarray(P1.position(np.array([s]))) - P2.p)
    rho, z = math.hypot(x[0], x[1]), x[2] - P2.patch.height
    lo, hi = P2.patch.lower[0], P2.patch.upper[0]
    return math.hypot(z, rho - min(max(rho, lo), hi))


@pytest.mark.parametrize("case", CREEPING, ids=lambda c: c["pair"])
def test_a_circle_through_a_face_near_its_edge_is_a_touch(case):
    """The target's rim piercing the chaser's face a few um from its inside edge (IDSS plan
    sample 0 on the paper's geometry): the minima form a curve and Newton creeps from one start.
    Both seeks take it as a touch within CREEP_TOUCH, at the distance of a bounded 1-D
    minimisation of the closed-form point-to-annulus distance over the circle."""
    from scipy.optimize import minimize_scalar
    pair = next(p for p in DockingScene(ApdsGeometry(), "complete").pairs if p.name == case["pair"])
    P1 = posed(pair.patch1, np.array(case["R1"]), np.array(case["o1"]))
    P2 = posed(pair.patch2, np.array(case["R2"]), np.array(case["o2"]))
    rtol, beyond = case["kw"]
    got = compiled.seek_couple(P1, P2, distance_rtol=rtol, rtol_beyond=beyond)
    ref = seek_couple(P1, P2, distance_rtol=rtol, rtol_beyond=beyond)
    grid = np.linspace(0.0, 2 * math.pi, 4001)
    k = int(np.argmin([_circle_to_annulus(P1, P2, s) for s in grid]))
    best = minimize_scalar(lambda s: _circle_to_annulus(P1, P2, s),
                           bounds=(grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]),
                           method="bounded", options={"xatol": 1e-12})
    assert got.distance <= compiled.CREEP_TOUCH and ref.distance <= compiled.CREEP_TOUCH
    assert got.distance == pytest.approx(best.fun, abs=1e-7)
    assert ref.distance == pytest.approx(best.fun, abs=1e-7)
