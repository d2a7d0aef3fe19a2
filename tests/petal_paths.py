"""Points of a petal's guide surface and paths of a single point of the chaser, written from the
paper's equations (Eq. 12-14) for the interpenetration checks' tests
(tests/docking/test_penetration.py, tests/docking/test_mesh_check.py)."""
import math

import numpy as np


def cone_point(g, k, s, zeta):
    """The point of petal k's guide surface at fraction s across the petal and height zeta, and
    the cone's outward unit normal there (Eq. 12 and 13 written out here)."""
    rho = g.R - zeta / math.tan(g.alpha1)
    inset = math.asin(g.R * math.sin(g.alpha2) / rho) - g.alpha2
    th = (2 * k - 2) * math.pi / 3 + inset + s * (math.pi / 3 - 2 * inset)
    e_rho = np.array([math.cos(th), math.sin(th), 0.0])
    x = rho * e_rho + np.array([0.0, 0.0, zeta])
    n = math.sin(g.alpha1) * e_rho + np.array([0.0, 0.0, math.cos(g.alpha1)])
    return x, n


def one_point_path(points):
    """A one-point feature of the chaser, its APDS frame the target's translated along the
    points (one sample per point, 1 ms apart): (t, R_WA, p_WA)."""
    n = len(points)
    p_WA = np.zeros((n, 2, 3))
    p_WA[:, 1] = points
    R_WA = np.broadcast_to(np.eye(3), (n, 2, 3, 3)).copy()
    return np.arange(n) * 1e-3, R_WA, p_WA


def near_side(g, delta, zeta=0.1):
    """The point of petal 1's guide surface delta (m) in from guide side 1 at height zeta, and
    the cone's outward normal there: guide side 1 (Eq. 14) at zeta, moved delta along the
    surface at right angles to the side (the side's tangent from two points of Eq. 14), towards
    the middle of the petal, and back onto the cone."""
    A, tan1 = g.R * math.sin(g.alpha2), math.tan(g.alpha1)

    def side(rho):                                 # Eq. (14), i = 1, at radius rho
        th = math.asin(A / rho) - g.alpha2
        return np.array([rho * math.cos(th), rho * math.sin(th), (g.R - rho) * tan1])

    rho = g.R - zeta / tan1
    x = side(rho)
    tangent = side(rho - 1e-6) - side(rho + 1e-6)
    n = math.sin(g.alpha1) * np.array([x[0], x[1], 0.0]) / rho + [0.0, 0.0, math.cos(g.alpha1)]
    inward = np.cross(n, tangent)
    inward /= np.linalg.norm(inward)
    if inward @ (cone_point(g, 1, 0.5, zeta)[0] - x) < 0.0:
        inward = -inward
    y = x + delta * inward
    e = np.array([y[0], y[1], 0.0]) / math.hypot(y[0], y[1])
    n = math.sin(g.alpha1) * e + [0.0, 0.0, math.cos(g.alpha1)]
    off = (math.hypot(y[0], y[1]) - g.R) * math.sin(g.alpha1) + y[2] * math.cos(g.alpha1)
    return y - off * n, n                          # back onto the cone (Eq. 12)
