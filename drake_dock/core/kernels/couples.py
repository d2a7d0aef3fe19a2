"""The kinematics of one couple of two moving patches (Sect. 5 and 7 of the paper), compiled,
by pair kind: curve-curve ("CC") and curve-surface ("CS", `evaluate_one`), point-curve ("PC",
`evaluate_pc_one`) and point-surface ("PS", `evaluate_ps_one`), the model of each in
`drake_dock.core.couple`. Each evaluates the closest-point conditions in contact form (Eq. 37-38),
one Newton projection of the integrated couple, Eq. (47) for u*', the contact frame
(Definition 2), the gap, the relative velocity (Eq. 23-25) and the velocity-product terms of
Eq. (52) into one row, its fields at the offsets below (`ROW`). `conditions` gives F, its
Jacobian Fu (Eq. 40) and their conditioning at a couple without projecting it.

The patches are kernel descriptions (`drake_dock.core.kernels.jets`), a point by its frame's
coordinates and radius; each patch's frame comes as a `frames.Frame` record (its rotation an array,
its origin and twist 3-tuples), points as 3-tuples.
"""
from __future__ import annotations

import math

from numba import njit

from drake_dock.core.kernels.frames import (Frame, add as _add, axpy as _axpy, cross as _cr,
                                             dot as _dot, frame_rates_cc, frame_rates_cs,
                                             frame_rates_pc, mul as _mul, sub as _sub)
from drake_dock.core.kernels.jets import jet

# Row layout: u (3), drift (3), udot (3), residual, conditioning, p1 (3), p2 (3), n (3),
# ta (3), tb (3), gap, v_rel (3), vn, vt (2), bias_n, bias_t (2), max |drift| / span, and the
# integrated rate u*' = udot + drift_feedback * drift (3).
U, DRIFT, UDOT, RESIDUAL, COND, P1, P2, N, TA, TB, GAP, VREL, VN, VT, BIAS_N, BIAS_T, \
    DRIFT_REL, RATE = 0, 3, 6, 9, 10, 11, 14, 17, 20, 23, 26, 27, 30, 31, 33, 34, 36, 37
ROW = 40
# Pair kinds.
CC, CS, PC, PS = 0, 1, 2, 3
_Z = (0.0, 0.0, 0.0)


@njit(cache=True)
def _rot(R, a):
    return (R[0, 0] * a[0] + R[0, 1] * a[1] + R[0, 2] * a[2],
            R[1, 0] * a[0] + R[1, 1] * a[1] + R[1, 2] * a[2],
            R[2, 0] * a[0] + R[2, 1] * a[1] + R[2, 2] * a[2])


@njit(cache=True)
def _geometry(kind, prm, R, u0, u1):
    """The world-oriented jet (R r, R T, R K) of a patch."""
    r, t0, t1, k00, k01, k11 = jet(kind, prm, u0, u1)
    return _rot(R, r), _rot(R, t0), _rot(R, t1), _rot(R, k00), _rot(R, k01), _rot(R, k11)


@njit(cache=True)
def _residual(cc, d, T1, K1, T2, T2b, K2, K2ab, K2bb):
    """F and Fu (Eq. 37-40) as three rows (the third zero for CC)."""
    if cc:
        t12 = _dot(T1, T2)
        return ((_dot(T1, d), _dot(T2, d), 0.0),
                (_dot(K1, d) + _dot(T1, T1), -t12, 0.0), (t12, _dot(K2, d) - _dot(T2, T2), 0.0),
                _Z)
    su, sv, suu, suv, svv = T2, T2b, K2, K2ab, K2bb
    Nv = _cr(su, sv)
    susv = _dot(su, sv)
    return ((_dot(su, d), _dot(sv, d), _dot(T1, Nv)),
            (_dot(su, T1), _dot(suu, d) - _dot(su, su), _dot(suv, d) - susv),
            (_dot(sv, T1), _dot(suv, d) - susv, _dot(svv, d) - _dot(sv, sv)),
            (_dot(K1, Nv), _dot(T1, _add(_cr(suu, sv), _cr(su, suv))),
             _dot(T1, _add(_cr(suv, sv), _cr(su, svv)))))


@njit(cache=True, inline="always")
def _det(n, A0, A1, A2):
    if n == 2:
        return A0[0] * A1[1] - A0[1] * A1[0]
    return _dot(A0, _cr(A1, A2))


@njit(cache=True)
def _solve(n, A0, A1, A2, b):
    """A x = b by Cramer's rule, n = 2 or 3 (the callers have checked the conditioning of A,
    `_conditioning`: no pivoting is needed at these sizes)."""
    if n == 2:
        a, c = A0[0], A0[1]
        d, e = A1[0], A1[1]
        det = a * e - c * d
        return ((b[0] * e - c * b[1]) / det, (a * b[1] - b[0] * d) / det, 0.0)
    c0 = _cr(A1, A2)
    det = _dot(A0, c0)
    c1, c2 = _cr(A2, A0), _cr(A0, A1)
    return ((c0[0] * b[0] + c1[0] * b[1] + c2[0] * b[2]) / det,
            (c0[1] * b[0] + c1[1] * b[1] + c2[1] * b[2]) / det,
            (c0[2] * b[0] + c1[2] * b[1] + c2[2] * b[2]) / det)


@njit(cache=True)
def _row_norm(n, a):
    s = a[0] * a[0] + a[1] * a[1]
    if n == 3:
        s += a[2] * a[2]
    return math.sqrt(s)


@njit(cache=True)
def _conditioning(n, A0, A1, A2, T1, T2, T2b):
    """|det Fu| / product of its row norms, its columns scaled by the tangent lengths."""
    c0, c1, c2 = math.sqrt(_dot(T1, T1)), math.sqrt(_dot(T2, T2)), 1.0
    if n == 3:
        c2 = math.sqrt(_dot(T2b, T2b))
    if min(c0, min(c1, c2)) > 0.0:
        A0 = (A0[0] / c0, A0[1] / c1, A0[2] / c2)
        A1 = (A1[0] / c0, A1[1] / c1, A1[2] / c2)
        A2 = (A2[0] / c0, A2[1] / c1, A2[2] / c2)
    den = _row_norm(n, A0) * _row_norm(n, A1)
    if n == 3:
        den *= _row_norm(n, A2)
    return abs(_det(n, A0, A1, A2)) / den if den > 0 else 0.0


@njit(cache=True)
def _put(out, at, a):
    out[at], out[at + 1], out[at + 2] = a[0], a[1], a[2]


@njit(cache=True)
def evaluate_one(cc, kind1, prm1, kind2, prm2, f1, f2, u_state, sigma, project, out):
    """One curve-curve (``cc``) or curve-surface couple at ``u_state`` (u1, u2[, u2b]) into
    the row ``out``: patch 1 the curve (kind1, prm1) of the `Frame` f1, patch 2 (kind2, prm2)
    of f2; sigma = +-1 orients n (Definition 2). With ``project`` one Newton step on F(u) = 0
    (Eq. 37-38) corrects the couple first; a correction below 1e-9 of u moves the points along
    their tangents."""
    R1, o1, w1, v1 = f1
    R2, o2, w2, v2 = f2
    n = 2 if cc else 3
    u = (u_state[0], u_state[1], u_state[2] if n == 3 else 0.0)
    r1, T1, _, K1, _, _ = _geometry(kind1, prm1, R1, u[0], 0.0)
    r2, T2, T2b, K2, K2ab, K2bb = _geometry(kind2, prm2, R2, u[1], u[2])
    d = _sub(_add(r1, o1), _add(r2, o2))
    F, A0, A1, A2 = _residual(cc, d, T1, K1, T2, T2b, K2, K2ab, K2bb)
    ss = F[0] * F[0] + F[1] * F[1]
    if n == 3:
        ss += F[2] * F[2]
    residual = math.sqrt(ss)
    cond = _conditioning(n, A0, A1, A2, T1, T2, T2b)
    du = _Z
    if project and residual > 0.0 and cond > 1e-14:
        x = _solve(n, A0, A1, A2, F)
        du = (-x[0], -x[1], -x[2] if n == 3 else 0.0)
        u = (u[0] + du[0], u[1] + du[1], u[2] + du[2] if n == 3 else 0.0)
        big_du = max(abs(du[0]), abs(du[1]))
        big_u = max(abs(u[0]), abs(u[1]))
        if n == 3:
            big_du, big_u = max(big_du, abs(du[2])), max(big_u, abs(u[2]))
        if big_du > 1e-9 * (1.0 + big_u):
            r1, T1, _, K1, _, _ = _geometry(kind1, prm1, R1, u[0], 0.0)
            r2, T2, T2b, K2, K2ab, K2bb = _geometry(kind2, prm2, R2, u[1], u[2])
            d = _sub(_add(r1, o1), _add(r2, o2))
            F, A0, A1, A2 = _residual(cc, d, T1, K1, T2, T2b, K2, K2ab, K2bb)
            cond = _conditioning(n, A0, A1, A2, T1, T2, T2b)
        else:
            # A round-off-sized correction: the points move along their tangents.
            r1 = _axpy(du[0], T1, r1)
            r2 = _axpy(du[1], T2, r2)
            if n == 3:
                r2 = _axpy(du[2], T2b, r2)
            d = _sub(_add(r1, o1), _add(r2, o2))
    x1, x2 = _add(r1, o1), _add(r2, o2)
    v_rel = _sub(_add(v1, _cr(w1, r1)), _add(v2, _cr(w2, r2)))
    w1t1 = _cr(w1, T1)
    w2t2 = _cr(w2, T2)
    su, sv = T2, T2b
    Nv = _cr(su, sv)
    w2su, w2sv = w2t2, _cr(w2, sv)
    if cc:
        Ft = (_dot(w1t1, d) + _dot(T1, v_rel), _dot(w2t2, d) + _dot(T2, v_rel), 0.0)
    else:
        Ft = (_dot(w2su, d) + _dot(su, v_rel), _dot(w2sv, d) + _dot(sv, v_rel),
              _dot(w1t1, Nv) + _dot(T1, _cr(w2, Nv)))
    # Eq. (47): u' = -J^-1 dF/dt (J = Fu, Eq. 40); zeros where J is singular.
    udot = _Z
    if cond > 1e-14:
        udot = _solve(n, A0, A1, A2, (-Ft[0], -Ft[1], -Ft[2]))
        if n == 2:
            udot = (udot[0], udot[1], 0.0)
    t1dot = _axpy(udot[0], K1, w1t1)
    if cc:
        t2dot = _axpy(udot[1], K2, w2t2)
        nv, ndot, ta, tadot, conv = frame_rates_cc(T1, T2, t1dot, t2dot, w1, w2, udot[0],
                                                   udot[1], sigma)
    else:
        suu, suv, svv = K2, K2ab, K2bb
        sudot = _axpy(udot[2], suv, _axpy(udot[1], suu, w2su))
        svdot = _axpy(udot[2], svv, _axpy(udot[1], suv, w2sv))
        nv, ndot, ta, tadot, conv = frame_rates_cs(T1, su, sv, sudot, svdot, Nv, w1, w2,
                                                   udot[0], udot[1], udot[2], sigma)
    tb = _cr(nv, ta)
    tbdot = _add(_cr(ndot, ta), _cr(nv, tadot))
    _put(out, U, u)
    _put(out, DRIFT, du)
    _put(out, UDOT, udot)
    out[RESIDUAL], out[COND] = residual, cond
    _put(out, P1, x1)
    _put(out, P2, x2)
    _put(out, N, nv)
    _put(out, TA, ta)
    _put(out, TB, tb)
    out[GAP] = _dot(nv, d)
    _put(out, VREL, v_rel)
    out[VN] = _dot(nv, v_rel)
    out[VT], out[VT + 1] = _dot(ta, v_rel), _dot(tb, v_rel)
    out[BIAS_N] = _dot(nv, conv) + _dot(ndot, v_rel)
    out[BIAS_T] = _dot(ta, conv) + _dot(tadot, v_rel)
    out[BIAS_T + 1] = _dot(tb, conv) + _dot(tbdot, v_rel)


@njit(cache=True)
def evaluate_pc_one(kind2, prm2, p, radius, f1, f2, s, sigma, project, out):
    """One point-curve couple (kind "PC"): the point p (coordinates in its `Frame` f1; a
    sphere of ``radius``) against the curve (kind2, prm2) of f2, u = (s,), into the row
    ``out``. F = t2 . d,
    Fu = k2 . d - t2 . t2; s' = -Ft / Fu (Eq. 47); the frame from d' = v_rel - t2 s' and
    t2' = w2 x t2 + k2 s' (`frame_rates_pc`). A point on the curve (|d| = 0, no normal) leaves
    the gap NaN for the caller to report."""
    R1, o1, w1, v1 = f1
    R2, o2, w2, v2 = f2
    r1 = _rot(R1, p)
    x1 = _add(r1, o1)
    r2, T2, _, K2, _, _ = _geometry(kind2, prm2, R2, s, 0.0)
    d = _sub(x1, _add(r2, o2))
    F, Fu = _dot(T2, d), _dot(K2, d) - _dot(T2, T2)
    residual = abs(F)
    den = _dot(T2, T2) + math.sqrt(_dot(K2, K2) * _dot(d, d))
    cond = abs(Fu) / den if den > 0 else 0.0
    ds = 0.0
    if project and residual > 0.0 and cond > 1e-14:
        ds = -F / Fu
        s = s + ds
        r2, T2, _, K2, _, _ = _geometry(kind2, prm2, R2, s, 0.0)
        d = _sub(x1, _add(r2, o2))
        F, Fu = _dot(T2, d), _dot(K2, d) - _dot(T2, T2)
        den = _dot(T2, T2) + math.sqrt(_dot(K2, K2) * _dot(d, d))
        cond = abs(Fu) / den if den > 0 else 0.0
    dist = math.sqrt(_dot(d, d))
    out[U], out[DRIFT], out[RESIDUAL], out[COND] = s, ds, residual, cond
    if not dist > 0.0:
        out[GAP] = math.nan
        return
    x2 = _add(r2, o2)
    v_rel = _sub(_add(v1, _cr(w1, r1)), _add(v2, _cr(w2, r2)))
    w2t2 = _cr(w2, T2)
    Ft = _dot(w2t2, d) + _dot(T2, v_rel)
    sdot = -Ft / Fu if cond > 1e-14 else 0.0
    nv, ndot, ta, tadot, conv = frame_rates_pc(d, T2, _axpy(-sdot, T2, v_rel),
                                               _axpy(sdot, K2, w2t2), w2, sdot, sigma)
    # The contact point is the sphere's point towards the curve, q = -radius d/|d| from its
    # centre: v_rel there, and its motion over the sphere, w1 x (q' - w1 x q), in the Eq. (52)
    # term (the normal row's terms equal the centre's).
    q = _mul(nv, -radius * sigma)
    qdot = _mul(ndot, -radius * sigma)
    x1 = _add(x1, q)
    v_rel = _add(v_rel, _cr(w1, q))
    conv = _add(conv, _cr(w1, _sub(qdot, _cr(w1, q))))
    tb = _cr(nv, ta)
    tbdot = _add(_cr(ndot, ta), _cr(nv, tadot))
    out[UDOT] = sdot
    _put(out, P1, x1)
    _put(out, P2, x2)
    _put(out, N, nv)
    _put(out, TA, ta)
    _put(out, TB, tb)
    out[GAP] = sigma * dist - radius
    _put(out, VREL, v_rel)
    out[VN] = _dot(nv, v_rel)
    out[VT], out[VT + 1] = _dot(ta, v_rel), _dot(tb, v_rel)
    out[BIAS_N] = _dot(nv, conv) + _dot(ndot, v_rel)
    out[BIAS_T] = _dot(ta, conv) + _dot(tadot, v_rel)
    out[BIAS_T + 1] = _dot(tb, conv) + _dot(tbdot, v_rel)


@njit(cache=True)
def evaluate_ps_one(kind2, prm2, p, radius, f1, f2, u_state, sigma, project, out):
    """One point-surface couple (kind "PS"): the point p (coordinates in its `Frame` f1; a
    sphere of ``radius``) against the surface (kind2, prm2) of f2, u = (u, v), into the row
    ``out`` (its u,
    drift and udot in the row's first two places of each). F = [s_u . d, s_v . d] (Eq. 38
    without its tangency row); the frame as for C-S with no curve on Body 1; the contact point
    is the sphere's point towards the surface, q = -radius n from its centre."""
    R1, o1, w1, v1 = f1
    R2, o2, w2, v2 = f2
    r1 = _rot(R1, p)
    x1 = _add(r1, o1)
    a0, a1 = u_state[0], u_state[1]
    r2, su, sv, suu, suv, svv = _geometry(kind2, prm2, R2, a0, a1)
    d = _sub(x1, _add(r2, o2))
    susv = _dot(su, sv)
    F0, F1 = _dot(su, d), _dot(sv, d)
    A0 = (_dot(suu, d) - _dot(su, su), _dot(suv, d) - susv, 0.0)
    A1 = (_dot(suv, d) - susv, _dot(svv, d) - _dot(sv, sv), 0.0)
    residual = math.hypot(F0, F1)
    cond = _ps_conditioning(A0, A1, su, sv)
    du0, du1 = 0.0, 0.0
    if project and residual > 0.0 and cond > 1e-14:
        x = _solve(2, A0, A1, _Z, (F0, F1, 0.0))
        du0, du1 = -x[0], -x[1]
        a0, a1 = a0 + du0, a1 + du1
        r2, su, sv, suu, suv, svv = _geometry(kind2, prm2, R2, a0, a1)
        d = _sub(x1, _add(r2, o2))
        susv = _dot(su, sv)
        A0 = (_dot(suu, d) - _dot(su, su), _dot(suv, d) - susv, 0.0)
        A1 = (_dot(suv, d) - susv, _dot(svv, d) - _dot(sv, sv), 0.0)
        cond = _ps_conditioning(A0, A1, su, sv)
    x2 = _add(r2, o2)
    w2su, w2sv = _cr(w2, su), _cr(w2, sv)
    v_rel = _sub(_add(v1, _cr(w1, r1)), _add(v2, _cr(w2, r2)))
    Ft0, Ft1 = _dot(w2su, d) + _dot(su, v_rel), _dot(w2sv, d) + _dot(sv, v_rel)
    # Eq. (47); a singular Fu (p at a centre of curvature) gives zeros, reported by the
    # conditioning.
    ud0, ud1 = 0.0, 0.0
    if cond > 1e-14:
        y = _solve(2, A0, A1, _Z, (-Ft0, -Ft1, 0.0))
        ud0, ud1 = y[0], y[1]
    sudot = _axpy(ud1, suv, _axpy(ud0, suu, w2su))
    svdot = _axpy(ud1, svv, _axpy(ud0, suv, w2sv))
    nv, ndot, ta, tadot, conv = frame_rates_cs(_Z, su, sv, sudot, svdot, _cr(su, sv), w1, w2,
                                               0.0, ud0, ud1, sigma)
    q = _mul(nv, -radius)
    qdot = _mul(ndot, -radius)
    gap = _dot(nv, d) - radius
    x1 = _add(x1, q)
    v_rel = _add(v_rel, _cr(w1, q))
    conv = _add(conv, _cr(w1, _sub(qdot, _cr(w1, q))))
    tb = _cr(nv, ta)
    tbdot = _add(_cr(ndot, ta), _cr(nv, tadot))
    out[U], out[U + 1], out[DRIFT], out[DRIFT + 1] = a0, a1, du0, du1
    out[UDOT], out[UDOT + 1] = ud0, ud1
    out[RESIDUAL], out[COND] = residual, cond
    _put(out, P1, x1)
    _put(out, P2, x2)
    _put(out, N, nv)
    _put(out, TA, ta)
    _put(out, TB, tb)
    out[GAP] = gap
    _put(out, VREL, v_rel)
    out[VN] = _dot(nv, v_rel)
    out[VT], out[VT + 1] = _dot(ta, v_rel), _dot(tb, v_rel)
    out[BIAS_N] = _dot(nv, conv) + _dot(ndot, v_rel)
    out[BIAS_T] = _dot(ta, conv) + _dot(tadot, v_rel)
    out[BIAS_T + 1] = _dot(tb, conv) + _dot(tbdot, v_rel)


@njit(cache=True)
def _ps_conditioning(A0, A1, su, sv):
    """`_conditioning` of a point-surface Fu: its columns scaled by |s_u|, |s_v|, |det| over
    the product of the row norms."""
    c0, c1 = math.sqrt(_dot(su, su)), math.sqrt(_dot(sv, sv))
    if min(c0, c1) > 0.0:
        A0 = (A0[0] / c0, A0[1] / c1, 0.0)
        A1 = (A1[0] / c0, A1[1] / c1, 0.0)
    den = math.hypot(A0[0], A0[1]) * math.hypot(A1[0], A1[1])
    return abs(A0[0] * A1[1] - A0[1] * A1[0]) / den if den > 0 else 0.0


@njit(cache=True)
def conditions(pair, kind1, prm1, kind2, prm2, p, R1, o1, R2, o2, u_state, out):
    """The contact form's F (Eq. 37-38) into out[0:3], its Jacobian Fu = dF/du (Eq. 40) by
    rows into out[3:12] and its conditioning into out[12], at the couple ``u_state`` (a
    3-tuple, zero-padded) of a pair of kind ``pair`` (`CC` ... `PS`), unprojected: patch 1 the
    curve (kind1, prm1) of the frame (R1, o1), or for PC and PS the point p (its frame's
    coordinates); patch 2 (kind2, prm2) of (R2, o2). Entries beyond the couple's dimension are
    zero. The conditioning is the one the evaluations test (`_conditioning`; PC: |Fu| /
    (t2 . t2 + |k2| |d|), 0 with the point on a circle's axis)."""
    out[:13] = 0.0
    if pair == PC or pair == PS:
        x1 = _add(_rot(R1, p), o1)
        r2, su, sv, suu, suv, svv = _geometry(kind2, prm2, R2, u_state[0], u_state[1])
        d = _sub(x1, _add(r2, o2))
        if pair == PC:
            out[0], out[3] = _dot(su, d), _dot(suu, d) - _dot(su, su)
            den = _dot(su, su) + math.sqrt(_dot(suu, suu) * _dot(d, d))
            out[12] = abs(out[3]) / den if den > 0 else 0.0
            return
        susv = _dot(su, sv)
        A0 = (_dot(suu, d) - _dot(su, su), _dot(suv, d) - susv, 0.0)
        A1 = (_dot(suv, d) - susv, _dot(svv, d) - _dot(sv, sv), 0.0)
        out[0], out[1] = _dot(su, d), _dot(sv, d)
        out[3], out[4], out[6], out[7] = A0[0], A0[1], A1[0], A1[1]
        out[12] = _ps_conditioning(A0, A1, su, sv)
        return
    cc = pair == CC
    n = 2 if cc else 3
    r1, T1, _, K1, _, _ = _geometry(kind1, prm1, R1, u_state[0], 0.0)
    r2, T2, T2b, K2, K2ab, K2bb = _geometry(kind2, prm2, R2, u_state[1],
                                            u_state[2] if n == 3 else 0.0)
    d = _sub(_add(r1, o1), _add(r2, o2))
    F, A0, A1, A2 = _residual(cc, d, T1, K1, T2, T2b, K2, K2ab, K2bb)
    for c in range(n):
        out[c], out[3 + c], out[6 + c], out[9 + c] = F[c], A0[c], A1[c], A2[c]
    out[12] = _conditioning(n, A0, A1, A2, T1, T2, T2b)


def warm():
    """Compiles or loads the couples of each kind with the argument types of the compiled
    engine's calls (`drake_dock.core.kernels.engine`): frames' rotations as views of a stacked
    array in `Frame` records with their origins and twists as tuples, a row of a stacked
    array."""
    from drake_dock.core.patches import Circle, PlaneRect, Segment
    from drake_dock.core.kernels.jets import patch_spec
    import numpy as np
    R = np.tile(np.eye(3), (2, 1, 1))
    out = np.zeros((3, ROW))
    z = (0.0, 0.0, 0.0)
    project = np.bool_(True)
    k1, p1 = patch_spec(Segment((0.0, 0.0, 0.1), (1.0, 0.0, 0.1)))
    k2, p2 = patch_spec(Segment((0.5, -1.0, 0.0), (0.5, 1.0, 0.0)))
    f1, f2 = Frame(R[0], z, z, z), Frame(R[1], z, z, z)
    evaluate_one(True, k1, p1, k2, p2, f1, f2, (0.5, 0.5, 0.0), 1.0, project, out[0])
    kc, pcirc = patch_spec(Circle(0.3, 0.1))
    kp, pplane = patch_spec(PlaneRect((-1, -1, 0), (2, 0, 0), (0, 2, 0)))
    evaluate_one(False, kc, pcirc, kp, pplane, f1, f2, (0.5, 0.5, 0.5), 1.0, project, out[1])
    evaluate_pc_one(kc, pcirc, (0.1, 0.2, 0.3), 0.01, f1, f2, 0.5, 1.0, project, out[2])
    evaluate_ps_one(kp, pplane, (0.1, 0.2, 0.3), 0.01, f1, f2, (0.5, 0.5), 1.0, project,
                    out[2])
    for pair, (ka, pa), (kb, pb) in ((CC, (k1, p1), (k2, p2)), (CS, (kc, pcirc), (kp, pplane)),
                                     (PC, (0, p1), (kc, pcirc)), (PS, (0, p1), (kp, pplane))):
        conditions(pair, ka, pa, kb, pb, z, R[0], z, R[1], z, (0.5, 0.5, 0.5), out[0])
