"""Two couples along prescribed smooth motions, shared by the couple tests (tests/core) and the
scene tests (tests/docking): a ring outside a guide surface (C-S) and two facing guide sides
(C-C)."""
import numpy as np

from drake_dock.core.couple import closest_point_conditions
from drake_dock.docking.geometry.apds import apds_patches
from motions import Motion


def settle(kind, c1, X1, c2, X2, u, iters=20):
    """The couple u finished by Newton on the contact form (Eq. 37-38) at the poses X_i."""
    u = np.asarray(u, dtype=float)
    for _ in range(iters):
        F, Fu = closest_point_conditions(kind, c1, X1, c2, X2, u)
        u = u - np.linalg.solve(Fu, F)
        if np.abs(F).max() < 1e-15:
            break
    return u


def cs_scene(geom, gap=0.02):
    """A ring (Circle R) placed outside guide surface 1 of an APDS, touching it tangentially
    at the surface's middle from a distance ``gap``, both bodies moving."""
    P = apds_patches(geom)
    surf, ring = P.surfaces[1], P.ring
    u2 = np.array([0.5, 0.5 * geom.H])
    S = surf.position(u2)
    Tu = surf.first(u2)
    n = np.cross(Tu[:, 0], Tu[:, 1])
    n /= np.linalg.norm(n)
    if n @ S < 0:  # outward from the axis
        n = -n
    t_gen = Tu[:, 1] - (Tu[:, 1] @ n) * n
    t_gen /= np.linalg.norm(t_gen)
    # Ring frame: its plane spanned by n and t_gen; its lowest point (angle -pi/2 about the
    # frame's x = t_gen) at S + gap n.
    e1, e2 = t_gen, n
    e3 = np.cross(e1, e2)
    R0 = np.column_stack([e1, e2, e3])
    p0 = S + gap * n + ring.radius * n
    m1 = Motion(R0, p0, A=(0.004, 0.003, 0.002), W=(1.3, 0.9, 1.7), a=(0.01, 1.1),
                b=(0.008, 0.7))
    m2 = Motion(A=(0.002, -0.001, 0.003), W=(0.8, 1.4, 0.6), a=(0.012, 0.5), b=(0.006, 1.2))
    return "CS", ring, m1, surf, m2


def cc_scene(geom):
    """Target side 2 fixed-ish, chaser side 4 of the matched facing, approaching."""
    from drake_dock.docking.geometry.pairs import R_MATCHED
    P = apds_patches(geom)
    m1 = Motion(R_MATCHED, [0.0, 0.0, 0.12], A=(0.02, 0.01, 0.02), W=(1.0, 0.7, 0.5),
                V=(0, 0.01, -0.04), a=(0.08, 1.3), b=(0.05, 0.7))
    m2 = Motion(A=(0.003, 0.002, -0.002), W=(1.1, 0.9, 1.5), a=(0.01, 0.8))
    return "CC", P.sides[4], m1, P.sides[2], m2
