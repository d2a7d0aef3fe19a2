"""Prescribed smooth rigid motions with closed-form twists and accelerations, for kinematics
tests."""
import math

import numpy as np

from drake_dock.docking.geometry.rotations import rot_x, rot_z


class Motion:
    """Pose R(t) = Rz(a(t)) Rx(b(t)) R0, p(t) = p0 + A sin(W t) + V t, with
    a = A_a sin(w_a t), b = A_b sin(w_b t)."""

    def __init__(self, R0=np.eye(3), p0=np.zeros(3), A=(0.0, 0.0, 0.0), W=(1.0, 1.0, 1.0),
                 V=(0.0, 0.0, 0.0), a=(0.0, 1.0), b=(0.0, 1.0)):
        self.R0, self.p0 = np.asarray(R0, float), np.asarray(p0, float)
        self.A, self.W, self.V = (np.asarray(x, float) for x in (A, W, V))
        self.a, self.b = a, b

    def _ang(self, c, t):
        A, w = c
        return A * math.sin(w * t), A * w * math.cos(w * t), -A * w * w * math.sin(w * t)

    def pose(self, t):
        a, _, _ = self._ang(self.a, t)
        b, _, _ = self._ang(self.b, t)
        R = rot_z(a) @ rot_x(b) @ self.R0
        p = self.p0 + self.A * np.sin(self.W * t) + self.V * t
        return R, p

    def twist(self, t):
        a, ad, _ = self._ang(self.a, t)
        _, bd, _ = self._ang(self.b, t)
        w = ad * np.array([0.0, 0.0, 1.0]) + bd * (rot_z(a) @ np.array([1.0, 0.0, 0.0]))
        v = self.A * self.W * np.cos(self.W * t) + self.V
        return w, v

    def acceleration(self, t, P):
        """Acceleration of the material point at world position P."""
        a, ad, add = self._ang(self.a, t)
        _, bd, bdd = self._ang(self.b, t)
        ez, ex = np.array([0.0, 0.0, 1.0]), rot_z(a) @ np.array([1.0, 0.0, 0.0])
        w = ad * ez + bd * ex
        alpha = add * ez + bdd * ex + bd * ad * np.cross(ez, ex)
        acc = -self.A * self.W ** 2 * np.sin(self.W * t)
        r = P - self.pose(t)[1]
        return acc + np.cross(alpha, r) + np.cross(w, np.cross(w, r))


def check_rates_by_finite_differences(ev_at, m1, m2, times=(0.2, 0.55, 0.9), h=1e-4):
    """For a couple evaluated along prescribed motions m1 (Body 1) and m2 (Body 2) by
    ``ev_at(t)`` (a `CoupleEval` at the closed-form couple): vn = g', u' = du/dt, g'' =
    n . (a1 - a2) + bias_n and (t . v_rel)' = t . (a1 - a2) + bias_t (the tangential velocity
    components of the material points, differentiated with the frame moving along the couple),
    by central differences."""
    for t in times:
        e0, ep, em = ev_at(t), ev_at(t + h), ev_at(t - h)
        fp, fm = ev_at(t + 1e-6), ev_at(t - 1e-6)
        np.testing.assert_allclose(e0.vn, (fp.gap - fm.gap) / 2e-6, atol=1e-8)
        np.testing.assert_allclose(e0.udot, (fp.u - fm.u) / 2e-6, atol=1e-8)
        gdd = (ep.gap - 2 * e0.gap + em.gap) / h ** 2
        acc = m1.acceleration(t, e0.p1) - m2.acceleration(t, e0.p2)
        np.testing.assert_allclose(e0.n @ acc + e0.bias_n, gdd, atol=1e-5)
        vt_dot = (ep.vt - em.vt) / (2 * h)
        np.testing.assert_allclose(np.array([e0.ta @ acc, e0.tb @ acc]) + e0.bias_t, vt_dot,
                                   atol=1e-6)
        np.testing.assert_allclose(e0.vt, [e0.ta @ e0.v_rel, e0.tb @ e0.v_rel], atol=1e-15)


class PosedMotion:
    """A rigid motion given by its pose function ``pose(t)`` -> (R, p), with the accelerations
    of its material points by second central differences (for `check_rates_by_finite_differences`
    where no closed form is at hand)."""

    def __init__(self, pose, h=1e-4):
        self.pose, self.h = pose, h

    def acceleration(self, t, P):
        R, p = self.pose(t)
        body = R.T @ (np.asarray(P) - p)          # the material point in the body frame

        def x(s):
            Rs, ps = self.pose(s)
            return ps + Rs @ body
        return (x(t + self.h) - 2 * x(t) + x(t - self.h)) / self.h ** 2
