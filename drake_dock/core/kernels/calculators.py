"""The compiled engine's calculators for events and outputs: the bodies' and frames'
kinematics, the couples of chosen pairs, one couple's contact row (Eq. 11, 52), M, M^-1 and
the free acceleration, the far pairs' points and the couple output table of every pair."""
from __future__ import annotations

import numpy as np
from numba import njit

from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels.copies import copy1, copy2
from drake_dock.core.kernels.engine import couple_rates, pair_couple
from drake_dock.core.kernels.forces import block_apply, element_forces, kinetic_energy
from drake_dock.core.kernels.free_bodies import (body_kinematics, frame_kinematics,
                                                 mass_inverse_and_bias, mass_matrix,
                                                 point_rows)
from drake_dock.core.kernels.jets import position
from drake_dock.core.kernels.model import (BUSH_ROW, CS, FAR, PC, PS, Z_NQ, Z_NV, Z_NX,
                                           layout, unpack_model, unpack_modes)
from drake_dock.core.kernels.witness_values import rot_col

@njit(cache=True)
def kinematics(mp, q, v, Rb, pb, wb, vb, R, o, w, vf):
    """The bodies' and the frames' poses and twists at (q, v) (`free_bodies`)."""
    m = unpack_model(mp)
    body_kinematics(m.qs, m.vs, q, v, Rb, pb, wb, vb)
    frame_kinematics(m.frame_body, m.R_BF, m.p_BF, Rb, pb, wb, vb, R, o, w, vf)


@njit(cache=True)
def couples_at(mp, R, o, w, vf, u, sigma, which, project, drift_feedback, out):
    """The couples u (the layout of u*) of the pairs ``which`` with orientations sigma (per
    pair) into their rows of ``out`` (k, couples.ROW), projected (one Newton step) when
    ``project``; a point-curve couple whose point lies on its curve leaves its gap NaN."""
    m = unpack_model(mp)
    rate = np.zeros(u.shape[0])
    for i in which:
        row = out[i]
        pair_couple(m, i, R, o, w, vf, u, sigma[i], project, row)
        couple_rates(m, i, row, drift_feedback, rate)


@njit(cache=True)
def contact_row(mp, i, row, pb, wb, W, bias):
    """Pair i's row W (nv, 3) = the columns W^3, W^1, W^2 of Eq. (11) (along n, ta, tb) and
    its bias terms (3,) (Eq. 52) from its couple's row and the bodies' origins and angular
    velocities."""
    m = unpack_model(mp)
    D = np.empty((3, 3))
    acc = np.empty(3)
    for c in range(3):
        D[0, c], D[1, c], D[2, c] = row[K.N + c], row[K.TA + c], row[K.TB + c]
    a, b = m.fidx[i, 0], m.fidx[i, 1]
    Wt = np.empty((W.shape[0], 3))
    point_rows(m.vs, pb, wb, m.frame_body[a], m.frame_body[b], row[K.P1:K.P1 + 3],
               row[K.P2:K.P2 + 3], D, Wt, acc)
    copy2(W, Wt)
    bias[0] = row[K.BIAS_N] + acc[0]
    bias[1] = row[K.BIAS_T] + acc[1]
    bias[2] = row[K.BIAS_T + 1] + acc[2]


@njit(cache=True)
def dynamics_at(mp, q, v, tau_in, M, Minv, a0, scal):
    """M, M^-1 (nv, nv), the free acceleration a0 = M^-1 (tau_el + tau_in - C v), and into
    ``scal`` the power of the force elements and of the inputs and the kinetic and potential
    energy."""
    m = unpack_model(mp)
    nb, F, nv = m.qs.shape[0], m.frame_body.shape[0], v.shape[0]
    Rb, pb = np.empty((nb, 3, 3)), np.empty((nb, 3))
    wb, vb = np.empty((nb, 3)), np.empty((nb, 3))
    R, o, w, vf = np.empty((F, 3, 3)), np.empty((F, 3)), np.empty((F, 3)), np.empty((F, 3))
    body_kinematics(m.qs, m.vs, q, v, Rb, pb, wb, vb)
    frame_kinematics(m.frame_body, m.R_BF, m.p_BF, Rb, pb, wb, vb, R, o, w, vf)
    tau_el = np.empty(nv)
    nbush = m.bush_frames.shape[0]
    bush = np.empty((nbush, BUSH_ROW))
    damp = np.empty(nbush)
    pe, _ = element_forces(m, q, v, Rb, pb, R, o, w, vf, tau_el, bush, damp)
    M[:] = 0.0
    Minv[:] = 0.0
    mass_matrix(m.vs, m.mass, m.com, m.inertia, Rb, M)
    cv = np.zeros(nv)
    mass_inverse_and_bias(m.vs, m.mass, m.com, m.inertia_inv, m.inertia, Rb, wb, Minv, cv)
    copy1(a0, block_apply(m.vs, Minv, tau_el + tau_in - cv))
    p_el, p_in = 0.0, 0.0
    for a in range(nv):
        p_el += tau_el[a] * v[a]
        p_in += tau_in[a] * v[a]
    scal[0], scal[1], scal[2], scal[3] = p_el, p_in, kinetic_energy(m, Rb, wb, vb), pe


@njit(cache=True)
def mass_at(mp, Rb, M):
    """M (nv, nv) at the bodies' rotations Rb."""
    m = unpack_model(mp)
    M[:] = 0.0
    mass_matrix(m.vs, m.mass, m.com, m.inertia, Rb, M)


@njit(cache=True)
def _far_point(m, i, x, R, o):
    """Far pair i's world points at its couple in x (u* as last sought): each patch's point
    at its parameters (a point pair's patch 1 is its point)."""
    base = m.sizes[Z_NQ] + m.sizes[Z_NV]
    a, b = m.fidx[i, 0], m.fidx[i, 1]
    u = x[base + m.uoff[i]:base + m.uoff[i + 1]]
    kind = m.pair_kind[i]
    if kind == PC or kind == PS:
        r1 = (m.prm1[i, 0], m.prm1[i, 1], m.prm1[i, 2])
        r2 = position(m.kind2[i], m.prm2[i], u[0], u[1] if kind == PS else 0.0)
    else:
        r1 = position(m.kind1[i], m.prm1[i], u[0], 0.0)
        r2 = position(m.kind2[i], m.prm2[i], u[1], u[2] if kind == CS else 0.0)
    q1 = rot_col(R[a], r1[0], r1[1], r1[2])
    q2 = rot_col(R[b], r2[0], r2[1], r2[2])
    return ((q1[0] + o[a, 0], q1[1] + o[a, 1], q1[2] + o[a, 2]),
            (q2[0] + o[b, 0], q2[1] + o[b, 1], q2[2] + o[b, 2]))


@njit(cache=True)
def far_points(mp, which, x, R, o, p1, p2):
    """The world points of the far pairs ``which`` (`_far_point`) into p1, p2 (len(which),
    3)."""
    m = unpack_model(mp)
    for n in range(which.shape[0]):
        a, b = _far_point(m, which[n], x, R, o)
        for c in range(3):
            p1[n, c], p2[n, c] = a[c], b[c]


@njit(cache=True)
def couple_table(mp, sp, x, buf, cols, Y):
    """The couple outputs of every pair into Y (k, width) from an evaluation's result buffer
    (its far pass done, `far_witness`), at the columns ``cols`` (the starts of status, gap,
    vn, lambda_n, lambda_t, vt, u, p1, p2 and frame; `drake_dock.systems.contact_types.
    COUPLE_FIELDS`): a pair not far its couple's row, its mode as status and its frame's
    columns (ta, tb, n) row by row; a far pair status 0, its distance at the last seek less
    its travel bound as gap, u* as last sought and its points there, the identity frame."""
    m = unpack_model(mp)
    s = unpack_modes(sp)
    k, F, nbush = s.code.shape[0], m.frame_body.shape[0], m.bush_frames.shape[0]
    nn = s.near.shape[0]
    XD, OUT, LN, LT, GF, WV, BD, FR, FO, FW, FV, SC, BU, END = layout(
        m.sizes[Z_NX], k, m.sizes[Z_NV], F, nbush, nn)
    out = buf[OUT:LN].reshape((nn, K.ROW))
    lam_n, lam_t = buf[LN:LT], buf[LT:GF].reshape((k, 2))
    bound = buf[BD:FR]
    R, o = buf[FR:FO].reshape((F, 3, 3)), buf[FO:FW].reshape((F, 3))
    ST, GP, VN, LNc, LTc, VTc, Uc, P1c, P2c, FRc = cols[0], cols[1], cols[2], cols[3], \
        cols[4], cols[5], cols[6], cols[7], cols[8], cols[9]
    base = m.sizes[Z_NQ] + m.sizes[Z_NV]
    Y[:] = 0.0
    for i in range(k):
        y = Y[i]
        dims = m.uoff[i + 1] - m.uoff[i]
        if s.code[i] != FAR:
            row = out[s.slot[i]]
            y[ST] = s.code[i]
            y[GP], y[VN] = row[K.GAP], row[K.VN]
            y[LNc], y[LTc], y[LTc + 1] = lam_n[i], lam_t[i, 0], lam_t[i, 1]
            y[VTc], y[VTc + 1] = row[K.VT], row[K.VT + 1]
            for j in range(dims):
                y[Uc + j] = row[K.U + j]
            for c in range(3):
                y[P1c + c], y[P2c + c] = row[K.P1 + c], row[K.P2 + c]
                y[FRc + 3 * c] = row[K.TA + c]
                y[FRc + 3 * c + 1] = row[K.TB + c]
                y[FRc + 3 * c + 2] = row[K.N + c]
        else:
            y[GP] = s.distance[i] - bound[i]
            for j in range(dims):
                y[Uc + j] = x[base + m.uoff[i] + j]
            q1, q2 = _far_point(m, i, x, R, o)
            for c in range(3):
                y[P1c + c], y[P2c + c] = q1[c], q2[c]
                y[FRc + 4 * c] = 1.0


def warm():
    """Compiles or loads the calculators on `engine.toy_model`."""
    from drake_dock.core.kernels.engine import toy_model
    from drake_dock.core.kernels.model import NW
    from drake_dock.core.kernels.records import pack
    m, s, x = toy_model()
    mp, sp = pack(m), pack(s)
    nq, nv = int(m.sizes[Z_NQ]), int(m.sizes[Z_NV])
    nb, F, k = m.qs.shape[0], m.frame_body.shape[0], s.code.shape[0]
    q, v = x[:nq], x[nq:nq + nv]
    Rb, pb, wb, vb = np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3)), np.empty((nb, 3))
    R, o, w, vf = np.empty((F, 3, 3)), np.empty((F, 3)), np.empty((F, 3)), np.empty((F, 3))
    kinematics(mp, q, v, Rb, pb, wb, vb, R, o, w, vf)
    out = np.zeros((k, K.ROW))
    u = x[nq + nv:int(m.sizes[2]) + nq + nv]
    couples_at(mp, R, o, w, vf, u.copy(), s.sigma.copy(), np.arange(k, dtype=np.int64),
               np.bool_(True), 0.0, out)
    contact_row(mp, 0, out[0], pb, wb, np.empty((nv, 3)), np.empty(3))
    M, Minv, a0, scal = np.empty((nv, nv)), np.empty((nv, nv)), np.empty(nv), np.empty(4)
    dynamics_at(mp, q, v, np.zeros(nv), M, Minv, a0, scal)
    mass_at(mp, Rb, M)
    far = np.array([3], dtype=np.int64)
    far_points(mp, far, x, R, o, np.empty((1, 3)), np.empty((1, 3)))
    buf = np.zeros(layout(int(m.sizes[Z_NX]), k, nv, F, m.bush_frames.shape[0],
                          s.near.shape[0])[-1])
    del NW
    couple_table(mp, sp, x, buf, np.arange(10, dtype=np.int64), np.empty((k, 26)))
