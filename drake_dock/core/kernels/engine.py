"""One evaluation of the contact dynamics of free rigid bodies in one compiled call: from the
state (q, v, u*) and the generalized force of everything but contact to q', v', u*', the
couples' rows and the contact forces.

The steps are the paper's, each an existing kernel:
- the bodies' and the frames' poses and twists (`free_bodies`);
- the tracked couples, Eq. (47) with one Newton projection, the contact frame, gap, normal
  velocity and the Eq. (52) bias terms (`couples.evaluate_couples`,
  `couples.evaluate_point_curves`);
- M^-1 and the velocity-product terms (`free_bodies.mass_inverse_and_bias`), the free
  acceleration a0 = M^-1 (tau - C v);
- per couple in contact its row W (Eq. 11) and bias (Eq. 52) (`free_bodies.point_rows`), its
  sliding direction, and the constraint solve for the given modes (Eq. 48-52,
  `solve.solve_modes`).

The layouts are records of arrays (`Bodies`, `CoupleSet`), built once per system. The call
returns a status (`solve.OK`, `SINGULAR`, `NONFINITE`) and leaves the typed errors to the
caller, which names the couples.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels.free_bodies import (body_kinematics, frame_kinematics,
                                                 mass_inverse_and_bias, point_rows, qdot)
from drake_dock.core.kernels.solve import OK, SLIDE, STICK, solve_modes


class Bodies(NamedTuple):
    """Free bodies and the frames fixed on them (`free_bodies` module docstring)."""
    qs: np.ndarray       # (nb,) int64
    vs: np.ndarray       # (nb,) int64
    m: np.ndarray        # (nb,)
    c_B: np.ndarray      # (nb, 3)
    I_B: np.ndarray      # (nb, 3, 3) about the centre of mass
    I_B_inv: np.ndarray  # (nb, 3, 3)
    fb: np.ndarray       # (F,) int64, -1 for the world
    R_BF: np.ndarray     # (F, 3, 3)
    p_BF: np.ndarray     # (F, 3)


class CoupleSet(NamedTuple):
    """The pairs' couple kernels (`drake_dock.core.kernels.tracked.TrackedCouples`)."""
    cc: np.ndarray       # (k,) bool: curve-curve
    pc: np.ndarray       # (k,) bool: point-curve
    kind1: np.ndarray
    prm1: np.ndarray
    kind2: np.ndarray
    prm2: np.ndarray
    fidx: np.ndarray     # (k, 2) frame indices
    uoff: np.ndarray
    spans: np.ndarray


@njit(cache=True)
def evaluate(B, C, q, v, u, sigma, active, rows, codes, held_dir, has_dir, tau_el, tau_in, mu,
             mu_s, omega, v_slip, drift_feedback, drift_tol, energy_scale, R, o, w, vf, out,
             xdot, lam_n, lam_t, gf):
    """The evaluation (module docstring). ``active`` (k,) the tracked pairs; ``rows`` (r,) the
    pairs in contact with their mode ``codes`` (STICK or SLIDE), ``held_dir`` (r, 2) the
    sliding direction kept for a slow sliding couple when ``has_dir``; ``tau_el`` and
    ``tau_in`` (nv,) the generalized forces of the force elements and of the inputs.

    Outputs: the frames' R, o, w, vf; ``out`` (k, couples.ROW) as `couples.evaluate_couples`;
    ``xdot`` = [q', v', u*', friction power, power of tau_el, power of tau_in, ...] with the
    powers divided by ``energy_scale`` (the rest of xdot is the caller's); lam_n (k,),
    lam_t (k, 2) per pair (zero off contact); gf (nv,) the generalized contact force.

    Returns (status, cond(A), the first tracked point-curve pair whose point lies on its curve
    or -1, the first pair in contact whose projection exceeds ``drift_tol`` of its domain span
    or -1, friction power, power of tau_el, power of tau_in). The solve is skipped (status OK)
    when a pair is reported."""
    nb, nq, nv, nu = B.qs.shape[0], q.shape[0], v.shape[0], u.shape[0]
    qd, vdot, udot = xdot[:nq], xdot[nq:nq + nv], xdot[nq + nv:nq + nv + nu]
    Rb, pb = np.empty((nb, 3, 3)), np.empty((nb, 3))
    wb, vb = np.empty((nb, 3)), np.empty((nb, 3))
    body_kinematics(B.qs, B.vs, q, v, Rb, pb, wb, vb)
    frame_kinematics(B.fb, B.R_BF, B.p_BF, Rb, pb, wb, vb, R, o, w, vf)
    qdot(B.qs, B.vs, q, v, qd)
    p_el, p_in = 0.0, 0.0
    for a in range(nv):
        p_el += tau_el[a] * v[a]
        p_in += tau_in[a] * v[a]
    # The tracked couples (Eq. 47).
    k = active.shape[0]
    udot[:] = 0.0
    other = active.copy()
    any_pc = False
    for i in range(k):
        if C.pc[i]:
            other[i] = False
            any_pc = any_pc or active[i]
    bad_pc, bad_drift = -1, -1
    # Projected; a bool, not the literal True, so that the couples' kernels compiled for the
    # tracked path (`tracked.TrackedCouples.evaluate`) serve here too.
    project = np.bool_(True)
    if any_pc:
        pc_idx = np.flatnonzero(C.pc)
        K.evaluate_point_curves(pc_idx, C.kind2, C.prm1, C.prm2, C.fidx, C.uoff, C.spans, R, o,
                                w, vf, u, sigma, active, project, drift_feedback, out, udot)
        for i in pc_idx:
            if active[i] and math.isnan(out[i, K.GAP]):
                bad_pc = i
                break
    K.evaluate_couples(C.cc, C.kind1, C.prm1, C.kind2, C.prm2, C.fidx, C.uoff, C.spans, R, o, w,
                       vf, u, sigma, other, project, drift_feedback, out, udot)
    r = rows.shape[0]
    for j in range(r):
        if out[rows[j], K.DRIFT_REL] > drift_tol:
            bad_drift = rows[j]
            break
    lam_n[:] = 0.0
    lam_t[:] = 0.0
    if bad_pc >= 0 or bad_drift >= 0:
        return OK, 0.0, bad_pc, bad_drift, 0.0, p_el, p_in
    # The free acceleration a0 = M^-1 (tau - C v).
    Minv = np.zeros((nv, nv))
    cv = np.zeros(nv)
    mass_inverse_and_bias(B.vs, B.m, B.c_B, B.I_B_inv, B.I_B, Rb, wb, Minv, cv)
    a0 = Minv @ (tau_el + tau_in - cv)
    # The rows of the couples in contact (Eq. 11, 52) and their sliding directions.
    W = np.empty((r, nv, 3))
    bias = np.empty((r, 3))
    gap, vn = np.empty(r), np.empty(r)
    mus, mus_s = np.full(r, mu), np.full(r, mu_s)
    dirs = np.zeros((r, 2))
    D = np.empty((3, 3))
    acc = np.empty(3)
    for j in range(r):
        i = rows[j]
        row = out[i]
        for c in range(3):
            D[0, c], D[1, c], D[2, c] = row[K.N + c], row[K.TA + c], row[K.TB + c]
        a, b = C.fidx[i, 0], C.fidx[i, 1]
        point_rows(B.vs, pb, wb, B.fb[a], B.fb[b], row[K.P1:K.P1 + 3], row[K.P2:K.P2 + 3], D,
                   W[j], acc)
        bias[j, 0] = row[K.BIAS_N] + acc[0]
        bias[j, 1] = row[K.BIAS_T] + acc[1]
        bias[j, 2] = row[K.BIAS_T + 1] + acc[2]
        gap[j], vn[j] = row[K.GAP], row[K.VN]
        if codes[j] == SLIDE:
            s = math.hypot(row[K.VT], row[K.VT + 1])
            if s > v_slip or not has_dir[j]:
                if s > 0.0:
                    dirs[j, 0], dirs[j, 1] = row[K.VT] / s, row[K.VT + 1] / s
                else:       # no direction: the solve reports NONFINITE
                    dirs[j, 0], dirs[j, 1] = math.nan, math.nan
            else:
                dirs[j, 0], dirs[j, 1] = held_dir[j, 0], held_dir[j, 1]
    lr_n, lr_t = np.empty(r), np.empty((r, 2))
    status, cond = solve_modes(Minv, a0, W, bias, gap, vn, mus, mus_s, codes, dirs, omega, vdot,
                               lr_n, lr_t, gf)
    power = 0.0
    for j in range(r):
        i = rows[j]
        lam_n[i], lam_t[i, 0], lam_t[i, 1] = lr_n[j], lr_t[j, 0], lr_t[j, 1]
        power -= lr_t[j, 0] * out[i, K.VT] + lr_t[j, 1] * out[i, K.VT + 1]
    e = nq + nv + nu
    xdot[e], xdot[e + 1], xdot[e + 2] = (power / energy_scale, p_el / energy_scale,
                                         p_in / energy_scale)
    return status, cond, bad_pc, bad_drift, power, p_el, p_in


def warm():
    """Compiles or loads the kernel: two free bodies with a frame each, and one CC, one CS and
    one PC couple between the frames (those of `tracked.warm`), the first two in contact, one
    sticking and one sliding; the argument types of `drake_dock.systems.engine`'s call."""
    from drake_dock.core.kernels.tracked import TrackedCouples
    from drake_dock.core.patches import Circle, PlaneRect, Point, Segment
    tc = TrackedCouples([("CC", Segment((0.0, 0.0, 0.1), (1.0, 0.0, 0.1)),
                          Segment((0.5, -1.0, 0.0), (0.5, 1.0, 0.0)), (0, 1)),
                         ("CS", Circle(0.3, 0.1), PlaneRect((-1, -1, 0), (2, 0, 0), (0, 2, 0)),
                          (0, 1)),
                         ("PC", Point((0.1, 0.2, 0.3), 0.01), Circle(0.3), (0, 1))])
    pc = np.zeros(3, dtype=np.bool_)
    pc[tc.pc] = True
    C = CoupleSet(tc.cc, pc, tc.kind1, tc.prm1, tc.kind2, tc.prm2, tc.fidx, tc.uoff, tc.spans)
    eye = np.array([np.eye(3), np.eye(3)])
    B = Bodies(np.array([0, 7], dtype=np.int64), np.array([0, 6], dtype=np.int64), np.ones(2),
               np.zeros((2, 3)), eye, eye.copy(), np.array([0, 1], dtype=np.int64), eye.copy(),
               np.zeros((2, 3)))
    q = np.array([1.0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1])
    u = np.array([0.5, 0.5, 0.0, 0.5, 0.5, 1.0])
    F, k, nv = 2, 3, 12
    evaluate(B, C, q, np.zeros(nv), u, np.ones(k), np.ones(k, dtype=np.bool_),
             np.array([0, 1], dtype=np.int64), np.array([STICK, SLIDE], dtype=np.int64),
             np.zeros((2, 2)), np.zeros(2, dtype=np.bool_), np.zeros(nv), np.zeros(nv), 0.3, 0.3,
             20.0, 1e-6, 0.0, 1e-3, 1.0, np.empty((F, 3, 3)), np.empty((F, 3)),
             np.empty((F, 3)), np.empty((F, 3)), np.zeros((k, K.ROW)),
             np.zeros(q.size + nv + u.size + 3), np.empty(k), np.empty((k, 2)), np.empty(nv))
