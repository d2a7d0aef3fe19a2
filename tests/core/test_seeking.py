"""The compiled seek's building blocks (`drake_dock.core.kernels.grids`,
`drake_dock.core.kernels.seek`) against independent constructions: the local grids against
numpy's meshgrid, the Newton step against the floored eigen-decomposition."""
import math

import numpy as np
import pytest

from drake_dock.core.patches import Circle, Cone
from drake_dock.core.kernels.grids import _axes_point, _local_axes
from drake_dock.core.kernels.seek import FLAT, _descent_step


@pytest.mark.parametrize("patch", [Cone(0.6, math.radians(45), (0.1, 1.0), (0.0, 0.2)),
                                   Circle(0.5, 0.1)], ids=["cone", "circle"])
def test_local_grids_match_meshgrid(patch):
    rng = np.random.default_rng(1)
    centres = rng.uniform(patch.lower, patch.upper, size=(4, patch.dim))
    centres[0] = patch.lower            # clipped at the lower ends (or wrapped)
    half = 0.3 * patch.span
    lower, upper = np.array(patch.lower, float), np.array(patch.upper, float)
    periodic = np.array(patch.periodic)
    for c in centres:
        A = _local_axes(c.copy(), half, lower, upper, periodic, 7)
        g = np.array([_axes_point(A, a) for a in range(7 ** patch.dim)])
        axes = []
        for k in range(patch.dim):
            lo, hi = c[k] - half[k], c[k] + half[k]
            if not patch.periodic[k]:
                lo, hi = max(lo, patch.lower[k]), min(hi, patch.upper[k])
            axes.append(np.linspace(lo, hi, 7))
        mesh = np.meshgrid(*axes, indexing="ij")
        want = patch.wrap(np.stack([m.ravel() for m in mesh], axis=-1))
        np.testing.assert_allclose(g, want, rtol=0, atol=1e-15)


def _eigen_parts(H, g):
    """The step -V (V^T g) / |w| with |w| floored at 1e-16 max(1, |w|max), split into its
    parts along the directions with |w| >= FLAT max(1, |w|max) and along the others."""
    w, V = np.linalg.eigh(H)
    w = np.abs(w)
    top = max(1.0, w.max())
    c = -(V.T @ g) / np.maximum(w, 1e-16 * top)
    flat = w < FLAT * top
    return V @ np.where(flat, 0.0, c), V @ np.where(flat, c, 0.0), flat


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_descent_step_is_the_floored_eigen_step(n):
    """The two parts of `_descent_step` (Cholesky where H is well conditioned) against the
    eigen-decomposition; the nearly singular Hessians have flat directions (but in 1-D, where
    the floor is FLAT |H|)."""
    rng = np.random.default_rng(n)
    flat_seen = 0
    for case in range(30):
        A = rng.normal(size=(n, n))
        if case % 3 == 0:        # positive definite
            H = A @ A.T + 0.1 * np.eye(n)
        elif case % 3 == 1:      # indefinite
            H = A + A.T
        else:                    # nearly singular: eigenvalues 1 .. 1e-13
            Q, _ = np.linalg.qr(A)
            H = Q @ np.diag(np.logspace(0, -13, n)) @ Q.T
        g = rng.normal(size=n)
        newton, flat = _descent_step(np.ascontiguousarray(H), g)
        if n == 1:
            want_newton = -g / max(abs(H[0, 0]), FLAT * max(1.0, abs(H[0, 0])))
            want_flat = np.zeros(1)
        else:
            want_newton, want_flat, dirs = _eigen_parts(H, g)
            flat_seen += dirs.any()
        for got, want in ((newton, want_newton), (flat, want_flat)):
            np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-12 * np.abs(want).max())
        assert newton @ g < 0.0 and flat @ g <= 0.0    # descent directions
        if case % 3 == 0:        # the Newton step itself: H x = -g
            np.testing.assert_allclose(H @ newton, -g, rtol=1e-9, atol=1e-12)
    assert flat_seen == (10 if n > 1 else 0)
