"""The witness values the compiled engine computes per pair (`drake_dock.systems.witnesses`
names them): the hand-over guard of an edge pair, a point-curve pair's side, the domain-end
margin; and the far pairs' travel bounds and their witness (Sect. 5.1)."""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels.jets import jet
from drake_dock.core.kernels.model import (AFFINE, FAR, O_COND_MIN, O_EARLY, O_HORIZON,
                                           S_DUE,
                                           S_FAR,
                                           S_FAR_EARLY, Z_NV, Z_NX,
                                           layout, unpack_model, unpack_modes)
from drake_dock.core.kernels.jets import position

@njit(cache=True)
def rot_col(R, a0, a1, a2):
    return (R[0, 0] * a0 + R[0, 1] * a1 + R[0, 2] * a2,
            R[1, 0] * a0 + R[1, 1] * a1 + R[1, 2] * a2,
            R[2, 0] * a0 + R[2, 1] * a1 + R[2, 2] * a2)


@njit(cache=True, inline="always")
def handover_guard(m, i, row, R2):
    """Edge pair i's hand-over guard (`drake_dock.core.handover.edge_guard`): the least over
    its edges of n . b, b the surface's outward conormal at the edge point, Body 2 turned by
    R2; inf without edges."""
    g = math.inf
    e_par = row[K.U + 1]
    for e in range(m.edge_first[i], m.edge_first[i] + m.edge_count[i]):
        j = m.edge_surface[e]
        fixed, upper, kmap = m.edge_info[e, 0], m.edge_info[e, 1], m.edge_info[e, 2]
        if kmap == AFFINE:
            free = m.edge_map[e, 0] * e_par + m.edge_map[e, 1]
        else:
            pt = position(m.kind2[i], m.prm2[i], e_par, 0.0)
            free = pt[int(m.edge_map[e, 0])]
        # The surface pair's u = (u1, a0, a1): a's bounds in columns 1, 2.
        bound = m.upper[j, 1 + fixed] if upper else m.lower[j, 1 + fixed]
        a0, a1 = (bound, free) if fixed == 0 else (free, bound)
        _, T0, T1, _, _, _ = jet(m.kind2[j], m.prm2[j], a0, a1)
        t = T0 if fixed == 0 else T1
        s = rot_col(R2, t[0], t[1], t[2])
        norm = math.sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2])
        dot = row[K.N] * s[0] + row[K.N + 1] * s[1] + row[K.N + 2] * s[2]
        g = min(g, (dot if upper else -dot) / norm)
    return g


@njit(cache=True, inline="always")
def point_curve_side(m, i, row, R2):
    """A point-curve pair's side (`drake_dock.core.couple.point_curve_side`): the cosine
    between its normal and the curve's curvature direction, 1 where the curve is straight."""
    _, _, _, k, _, _ = jet(m.kind2[i], m.prm2[i], row[K.U], 0.0)
    kw = rot_col(R2, k[0], k[1], k[2])
    nk = math.sqrt(kw[0] * kw[0] + kw[1] * kw[1] + kw[2] * kw[2])
    if not nk > 0.0:
        return 1.0
    return (row[K.N] * kw[0] + row[K.N + 1] * kw[1] + row[K.N + 2] * kw[2]) / nk


@njit(cache=True)
def end_margin(m, i, row):
    """The smallest margin of pair i's bounded parameters to their domain's ends, relative to
    the span (inf when none is bounded)."""
    w = math.inf
    for j in range(m.uoff[i + 1] - m.uoff[i]):
        if m.bounded[i, j]:
            lo, hi = m.lower[i, j], m.upper[i, j]
            span = hi - lo
            w = min(w, min((row[K.U + j] - lo) / span, (hi - row[K.U + j]) / span))
    return w


@njit(cache=True, inline="always")
def end_margin_rate(m, i, row):
    """The rate (1/s) of `end_margin`: that of the margin it takes, from the couple's rate
    (Eq. 47, row UDOT); NaN when no parameter is bounded."""
    w, r = math.inf, math.nan
    for j in range(m.uoff[i + 1] - m.uoff[i]):
        if m.bounded[i, j]:
            lo, hi = m.lower[i, j], m.upper[i, j]
            span = hi - lo
            if (row[K.U + j] - lo) / span < w:
                w, r = (row[K.U + j] - lo) / span, row[K.UDOT + j] / span
            if (hi - row[K.U + j]) / span < w:
                w, r = (hi - row[K.U + j]) / span, -row[K.UDOT + j] / span
    return r


@njit(cache=True)
def regular_rates(mp, rows, pairs, slots, out):
    """Into ``out``: the rates of the regular witnesses (W_REGULAR, min(`end_margin`,
    conditioning - conditioning_min)) of ``pairs``, their couple rows at ``slots`` of an
    evaluation's ``rows`` (n_near, ROW): the end margin's rate where it is the least, NaN where
    the conditioning is (its rate is not computed)."""
    m = unpack_model(mp)
    for k in range(pairs.shape[0]):
        i, row = pairs[k], rows[slots[k]]
        if end_margin(m, i, row) <= row[K.COND] - m.options[O_COND_MIN]:
            out[k] = end_margin_rate(m, i, row)
        else:
            out[k] = math.nan


@njit(cache=True)
def witness_now(mp, wv, rows, flat, gap_pos, g_flat, gap_flat, regular_pos, regular_pair,
                regular_slot):
    """The armed pair witnesses' values w (the raveled witness values ``wv`` at ``flat``) and
    rates d, NaN where unknown: a tracked couple's gap witness (places ``gap_pos``; its gap and
    v_n in the raveled couple ``rows`` at ``g_flat``, ``gap_flat``) has g' = v_n while the gap
    is positive; the regular witnesses (places ``regular_pos``, pairs ``regular_pair``, rows
    at ``regular_slot``) have `regular_rates`. Also the places of the gap witnesses whose gap
    is at or below zero (their witness is v_n; its rate g'' is for the caller; a NaN gap is
    neither, its rate stays NaN). Returns (w, d, turning)."""
    n = flat.shape[0]
    w, d = np.empty(n), np.full(n, np.nan)
    for k in range(n):
        w[k] = wv[flat[k]]
    flat_rows = rows.ravel()
    turning = np.empty(gap_pos.shape[0], dtype=np.intp)
    nt = 0
    for m_ in range(gap_pos.shape[0]):
        g = flat_rows[g_flat[m_]]
        if g > 0.0:
            d[gap_pos[m_]] = flat_rows[gap_flat[m_]]
        elif g <= 0.0:
            turning[nt] = gap_pos[m_]
            nt += 1
    if regular_pos.shape[0]:
        rates = np.empty(regular_pos.shape[0])
        regular_rates(mp, rows, regular_pair, regular_slot, rates)
        for k in range(regular_pos.shape[0]):
            d[regular_pos[k]] = rates[k]
    return w, d, turning[:nt]


@njit(cache=True, inline="always")
def far_bounds(m, s, R, o, bound):
    """The far pairs' travel bound (Sect. 5.1; `drake_dock.systems.far_pairs`):
    |delta(X21 c1)| + |delta R21|_2 r1 since their last seek, inf for a pair never sought;
    NaN for pairs that are not far."""
    P = m.frame_pairs.shape[0]
    R21 = np.empty((P, 3, 3))
    p21 = np.empty((P, 3))
    for f in range(P):
        a, b = m.frame_pairs[f, 0], m.frame_pairs[f, 1]
        for r in range(3):
            for c in range(3):
                R21[f, r, c] = R[b, 0, r] * R[a, 0, c] + R[b, 1, r] * R[a, 1, c] \
                    + R[b, 2, r] * R[a, 2, c]
            p21[f, r] = R[b, 0, r] * (o[a, 0] - o[b, 0]) + R[b, 1, r] * (o[a, 1] - o[b, 1]) \
                + R[b, 2, r] * (o[a, 2] - o[b, 2])
    for i in range(s.code.shape[0]):
        if s.code[i] != FAR:
            bound[i] = math.nan
            continue
        if not s.sought[i]:
            bound[i] = math.inf
            continue
        f = m.frame_pair[i]
        lin2 = 0.0
        tr = 0.0
        for r in range(3):
            acc = p21[f, r] - s.p0[i, r]
            for c in range(3):
                acc += (R21[f, r, c] - s.R0[i, r, c]) * m.centre1[i, c]
                tr += s.R0[i, r, c] * R21[f, r, c]
            lin2 += acc * acc
        bound[i] = math.sqrt(lin2) + math.sqrt(max(3.0 - tr, 0.0)) * m.radius1[i]


@njit(cache=True, inline="always")
def bound_rate(m, i, R, o, w, vf):
    """An upper bound of the rate of far pair i's travel bound (`far_bounds`): the speed of
    its bounding sphere's centre relative to frame 2 plus the relative angular speed times
    its radius."""
    a, b = m.frame_pairs[m.frame_pair[i], 0], m.frame_pairs[m.frame_pair[i], 1]
    c = rot_col(R[a], m.centre1[i, 0], m.centre1[i, 1], m.centre1[i, 2])
    v2 = 0.0
    rot2 = 0.0
    for r in range(3):
        r1, r2 = (r + 1) % 3, (r + 2) % 3
        pa = w[a, r1] * c[r2] - w[a, r2] * c[r1]                         # w_a x (R_a c)
        d = (c[r1] + o[a, r1] - o[b, r1], c[r2] + o[a, r2] - o[b, r2])    # P1 - o_b
        pb = w[b, r1] * d[1] - w[b, r2] * d[0]                           # w_b x (P1 - o_b)
        v = vf[a, r] + pa - vf[b, r] - pb
        v2 += v * v
        dw = w[a, r] - w[b, r]
        rot2 += dw * dw
    return math.sqrt(v2) + math.sqrt(rot2) * m.radius1[i]


@njit(cache=True)
def due_in(m, s, i, R, o, w, vf, bound):
    """The time before far pair i (sought before) is due a seek at a step's start: (reseek_early
    clearance - bound) / (the bound's rate, `bound_rate`), 0 once its bound has reached
    reseek_early of its clearance, inf at rest."""
    left = m.options[O_EARLY] * s.clearance[i] - bound[i]
    if left <= 0.0:
        return 0.0
    rate = bound_rate(m, i, R, o, w, vf)
    return left / rate if rate > 0.0 else math.inf


@njit(cache=True)
def _far_views(m, s, buf):
    """The far pass's views of an evaluation's result buffer (`layout`): the travel bounds,
    the frames' rotations, origins, angular and linear velocities, and the scalars."""
    k, F, nbush = s.code.shape[0], m.frame_body.shape[0], m.bush_frames.shape[0]
    XD, OUT, LN, LT, GF, WV, BD, FR, FO, FW, FV, SC, BU, END = layout(
        m.sizes[Z_NX], k, m.sizes[Z_NV], F, nbush, s.near.shape[0])
    return (buf[BD:FR], buf[FR:FO].reshape((F, 3, 3)), buf[FO:FW].reshape((F, 3)),
            buf[FW:FV].reshape((F, 3)), buf[FV:SC].reshape((F, 3)), buf[SC:BU])


@njit(cache=True)
def far_witness(mp, sp, buf):
    """Into an evaluation's result buffer (`layout`): the far pairs' travel bounds (BOUND;
    NaN for the pairs not far), their witness, the smallest clearance left, min (clearance -
    bound) (1 if no pair is far; scalar S_FAR), whether a pair sought before is due a seek at
    this step's start, its `due_in` within the reseek horizon (S_DUE), and the time before the
    next of the others is (inf for none; S_FAR_EARLY). Asked by the witnesses and the step's
    start, not by every evaluation."""
    m = unpack_model(mp)
    s = unpack_modes(sp)
    k = s.code.shape[0]
    bound, R, o, w, vf, scalars = _far_views(m, s, buf)
    far_bounds(m, s, R, o, bound)
    wfar = math.inf
    lead = math.inf
    due = 0.0
    early, horizon = m.options[O_EARLY], m.options[O_HORIZON]
    for i in range(k):
        if s.code[i] == FAR:
            wfar = min(wfar, s.clearance[i] - bound[i])
            if s.sought[i] and early > 0.0:
                t_due = due_in(m, s, i, R, o, w, vf, bound)
                if t_due <= horizon:
                    due = 1.0
                else:
                    lead = min(lead, t_due)
    scalars[S_FAR] = 1.0 if wfar == math.inf else wfar
    scalars[S_FAR_EARLY] = lead
    scalars[S_DUE] = due


@njit(cache=True)
def due_far(mp, sp, buf):
    """The far pairs (ascending) due a seek at this step's start (`far_witness`'s S_DUE): those
    sought before whose `due_in` is within the reseek horizon, from an evaluation's result
    buffer with its far pass done."""
    m = unpack_model(mp)
    s = unpack_modes(sp)
    k = s.code.shape[0]
    bound, R, o, w, vf, scalars = _far_views(m, s, buf)
    out = np.empty(k, dtype=np.int64)
    n = 0
    if m.options[O_EARLY] > 0.0:
        for i in range(k):
            if s.code[i] == FAR and s.sought[i] and \
                    due_in(m, s, i, R, o, w, vf, bound) <= m.options[O_HORIZON]:
                out[n] = i
                n += 1
    return out[:n]
