"""Free rigid bodies in compiled code: the kinematics, the mass matrix's inverse, the velocity-
product (gyroscopic) terms and the contact rows of a set of bodies that each move freely (six
degrees of freedom, no joint between them), over plain arrays.

Layout (Drake's quaternion floating joint, which the tests compare with): body b's positions
are q[qs[b]:qs[b] + 7] = (quaternion w, x, y, z; origin p_WBo) and its velocities
v[vs[b]:vs[b] + 6] = (w_WB, v_WBo), both expressed in the world frame. Its mass m[b], its
centre of mass c_B[b] (body frame) and its rotational inertia about the centre of mass
I_B[b] (body frame; its inverse I_B_inv[b]). A frame f is fixed on body fb[f] (-1: the world)
at the pose (R_BF[f], p_BF[f]).

With c = R c_B and I = R I_B R^T in the world frame and [c] the cross-product matrix, the
mass matrix of a body about its origin is M = [[I - m [c][c], m [c]], [-m [c], m 1]] and its
inverse M^-1 = [[I^-1, -I^-1 [c]], [[c] I^-1, 1/m - [c] I^-1 [c]]] (the Schur complement of
m 1 is the inertia about the centre of mass). The velocity-product terms are the Newton-Euler
equations' at zero acceleration: torque w x I w + m c x (w x (w x c)) about the origin and
force m w x (w x c).
"""
from __future__ import annotations

import numpy as np
from numba import njit
from drake_dock.core.kernels.copies import copy1, copy2


@njit(cache=True)
def rotation(q0, q1, q2, q3):
    """The rotation matrix of the quaternion (w, x, y, z), normalised as Drake does (2 / |q|^2)."""
    s = 2.0 / (q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    R = np.empty((3, 3))
    R[0, 0] = 1.0 - s * (q2 * q2 + q3 * q3)
    R[0, 1] = s * (q1 * q2 - q0 * q3)
    R[0, 2] = s * (q1 * q3 + q0 * q2)
    R[1, 0] = s * (q1 * q2 + q0 * q3)
    R[1, 1] = 1.0 - s * (q1 * q1 + q3 * q3)
    R[1, 2] = s * (q2 * q3 - q0 * q1)
    R[2, 0] = s * (q1 * q3 - q0 * q2)
    R[2, 1] = s * (q2 * q3 + q0 * q1)
    R[2, 2] = 1.0 - s * (q1 * q1 + q2 * q2)
    return R


@njit(cache=True)
def mm3(A, B):
    """A B of 3x3 matrices (loops: small products called through BLAS cost more than they
    compute)."""
    C = np.empty((3, 3))
    for r in range(3):
        for c in range(3):
            C[r, c] = A[r, 0] * B[0, c] + A[r, 1] * B[1, c] + A[r, 2] * B[2, c]
    return C


@njit(cache=True)
def mmt3(A, B):
    """A B^T of 3x3 matrices."""
    C = np.empty((3, 3))
    for r in range(3):
        for c in range(3):
            C[r, c] = A[r, 0] * B[c, 0] + A[r, 1] * B[c, 1] + A[r, 2] * B[c, 2]
    return C


@njit(cache=True)
def mv3(A, x):
    """A x of a 3x3 matrix and a 3-vector."""
    y = np.empty(3)
    for r in range(3):
        y[r] = A[r, 0] * x[0] + A[r, 1] * x[1] + A[r, 2] * x[2]
    return y


@njit(cache=True, inline="always")
def mtv3(A, x):
    """A^T x of a 3x3 matrix and a 3-vector."""
    y = np.empty(3)
    for r in range(3):
        y[r] = A[0, r] * x[0] + A[1, r] * x[1] + A[2, r] * x[2]
    return y


@njit(cache=True)
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
def body_kinematics(qs, vs, q, v, Rb, pb, wb, vb):
    """The bodies' world rotations Rb (nb, 3, 3), origins pb, angular velocities wb and origin
    velocities vb (nb, 3)."""
    for b in range(qs.shape[0]):
        i, j = qs[b], vs[b]
        copy2(Rb[b], rotation(q[i], q[i + 1], q[i + 2], q[i + 3]))
        for c in range(3):
            pb[b, c] = q[i + 4 + c]
            wb[b, c] = v[j + c]
            vb[b, c] = v[j + 3 + c]


@njit(cache=True)
def frame_kinematics(fb, R_BF, p_BF, Rb, pb, wb, vb, R, o, w, vf):
    """The frames' world rotations R (F, 3, 3), origins o, and twists w, vf (F, 3)."""
    r = np.empty(3)
    wr = np.empty(3)
    for f in range(fb.shape[0]):
        b = fb[f]
        if b < 0:
            copy2(R[f], R_BF[f])
            copy1(o[f], p_BF[f])
            w[f] = 0.0
            vf[f] = 0.0
            continue
        copy2(R[f], mm3(Rb[b], R_BF[f]))
        for c in range(3):
            r[c] = Rb[b, c, 0] * p_BF[f, 0] + Rb[b, c, 1] * p_BF[f, 1] + Rb[b, c, 2] * p_BF[f, 2]
        _cross(wb[b], r, wr)
        for c in range(3):
            o[f, c] = pb[b, c] + r[c]
            w[f, c] = wb[b, c]
            vf[f, c] = vb[b, c] + wr[c]


@njit(cache=True, inline="always")
def qdot(qs, vs, q, v, out):
    """q' for v: the quaternion's rate 1/2 (0, w) (x) q, the origin's v_WBo."""
    for b in range(qs.shape[0]):
        i, j = qs[b], vs[b]
        a0, a1, a2, a3 = q[i], q[i + 1], q[i + 2], q[i + 3]
        w0, w1, w2 = v[j], v[j + 1], v[j + 2]
        out[i] = 0.5 * (-w0 * a1 - w1 * a2 - w2 * a3)
        out[i + 1] = 0.5 * (w0 * a0 + w1 * a3 - w2 * a2)
        out[i + 2] = 0.5 * (-w0 * a3 + w1 * a0 + w2 * a1)
        out[i + 3] = 0.5 * (w0 * a2 - w1 * a1 + w2 * a0)
        for c in range(3):
            out[i + 4 + c] = v[j + 3 + c]


@njit(cache=True)
def mass_inverse_and_bias(vs, m, c_B, I_B_inv, I_B, Rb, wb, Minv, bias):
    """M^-1 (nv, nv; block diagonal, see the module docstring) and the velocity-product terms
    C(q, v) v (nv,). Entries of Minv outside the bodies' blocks are left as they are."""
    for b in range(vs.shape[0]):
        j = vs[b]
        R = Rb[b]
        c = mv3(R, c_B[b])
        Ii = mmt3(mm3(R, I_B_inv[b]), R)
        Iw = mmt3(mm3(R, I_B[b]), R)
        X = np.zeros((3, 3))            # [c]
        X[0, 1], X[0, 2], X[1, 2] = -c[2], c[1], -c[0]
        X[1, 0], X[2, 0], X[2, 1] = c[2], -c[1], c[0]
        IiX = mm3(Ii, X)
        XIi = mm3(X, Ii)
        XIiX = mm3(X, IiX)
        for r in range(3):
            for k in range(3):
                Minv[j + r, j + k] = Ii[r, k]
                Minv[j + r, j + 3 + k] = -IiX[r, k]
                Minv[j + 3 + r, j + k] = XIi[r, k]
                Minv[j + 3 + r, j + 3 + k] = (1.0 / m[b] if r == k else 0.0) - XIiX[r, k]
        w = wb[b]
        Icw = mv3(Iw, w)
        t = np.empty(3)
        wc = np.empty(3)
        wwc = np.empty(3)
        cwwc = np.empty(3)
        _cross(w, Icw, t)
        _cross(w, c, wc)
        _cross(w, wc, wwc)
        _cross(c, wwc, cwwc)
        for k in range(3):
            bias[j + k] = t[k] + m[b] * cwwc[k]
            bias[j + 3 + k] = m[b] * wwc[k]


@njit(cache=True)
def point_rows(vs, pb, wb, body1, body2, p1, p2, D, W, acc):
    """One contact row: W (nv, 3) the columns D^T J of Eq. (11) for the relative velocity of the
    points p1 (on body1) and p2 (on body2), world positions, with D (3, 3) the rows n, ta, tb,
    and acc (3,) = D (the relative bias acceleration w x (w x r)). A body -1 (the world)
    contributes nothing. W is overwritten."""
    W[:] = 0.0
    acc[:] = 0.0
    r = np.empty(3)
    wr = np.empty(3)
    wwr = np.empty(3)
    rd = np.empty(3)
    a = np.zeros(3)
    for side in range(2):
        b = body1 if side == 0 else body2
        if b < 0:
            continue
        sign = 1.0 if side == 0 else -1.0
        p = p1 if side == 0 else p2
        for k in range(3):
            r[k] = p[k] - pb[b, k]
        _cross(wb[b], r, wr)
        _cross(wb[b], wr, wwr)
        for k in range(3):
            a[k] += sign * wwr[k]
        j = vs[b]
        for col in range(3):
            _cross(r, D[col], rd)
            for k in range(3):
                W[j + k, col] += sign * rd[k]
                W[j + 3 + k, col] += sign * D[col, k]
    for col in range(3):
        acc[col] = D[col, 0] * a[0] + D[col, 1] * a[1] + D[col, 2] * a[2]


@njit(cache=True)
def mass_matrix(vs, m, c_B, I_B, Rb, M):
    """M (nv, nv; block diagonal, see the module docstring): [[I - m [c][c], m [c]],
    [-m [c], m 1]] per body, I = R I_B R^T about the centre of mass, c = R c_B. Entries
    outside the bodies' blocks are left as they are."""
    for b in range(vs.shape[0]):
        j = vs[b]
        R = Rb[b]
        c = mv3(R, c_B[b])
        Iw = mmt3(mm3(R, I_B[b]), R)
        X = np.zeros((3, 3))            # [c]
        X[0, 1], X[0, 2], X[1, 2] = -c[2], c[1], -c[0]
        X[1, 0], X[2, 0], X[2, 1] = c[2], -c[1], c[0]
        XX = mm3(X, X)
        for r in range(3):
            for k in range(3):
                M[j + r, j + k] = Iw[r, k] - m[b] * XX[r, k]
                M[j + r, j + 3 + k] = m[b] * X[r, k]
                M[j + 3 + r, j + k] = -m[b] * X[r, k]
                M[j + 3 + r, j + 3 + k] = m[b] if r == k else 0.0


@njit(cache=True)
def frame_poses(qs, q, fb, R_BF, p_BF, R, o):
    """The world rotations R (F, 3, 3) and origins o (F, 3) of the frames fixed on the bodies
    (layout of the module docstring) at the positions q."""
    for f in range(fb.shape[0]):
        b = fb[f]
        if b < 0:
            copy2(R[f], R_BF[f])
            copy1(o[f], p_BF[f])
            continue
        i = qs[b]
        Rb = rotation(q[i], q[i + 1], q[i + 2], q[i + 3])
        copy2(R[f], mm3(Rb, R_BF[f]))
        for c in range(3):
            o[f, c] = q[i + 4 + c] + Rb[c, 0] * p_BF[f, 0] + Rb[c, 1] * p_BF[f, 1] \
                + Rb[c, 2] * p_BF[f, 2]


def warm():
    """Compiles or loads `frame_poses` (the ring frames of a docking run's capture test)."""
    q = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    frame_poses(np.zeros(1, dtype=np.int64), q, np.zeros(2, dtype=np.int64),
                np.tile(np.eye(3), (2, 1, 1)), np.zeros((2, 3)), np.empty((2, 3, 3)),
                np.empty((2, 3)))
