"""`cone_reach`: the cone distance's extremes along a segment against dense samples of it (s is
1-Lipschitz, so the samples' least value lies within half a sample's travel of the true one),
and the points it keeps against a brute-force scan of each path through the petals' heights."""
import math

import numpy as np
import pytest

from drake_dock.docking.checks import cone_reach
from drake_dock.docking.checks import penetration as pen

N_SAMPLES = 20001


def _segments(g, rng, n):
    """Random segments near the cone, and degenerate ones: through the axis, vertical,
    horizontal, tangent to the cone, and with the norm's slope equal to c (sin^2(alpha1)
    |Q|^2 = c^2)."""
    th = rng.uniform(0, 2 * math.pi, n)
    z = rng.uniform(-0.05, g.H + 0.05, n)
    rho = g.R - z / math.tan(g.alpha1) + rng.normal(scale=0.01, size=n)
    A = np.column_stack([rho * np.cos(th), rho * np.sin(th), z])
    D = rng.normal(scale=0.05, size=(n, 3))
    sa, ca = math.sin(g.alpha1), math.cos(g.alpha1)
    through = np.array([[0.1, 0.05, 0.02], [-0.2, -0.1, 0.0]])      # the axis at f = 1/3
    vertical = np.array([[0.4, 0.1, 0.3], [0.0, 0.0, -0.4]])
    horizontal = np.array([[0.3, 0.2, 0.05], [0.2, 0.1, 0.0]])
    q = np.array([0.6, 0.8]) * 0.1                                 # |Q| = 0.1
    slope = np.array([[0.2, 0.0, 0.05], [*q, -sa * 0.1 / ca]])     # |c| = sin(alpha1) |Q|
    e = np.array([math.cos(0.3), math.sin(0.3)])
    P = np.array([*((g.R - 0.1 / math.tan(g.alpha1)) * e), 0.1])    # on the cone
    tangent = np.array([P - 0.05 * np.array([-e[1], e[0], 0.0]), 0.1 * np.array([-e[1], e[0],
                                                                                 0.0])])
    edges = [np.array([[*((g.R - z / math.tan(g.alpha1) - 0.01) * e), z], [*(0.02 * e), dz]])
             for z, dz in ((g.H + 1e-3, 0.0), (-1e-3, 0.0), (g.H + 1e-3, -1e-4), (-1e-3, 1e-4))
             ]                                       # through the cone just outside 0 <= z <= H
    extra = np.array([through, vertical, horizontal, slope, tangent, *edges])
    return np.concatenate([A, extra[:, 0]]), np.concatenate([D, extra[:, 1]])


def _sampled(g, A, D, lo, hi):
    f = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, N_SAMPLES)[None]
    Y = A[:, None] + f[..., None] * D[:, None]
    return pen.cone_distance(g, Y.reshape(-1, 3)).reshape(len(A), -1), Y[..., 2]


def test_cone_extremes_against_dense_samples(geom):
    rng = np.random.default_rng(5)
    A, D = _segments(geom, rng, 300)
    lo = rng.uniform(0.0, 0.5, len(A))
    hi = lo + rng.uniform(0.0, 0.5, len(A))
    lo[-9:], hi[-9:] = 0.0, 1.0
    least, most = cone_reach.cone_extremes(geom, A, D, lo, hi)
    s, _ = _sampled(geom, A, D, lo, hi)
    half_step = np.linalg.norm(D, axis=1) * (hi - lo) / (N_SAMPLES - 1) / 2
    assert np.all(least <= s.min(axis=1) + 1e-13)
    assert np.all(least >= s.min(axis=1) - half_step - 1e-13)
    assert np.array_equal(most, np.maximum(s[:, 0], s[:, -1]))
    assert np.all(most >= s.max(axis=1) - 1e-13)
    assert least[-9] < -1e-3 and least[-5] == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("margin", [0.0, 2e-3])
def test_may_cross_keeps_the_paths_that_meet_the_cone_at_the_petals_heights(geom, margin):
    """Kept: exactly the points whose sampled path changes side of the cone or comes within
    the tolerance of it at a height in the band, up to the samples' resolution."""
    rng = np.random.default_rng(8)
    A, D = _segments(geom, rng, 400)
    keep = cone_reach.may_cross(geom, A, D, margin)
    s, z = _sampled(geom, A, D, np.zeros(len(A)), np.ones(len(A)))
    band = (z >= -margin) & (z <= geom.H + margin)
    step = np.linalg.norm(D, axis=1)[:, None] / (N_SAMPLES - 1)
    meets = band & (np.abs(s) <= cone_reach.REACH_TOL)
    meets[:, 1:] |= band[:, 1:] & band[:, :-1] & (np.sign(s[:, 1:]) != np.sign(s[:, :-1]))
    near = band & (np.abs(s) <= cone_reach.REACH_TOL + step)
    assert np.all(keep[meets.any(axis=1)])
    assert np.all(near.any(axis=1)[keep] | _band_edge(geom, A, D, margin, step)[keep])
    assert 0.1 < keep.mean() < 0.9
    assert keep[-4:].tolist() == [margin > 0.0] * 4        # crossing just outside 0 <= z <= H


def _band_edge(g, A, D, margin, step):
    """Paths that enter or leave the band within a sample of the cone (the samples may miss
    the band's end)."""
    out = np.zeros(len(A), dtype=bool)
    for edge in (-margin, g.H + margin):
        with np.errstate(divide="ignore", invalid="ignore"):
            f = (edge - A[:, 2]) / D[:, 2]
        ok = (f >= 0.0) & (f <= 1.0)
        s = pen.cone_distance(g, A + np.where(ok, f, 0.0)[:, None] * D)
        out |= ok & (np.abs(s) <= cone_reach.REACH_TOL + 2 * step[:, 0])
    return out
