"""The force elements and energies of free bodies in compiled code: uniform gravity and Drake's
LinearBushingRollPitchYaw (`bushing`), their generalized force, power and potential, each
bushing's damper power apart; M^-1 applied by blocks; the kinetic energy."""
from __future__ import annotations

import numpy as np
from numba import njit

from drake_dock.core.kernels.bushing import OK as BUSH_OK, bushing_coordinates, bushing_wrenches
from drake_dock.core.kernels.frames import frame_of
from drake_dock.core.kernels.free_bodies import mtv3, mv3

@njit(cache=True)
def element_forces(m, q, v, Rb, pb, R, o, w, vf, tau, bush, damp):
    """The generalized force of gravity and the bushings into tau (nv,), each bushing's
    deflection, angles and force on C into ``bush`` (nbush, BUSH_ROW) and its damper's
    generalized force dotted with v into ``damp`` (nbush,); returns (the potential energy:
    gravity, and 1/2 k x^2 + 1/2 k_t theta^2 of the bushings in their own coordinates; the
    first bushing status other than `bushing.OK`, e.g. at gimbal lock, or OK)."""
    tau[:] = 0.0
    pe = 0.0
    status = BUSH_OK
    g = m.gravity
    for b in range(m.qs.shape[0]):
        j = m.vs[b]
        mb = m.mass[b]
        c0 = Rb[b, 0, 0] * m.com[b, 0] + Rb[b, 0, 1] * m.com[b, 1] + Rb[b, 0, 2] * m.com[b, 2]
        c1 = Rb[b, 1, 0] * m.com[b, 0] + Rb[b, 1, 1] * m.com[b, 1] + Rb[b, 1, 2] * m.com[b, 2]
        c2 = Rb[b, 2, 0] * m.com[b, 0] + Rb[b, 2, 1] * m.com[b, 1] + Rb[b, 2, 2] * m.com[b, 2]
        f0, f1_, f2_ = mb * g[0], mb * g[1], mb * g[2]
        tau[j] += c1 * f2_ - c2 * f1_
        tau[j + 1] += c2 * f0 - c0 * f2_
        tau[j + 2] += c0 * f1_ - c1 * f0
        tau[j + 3] += f0
        tau[j + 4] += f1_
        tau[j + 5] += f2_
        pe -= f0 * (pb[b, 0] + c0) + f1_ * (pb[b, 1] + c1) + f2_ * (pb[b, 2] + c2)
    W = np.empty((4, 6))                    # F_C, F_A and their damping parts
    FC, FA, FCd, FAd = W[0], W[1], W[2], W[3]
    td = np.zeros(v.shape[0])
    for n in range(m.bush_frames.shape[0]):
        a, c = m.bush_frames[n, 0], m.bush_frames[n, 1]
        G = m.bush_gains[n]
        A, C = frame_of(a, R, o, w, vf), frame_of(c, R, o, w, vf)
        st = bushing_wrenches(A, C, G, W)
        bushing_coordinates(A, C, bush[n, 0:3], bush[n, 3:6])
        if st != BUSH_OK and status == BUSH_OK:
            status = st
        for j in range(3):
            pe += 0.5 * G[2, j] * bush[n, j] ** 2 + 0.5 * G[0, j] * bush[n, 3 + j] ** 2
        for k in range(6):
            bush[n, 6 + k] = FC[k]
        td[:] = 0.0
        for f, F, Fd in ((c, FC, FCd), (a, FA, FAd)):
            b = m.frame_body[f]
            if b < 0:
                continue
            j = m.vs[b]
            r0, r1, r2 = o[f, 0] - pb[b, 0], o[f, 1] - pb[b, 1], o[f, 2] - pb[b, 2]
            tau[j] += F[0] + r1 * F[5] - r2 * F[4]
            tau[j + 1] += F[1] + r2 * F[3] - r0 * F[5]
            tau[j + 2] += F[2] + r0 * F[4] - r1 * F[3]
            tau[j + 3] += F[3]
            tau[j + 4] += F[4]
            tau[j + 5] += F[5]
            td[j] += Fd[0] + r1 * Fd[5] - r2 * Fd[4]
            td[j + 1] += Fd[1] + r2 * Fd[3] - r0 * Fd[5]
            td[j + 2] += Fd[2] + r0 * Fd[4] - r1 * Fd[3]
            td[j + 3] += Fd[3]
            td[j + 4] += Fd[4]
            td[j + 5] += Fd[5]
        p = 0.0
        for k in range(v.shape[0]):
            p += td[k] * v[k]
        damp[n] = p
    return pe, status


@njit(cache=True)
def block_apply(vs, A, x):
    """A x for A block diagonal in the bodies' 6x6 blocks (M^-1)."""
    y = np.zeros(x.shape[0])
    for b in range(vs.shape[0]):
        j = vs[b]
        for r in range(6):
            acc = 0.0
            for c in range(6):
                acc += A[j + r, j + c] * x[j + c]
            y[j + r] = acc
    return y


@njit(cache=True)
def kinetic_energy(m, Rb, wb, vb):
    """1/2 v^T M v of the free bodies: 1/2 m |v_c|^2 + 1/2 w . I w per body (v_c the centre of
    mass's velocity, I its inertia about it in the world frame)."""
    ke = 0.0
    for b in range(m.qs.shape[0]):
        R = Rb[b]
        c = mv3(R, m.com[b])
        w = wb[b]
        vc0 = vb[b, 0] + w[1] * c[2] - w[2] * c[1]
        vc1 = vb[b, 1] + w[2] * c[0] - w[0] * c[2]
        vc2 = vb[b, 2] + w[0] * c[1] - w[1] * c[0]
        wB = mtv3(R, w)
        Iw = mv3(m.inertia[b], wB)
        ke += 0.5 * m.mass[b] * (vc0 * vc0 + vc1 * vc1 + vc2 * vc2) \
            + 0.5 * (wB[0] * Iw[0] + wB[1] * Iw[1] + wB[2] * Iw[2])
    return ke
