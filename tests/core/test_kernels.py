"""The compiled kernels against the pure-Python reference they replace: patch jets against
`Patch.jet`, and every field of the couple evaluation against `evaluate_couple`, to 1e-12, on
the APDS patches (several geometries) and small scenes of segments, circles, planes and cones."""
import math

import numpy as np
import pytest

from drake_dock.core.couple import evaluate_couple
from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels.jets import jet, patch_spec, position
from drake_dock.core.kernels.tracked import TrackedCouples
from drake_dock.core.patches import Circle, Cone, PlaneRect, PolarCurve, Segment, posed
from drake_dock.core.seeking import seek_couple
from drake_dock.docking.geometry.apds import apds_patches
from drake_dock.docking.geometry.pairs import R_MATCHED
from drake_dock.docking.geometry.rotations import rot_vec
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.scenario.dimensions import ApdsGeometry

GEOMETRIES = [ApdsGeometry(), ApdsGeometry(R=0.9, Rs=0.55, H=0.3, alpha1_deg=50.0,
                                           alpha2_deg=25.0)]
FIELDS = ("u", "drift", "udot", "residual", "conditioning", "p1", "p2", "n", "ta", "tb", "gap",
          "v_rel", "vn", "vt", "bias_n", "bias_t")


def _patches(g):
    P = apds_patches(g)
    return ([*P.sides.values(), *P.surfaces.values(), P.ring, Segment((0.1, -0.2, 0.3),
                                                                      (0.7, 0.4, -0.1)),
             PlaneRect((-1.0, -0.5, 0.2), (0.8, 0.1, 0.0), (0.0, 0.9, 0.3), (2.0, 1.5)),
             Cone(0.5, 0.9, (0.2, 1.4), (0.0, 0.3))])


@pytest.mark.parametrize("g", GEOMETRIES)
def test_jets_equal_the_patches(g):
    """The kernel's jet (r, T, K) equals `Patch.jet` at random points of each domain."""
    rng = np.random.default_rng(1)
    for patch in _patches(g):
        kind, prm = patch_spec(patch)
        for _ in range(20):
            u = patch.lower + rng.random(patch.dim) * patch.span
            r, T, Kp = patch.jet(u)
            want = [r, *T] + ([Kp[0][0]] if patch.dim == 1 else [Kp[0][0], Kp[0][1], Kp[1][1]])
            got = jet(kind, prm, u[0], u[1] if patch.dim == 2 else 0.0)
            got = [got[0], got[1]] + ([got[3]] if patch.dim == 1 else [got[2], *got[3:]])
            np.testing.assert_allclose(np.array(got), np.array(want), rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("g", GEOMETRIES)
def test_position_is_the_jets_point(g):
    """`position` (the seek's grids) gives the bits of the jet's r, for every kind, at random
    points of each domain and on its ends."""
    P = apds_patches(g)
    rng = np.random.default_rng(2)
    for patch in _patches(g) + [*P.tips.values(), P.rim, P.face]:
        kind, prm = patch_spec(patch)
        U = patch.lower + rng.random((200, patch.dim)) * patch.span
        for u in np.concatenate([U, [patch.lower, patch.upper]]):
            u1 = u[1] if patch.dim == 2 else 0.0
            assert position(kind, prm, u[0], u1) == jet(kind, prm, u[0], u1)[0], (patch, u)


def test_patch_spec_declines_an_undescribed_curve():
    """A polar curve without the sine form's parameters has no kernel: the caller's Python
    path is used (`TrackedCouples.supported` is False)."""
    curve = PolarCurve(lambda th: (1.0 + 0 * th, 0 * th, 0 * th),
                       lambda th: (0 * th, 0 * th, 0 * th), (0.0, 1.0))
    assert patch_spec(curve) is None
    assert not TrackedCouples([("CC", curve, Segment((0, 0, 0), (1, 0, 0)), (0, 1))]).supported
    assert TrackedCouples([("CC", Segment((0, 0, 1), (1, 0, 1)),
                            Segment((0, 0, 0), (1, 0, 0)), (0, 1))]).supported


def _compare(pairs, poses, twists, us, sigmas, project=True, feedback=7.0):
    """Evaluates the pairs (kind, patch1, patch2, (frame a, frame b)) by the kernel and by
    `evaluate_couple` and checks every field; returns the kernel's rows."""
    tc = TrackedCouples(pairs)
    assert tc.supported
    R = np.array([X[0] for X in poses])
    o = np.array([X[1] for X in poses])
    w = np.array([V[0] for V in twists])
    v = np.array([V[1] for V in twists])
    u = np.concatenate(us)
    out, rate = tc.evaluate(R, o, w, v, u, np.array(sigmas),
                            np.ones(len(pairs), dtype=np.bool_), project=project,
                            drift_feedback=feedback)
    for i, (kind, p1, p2, (a, b)) in enumerate(pairs):
        ref = evaluate_couple(kind, p1, poses[a], twists[a], p2, poses[b], twists[b], us[i],
                              sigmas[i], project=project)
        got = tc.couple_eval(out, i)
        np.testing.assert_allclose(got.frame, ref.frame, rtol=0, atol=1e-12)
        for f in FIELDS:
            want = np.asarray(getattr(ref, f), dtype=float)
            scale = 1.0 + np.abs(want).max()
            np.testing.assert_allclose(getattr(got, f), want, rtol=0, atol=1e-12 * scale,
                                       err_msg=f"pair {i} field {f}")
        span = np.concatenate([p1.span, p2.span])
        m = len(span)
        np.testing.assert_allclose(out[i, K.DRIFT_REL], np.max(np.abs(ref.drift) / span),
                                   rtol=1e-12, atol=1e-300)
        np.testing.assert_allclose(rate[tc.uoff[i]:tc.uoff[i + 1]],
                                   ref.udot + feedback * ref.drift, rtol=0,
                                   atol=1e-12 * (1 + np.abs(ref.udot).max()))
    return out


def _twist(rng):
    return rng.normal(size=3) * 0.7, rng.normal(size=3) * 0.2


@pytest.mark.parametrize("g", GEOMETRIES)
@pytest.mark.parametrize("d", [0.12, 0.05, 0.02])
def test_apds_couples_equal_the_python_path(g, d):
    """The APDS pairs whose closest couple is interior, with the chaser at ring distance d,
    tilted and moving, from their closest couples perturbed off the closest-point conditions
    (so that the projection acts), both orientations sigma."""
    rng = np.random.default_rng(int(100 * d))
    X_T = (np.eye(3), np.zeros(3))
    X_C = (rot_vec((0.03, -0.02, 0.01)) @ R_MATCHED, np.array([0.01, -0.005, d]))
    poses, twists = [X_T, X_C], [_twist(rng), _twist(rng)]
    frame = {"target_apds": 0, "chaser_apds": 1}
    pairs, us, sigmas = [], [], []
    for k, pr in enumerate(DockingScene(g, "paper").pairs):
        span = np.concatenate([pr.patch1.span, pr.patch2.span])
        c = seek_couple(posed(pr.patch1, *poses[frame[pr.body1]]),
                        posed(pr.patch2, *poses[frame[pr.body2]]))
        if not c.interior:
            continue
        pairs.append((pr.kind, pr.patch1, pr.patch2, (frame[pr.body1], frame[pr.body2])))
        us.append(c.u + 1e-3 * span * rng.normal(size=len(span)))
        sigmas.append(1.0 if k % 2 else -1.0)
    assert {p[0] for p in pairs} == {"CC", "CS"}
    _compare(pairs, poses, twists, us, sigmas)
    _compare(pairs, poses, twists, us, sigmas, project=False)


def _settled(pairs, poses, us):
    """The couples projected onto the closest-point conditions by a few Newton steps of the
    reference (so that the kernel's round-off-sized branch is exercised)."""
    out = []
    for (kind, p1, p2, (a, b)), u in zip(pairs, us):
        for _ in range(30):
            ev = evaluate_couple(kind, p1, poses[a], (np.zeros(3),) * 2, p2, poses[b],
                                 (np.zeros(3),) * 2, u, 1.0)
            u = ev.u
        out.append(np.array(u))
    return out


def test_small_scenes_equal_the_python_path():
    """Segments crossing (CC), a circle over a plane and a cone (CS), settled couples and
    perturbed ones, with three frames."""
    rng = np.random.default_rng(7)
    pairs = [("CC", Segment((0.0, 0.0, 0.1), (1.0, 0.2, 0.1)),
              Segment((0.5, -1.0, 0.0), (0.4, 1.0, 0.05)), (0, 1)),
             ("CS", Circle(0.3, 0.1), PlaneRect((-1, -1, 0), (2, 0, 0.1), (0, 2, 0)), (2, 1)),
             ("CS", Circle(0.2, 0.0), Cone(0.5, 0.9, (0.2, 1.4), (0.0, 0.3)), (2, 0)),
             ("CC", Circle(0.4, 0.05), Segment((0.2, -0.5, 0.3), (0.3, 0.5, -0.2)), (0, 2))]
    poses = [(rot_vec(rng.normal(size=3) * 0.1), rng.normal(size=3) * 0.05) for _ in range(3)]
    poses[2] = (rot_vec((math.pi / 2, 0.1, 0.0)), np.array([0.3, 0.1, 0.2]))
    twists = [_twist(rng) for _ in range(3)]
    us = [np.array([0.5, 0.5]), np.array([1.0, 0.4, 0.5]), np.array([0.7, 0.8, 0.1]),
          np.array([2.0, 0.5])]
    _compare(pairs, poses, twists, us, [1.0, -1.0, 1.0, -1.0])
    settled = _settled(pairs, poses, us)
    _compare(pairs, poses, twists, settled, [1.0, -1.0, 1.0, -1.0])
    near = [u + 1e-12 for u in settled]
    _compare(pairs, poses, twists, near, [1.0, 1.0, -1.0, 1.0])


def test_inactive_pairs_are_left_zero():
    """Only the pairs asked for are evaluated (a far pair's row stays zero)."""
    seg = Segment((0.0, 0.0, 0.1), (1.0, 0.0, 0.1))
    tc = TrackedCouples([("CC", seg, Segment((0.5, -1, 0), (0.5, 1, 0)), (0, 1))] * 2)
    R, z = np.array([np.eye(3)] * 2), np.zeros((2, 3))
    out, rate = tc.evaluate(R, z, z, z, np.full(4, 0.5), np.ones(2), np.array([True, False]))
    assert out[0, K.GAP] == pytest.approx(0.1) and not out[1].any() and not rate[2:].any()
