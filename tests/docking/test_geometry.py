"""APDS patches (Sect. 4) and the generic patch core against independent definitions."""
import math

import numpy as np
import pytest

from drake_dock.core.patches import Circle, Cone, PlaneRect, Reparametrized, Segment, posed
from drake_dock.docking.geometry.apds import apds_patches, guide_side, guide_surface, ring_circle
from drake_dock.docking.geometry.rotations import rot_x, rot_z

RNG = np.random.default_rng(7)


def _interior_samples(patch, n=25):
    lo, hi = patch.lower, patch.upper
    return lo + (hi - lo) * (0.02 + 0.96 * RNG.random((n, patch.dim)))


def _all_patches(g):
    P = apds_patches(g)
    out = {f"side{i}": c for i, c in P.sides.items()}
    out.update({f"surface{k}": s for k, s in P.surfaces.items()})
    out["ring"] = P.ring
    out["circle"] = Circle(0.7, 0.2)
    out["segment"] = Segment([0.1, 0.2, 0.3], [1.0, -0.5, 2.0])
    out["plane"] = PlaneRect([0, 0, 1], [1, 0, 0.2], [0, 1, -0.1], (2, 3))
    out["cone"] = Cone(0.6, math.radians(45), (0.1, 1.0), (0.0, 0.2))
    return out


def test_guide_sides_lie_on_cone_and_auxiliary_plane(geom):
    g = geom
    cot1 = 1 / math.tan(g.alpha1)
    for i in range(1, 7):
        c = guide_side(g, i)
        phi = (i - 1) * math.pi / 3
        t = np.linspace(c.lower[0], c.upper[0], 201)
        t = t[np.argsort(np.abs(t - phi))]  # from the outer circle towards the tip
        X = c.position(t[:, None])
        rho = np.hypot(X[:, 0], X[:, 1])
        # On the cone of Eq. (12).
        np.testing.assert_allclose(rho, g.R - X[:, 2] * cot1, rtol=0, atol=1e-13)
        # In the auxiliary plane: vertical, through the outer-circle point at (i-1) pi/3, whose
        # trace makes the angle alpha2 with the radius line there (Sect. 4.1.1).
        e_r = np.array([math.cos(phi), math.sin(phi)])
        w = X[1:, :2] - g.R * e_r
        w /= np.linalg.norm(w, axis=1, keepdims=True)
        cross = w[:, 0] * e_r[1] - w[:, 1] * e_r[0]
        np.testing.assert_allclose(np.abs(cross), math.sin(g.alpha2), atol=1e-12)
        np.testing.assert_allclose(-(w @ e_r), math.cos(g.alpha2), atol=1e-12)  # inwards
        # Sides 1, 3, 5 lean towards increasing theta, 2, 4, 6 towards decreasing.
        theta = np.unwrap(np.arctan2(X[:, 1], X[:, 0]))
        assert np.all(np.sign(np.diff(theta)) == (1 if i % 2 else -1))


def test_guide_side_ends(geom):
    g = geom
    for i in range(1, 7):
        c = guide_side(g, i)
        phi = (i - 1) * math.pi / 3
        ends = [c.lower[0], c.upper[0]]
        start = min(ends, key=lambda t: abs(t - phi))
        stop = max(ends, key=lambda t: abs(t - phi))
        assert start == pytest.approx(phi, abs=1e-15)
        X0 = c.position(np.array([start]))
        np.testing.assert_allclose([np.hypot(X0[0], X0[1]), X0[2]], [g.R, 0.0], atol=1e-14)
        X1 = c.position(np.array([stop]))
        assert X1[2] == pytest.approx(g.H, abs=1e-13)
        # docs/model.md, "APDS geometry": 18.59 deg for the paper's numbers.
        assert math.degrees(abs(stop - phi)) == pytest.approx(18.59, abs=0.005)


def test_guide_surface_edges_are_the_sides(geom):
    from scipy.optimize import brentq
    g = geom
    for k in (1, 2, 3):
        S = guide_surface(g, k)
        for s_edge, side in ((0.0, guide_side(g, 2 * k - 1)), (1.0, guide_side(g, 2 * k))):
            for z in np.linspace(0.0, g.H, 9):
                X = S.position(np.array([s_edge, z]))
                # The side's point at the same height, found on the side alone.
                f = lambda t: side.position(np.array([t]))[2] - z  # noqa: E731
                ends = sorted((side.lower[0], side.upper[0]), key=lambda t: abs(f(t)))
                t = ends[0] if abs(f(ends[0])) < 1e-15 else \
                    brentq(f, side.lower[0], side.upper[0], xtol=1e-15)
                np.testing.assert_allclose(X, side.position(np.array([t])), atol=1e-12)


def test_derivatives_match_central_differences(geom):
    R = rot_z(0.3) @ rot_x(1.1)
    p = np.array([0.2, -0.1, 3.0])
    for name, patch in _all_patches(geom).items():
        for P in (patch, posed(patch, R, p)):
            U = _interior_samples(patch)
            T = P.first(U)
            S = P.second(U)
            for a in range(patch.dim):
                h = 1e-5 * max(1.0, float(patch.upper[a] - patch.lower[a]))
                e = np.zeros(patch.dim)
                e[a] = h
                fd1 = (P.position(U + e) - P.position(U - e)) / (2 * h)
                fd2 = (P.first(U + e) - P.first(U - e)) / (2 * h)
                scale1 = np.abs(T).max()
                scale2 = max(np.abs(S).max(), scale1)
                assert np.abs(fd1 - T[..., a]).max() <= 1e-7 * scale1, name
                assert np.abs(fd2 - S[..., a]).max() <= 1e-7 * scale2, name


def test_point_jets_equal_the_vectorised_evaluation(geom):
    """`Patch.jet` (plain floats, used by the couple evaluation) against the vectorised
    position/first/second, including a curve through a reparametrisation."""
    patches = _all_patches(geom)
    patches["reparam_curve"] = Reparametrized(Circle(0.5, 0.1), _Square())
    for name, patch in patches.items():
        for u in _interior_samples(patch, 6):
            r, T, K = patch.jet(u)
            assert np.allclose(r, patch.position(u), rtol=0, atol=1e-14), name
            assert np.allclose(np.array(T).T, patch.first(u), rtol=0, atol=1e-13), name
            assert np.allclose(np.transpose(np.array(K), (2, 0, 1)), patch.second(u), rtol=0,
                               atol=1e-12), name


class _Square:
    """u = s^2 on s in [0.5, 2]: a parameter map without a ``jet`` of its own."""

    lower, upper = np.array([0.5]), np.array([2.0])

    def value(self, s):
        return np.asarray(s, dtype=float) ** 2

    def jac(self, s):
        return 2 * np.asarray(s, dtype=float)[..., None]

    def hess(self, s):
        return np.full(np.shape(s) + (1, 1), 2.0)


def test_turning_by_120_deg_maps_patches_onto_each_other(geom):
    Rz = rot_z(2 * math.pi / 3)
    for i in range(1, 7):
        a, b = guide_side(geom, i), guide_side(geom, (i + 1) % 6 + 1)
        u = np.linspace(a.lower[0], a.upper[0], 50)[:, None]
        np.testing.assert_allclose(a.position(u) @ Rz.T, b.position(u + 2 * math.pi / 3),
                                   atol=1e-13)
    for k in (1, 2, 3):
        a, b = guide_surface(geom, k), guide_surface(geom, k % 3 + 1)
        U = _interior_samples(a, 50)
        np.testing.assert_allclose(a.position(U) @ Rz.T, b.position(U), atol=1e-13)
    ring = ring_circle(geom)
    u = np.linspace(0, 2 * math.pi, 50)[:, None]
    np.testing.assert_allclose(ring.position(u) @ Rz.T, ring.position(u + 2 * math.pi / 3),
                               atol=1e-13)


def test_ring_is_the_inside_circle(geom):
    u = np.linspace(0, 2 * math.pi, 37)[:, None]
    X = ring_circle(geom).position(u)
    np.testing.assert_allclose(np.hypot(X[:, 0], X[:, 1]), geom.Rs, atol=1e-15)
    np.testing.assert_allclose(X[:, 2], 0.0, atol=0)
