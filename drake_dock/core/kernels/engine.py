"""One evaluation of the contact dynamics of free rigid bodies in one compiled call: from the
state x = [q, v, u*, energy integrals] to its time derivative, the couples, the contact forces,
the values of every witness and the far pairs' travel bounds.

The steps are the paper's:
- the bodies' and the frames' poses and twists (`free_bodies`);
- the force elements: uniform gravity and Drake's LinearBushingRollPitchYaw (the Stewart
  element, `bushing`), their generalized force, power and potential, each bushing's damper
  power apart;
- the tracked couples, Eq. (47) with one Newton projection, the contact frame, gap, normal
  velocity and the Eq. (52) bias terms, by pair kind (`couples`);
- M^-1 and the velocity-product terms (`free_bodies.mass_inverse_and_bias`), the free
  acceleration a0 = M^-1 (tau - C v);
- per couple in contact its row W (Eq. 11) and bias (Eq. 52) (`free_bodies.point_rows`), its
  sliding direction, and the constraint solve for the given modes (Eq. 48-52,
  `solve.solve_modes`);
- the witnesses of the contact system's table (`drake_dock.systems.witnesses`): per pair the
  value of each kind (`W_IMPACT` ... `W_SIDE`), and the far pairs' smallest clearance left.

Records (`drake_dock.core.kernels.records`): `Model` (the bodies, frames, force elements,
pairs, hand-over edges and options, built once per system) and `ModeArrays` (the pairs' modes
and far-pair data, built once per sealed set of modes), each packed; the results go into one
float buffer whose sections `layout` gives. The call returns nothing: a status in the buffer
(`solve.OK`, `SINGULAR`, `NONFINITE`, or a pair to report: a point on its curve, a drift
beyond ``drift_tol``) leaves the typed errors to the caller, which names the couples.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels.forces import block_apply, element_forces, kinetic_energy
from drake_dock.core.kernels.frames import frame_of
from drake_dock.core.kernels.free_bodies import (body_kinematics, frame_kinematics,
                                                 mass_inverse_and_bias, point_rows, qdot)
from drake_dock.core.kernels.model import (BUSH_ROW, CC, FAR, NW, O_COND_MIN, O_DRIFT_FB, O_DRIFT_TOL,
                                           O_ENERGY, O_GUARD, O_MU, O_MU_S, O_OMEGA, O_V_SLIP,
                                           PC, PS, S_BAD_PC, S_BUSH, S_COND, S_DAMP, S_DRIFTING,
                                           S_FAR, S_FRICTION, S_KE, S_P_EL, S_P_IN, S_PE,
                                           S_REPORT, S_STATUS, SLIDING, STICKING, W_CONE,
                                           W_HANDOVER, W_IMPACT, W_LAMBDA, W_REGULAR, W_SIDE, W_SLIP,
                                           Z_IE, Z_NQ, Z_NV, Z_NX, layout, unpack_model,
                                           unpack_modes)
from drake_dock.core.kernels.solve import OK, SLIDE, STICK, Problem, Solution, solve_modes
from drake_dock.core.kernels.witness_values import end_margin, handover_guard, point_curve_side

@njit(cache=True)
def pair_couple(m, i, R, o, w, vf, u, sigma, project, row):
    """Pair i's couple into its couple row (its kind's kernel), from the frames' poses and
    twists (R, o, w, vf) and the couples u (the layout of u*), projected (one Newton step)
    when ``project``."""
    f1, f2 = frame_of(m.fidx[i, 0], R, o, w, vf), frame_of(m.fidx[i, 1], R, o, w, vf)
    ui = u[m.uoff[i]:m.uoff[i + 1]]
    kind = m.pair_kind[i]
    if kind == PC:
        p = (m.prm1[i, 0], m.prm1[i, 1], m.prm1[i, 2])
        K.evaluate_pc_one(m.kind2[i], m.prm2[i], p, m.prm1[i, 3], f1, f2, ui[0], sigma,
                          project, row)
    elif kind == PS:
        p = (m.prm1[i, 0], m.prm1[i, 1], m.prm1[i, 2])
        K.evaluate_ps_one(m.kind2[i], m.prm2[i], p, m.prm1[i, 3], f1, f2, (ui[0], ui[1]),
                          sigma, project, row)
    else:
        us = (ui[0], ui[1], ui[2] if len(ui) == 3 else 0.0)
        K.evaluate_one(kind == CC, m.kind1[i], m.prm1[i], m.kind2[i], m.prm2[i], f1, f2, us,
                       sigma, project, row)


@njit(cache=True)
def couple_rates(m, i, row, drift_feedback, udot):
    """Pair i's largest drift relative to its spans (row DRIFT_REL) and its integrated rate
    u*' = Eq. (47) + drift_feedback x projection, into its row and into udot."""
    rel = 0.0
    for j in range(m.uoff[i + 1] - m.uoff[i]):
        rel = max(rel, abs(row[K.DRIFT + j]) / m.spans[i, j])
        row[K.RATE + j] = row[K.UDOT + j] + drift_feedback * row[K.DRIFT + j]
        udot[m.uoff[i] + j] = row[K.RATE + j]
    row[K.DRIFT_REL] = rel


@njit(cache=True)
def evaluate(mp, sp, x, tau_in, buf):
    """The evaluation (module docstring) at the state x with the inputs' generalized force
    tau_in (nv,), the model and modes packed (`Model`, `ModeArrays`), into ``buf`` (`layout`)."""
    m = unpack_model(mp)
    s = unpack_modes(sp)
    nq, nv, ie, nx = m.sizes[Z_NQ], m.sizes[Z_NV], m.sizes[Z_IE], m.sizes[Z_NX]
    k, F, nb, nbush = s.code.shape[0], m.frame_body.shape[0], m.qs.shape[0], \
        m.bush_frames.shape[0]
    nn = s.near.shape[0]
    XD, OUT, LN, LT, GF, WV, BD, FR, FO, FW, FV, SC, BU, END = layout(nx, k, nv, F, nbush, nn)
    opt = m.options
    q, v, u = x[:nq], x[nq:nq + nv], x[nq + nv:ie]
    xdot = buf[XD:XD + nx]
    out = buf[OUT:LN].reshape((nn, K.ROW))
    lam_n, lam_t = buf[LN:LT], buf[LT:GF].reshape((k, 2))
    gf = buf[GF:WV]
    wv = buf[WV:BD].reshape((nn, NW))
    R, o = buf[FR:FO].reshape((F, 3, 3)), buf[FO:FW].reshape((F, 3))
    w, vf = buf[FW:FV].reshape((F, 3)), buf[FV:SC].reshape((F, 3))
    sc = buf[SC:BU]
    bush = buf[BU:END].reshape((nbush, BUSH_ROW))
    sc[:] = 0.0
    sc[S_BAD_PC], sc[S_DRIFTING] = -1.0, -1.0
    # 1. Kinematics.
    Rb, pb = np.empty((nb, 3, 3)), np.empty((nb, 3))
    wb, vb = np.empty((nb, 3)), np.empty((nb, 3))
    body_kinematics(m.qs, m.vs, q, v, Rb, pb, wb, vb)
    frame_kinematics(m.frame_body, m.R_BF, m.p_BF, Rb, pb, wb, vb, R, o, w, vf)
    qdot(m.qs, m.vs, q, v, xdot[:nq])
    # 2. The force elements.
    tau_el = np.empty(nv)
    sc[S_PE], bst = element_forces(m, q, v, Rb, pb, R, o, w, vf, tau_el, bush, sc[S_DAMP:])
    sc[S_BUSH] = bst
    p_el, p_in = 0.0, 0.0
    for a in range(nv):
        p_el += tau_el[a] * v[a]
        p_in += tau_in[a] * v[a]
    sc[S_P_EL], sc[S_P_IN] = p_el, p_in
    sc[S_KE] = kinetic_energy(m, Rb, wb, vb)
    # 3. The couples of the pairs that are not far (Eq. 47) and the witnesses they give.
    udot = xdot[nq + nv:ie]
    udot[:] = 0.0
    lam_n[:] = 0.0
    lam_t[:] = 0.0
    gf[:] = 0.0
    fb, tol = opt[O_DRIFT_FB], opt[O_DRIFT_TOL]
    for j in range(nn):
        i = s.near[j]
        code = s.code[i]
        row = out[j]
        row[:] = 0.0
        wv[j, :] = 1.0
        # Projected; a bool, not the literal True, so that the kernel compiled for the
        # calculators (`calculators.couples_at`) serves here too.
        pair_couple(m, i, R, o, w, vf, u, s.sigma[i], np.bool_(True), row)
        couple_rates(m, i, row, fb, udot)
        if m.pair_kind[i] == PC and math.isnan(row[K.GAP]):
            if sc[S_BAD_PC] < 0:
                sc[S_BAD_PC] = i
            continue
        if row[K.DRIFT_REL] > tol and sc[S_DRIFTING] < 0:
            sc[S_DRIFTING] = i
        R2 = R[m.fidx[i, 1]]
        wv[j, W_IMPACT] = row[K.GAP] if row[K.GAP] > 0.0 else row[K.VN]
        wv[j, W_REGULAR] = min(end_margin(m, i, row), row[K.COND] - opt[O_COND_MIN])
        if m.edge_count[i] > 0:
            wv[j, W_HANDOVER] = handover_guard(m, i, row, R2) + opt[O_GUARD]
        if m.pair_kind[i] == PC:
            wv[j, W_SIDE] = point_curve_side(m, i, row, R2)
    sc[S_FAR] = math.nan        # `far_witness` fills it and BOUND when asked
    e = ie
    xdot[e + 1], xdot[e + 2] = p_el / opt[O_ENERGY], p_in / opt[O_ENERGY]
    for n in range(nbush):
        xdot[e + 3 + n] = sc[S_DAMP + n] / opt[O_ENERGY]
    vdot = xdot[nq:nq + nv]
    if sc[S_BAD_PC] >= 0:
        sc[S_STATUS] = OK
        sc[S_REPORT] = 1.0
        vdot[:] = 0.0
        xdot[e] = 0.0
        return
    # 5. The free acceleration a0 = M^-1 (tau - C v).
    Minv = np.zeros((nv, nv))
    cv = np.zeros(nv)
    mass_inverse_and_bias(m.vs, m.mass, m.com, m.inertia_inv, m.inertia, Rb, wb, Minv, cv)
    a0 = block_apply(m.vs, Minv, tau_el + tau_in - cv)
    # 6. The rows of the couples in contact (Eq. 11, 52), their modes and sliding directions,
    #    and the constraint solve (Eq. 48-52).
    rows = s.rows
    r = rows.shape[0]
    W = np.empty((r, nv, 3))
    bias = np.empty((r, 3))
    gap, vn = np.empty(r), np.empty(r)
    mus, mus_s = np.full(r, opt[O_MU]), np.full(r, opt[O_MU_S])
    codes = np.empty(r, dtype=np.int64)
    dirs = np.zeros((r, 2))
    D = np.empty((3, 3))
    acc = np.empty(3)
    v_slip = opt[O_V_SLIP]
    for j in range(r):
        i = rows[j]
        row = out[s.slot[i]]
        for c in range(3):
            D[0, c], D[1, c], D[2, c] = row[K.N + c], row[K.TA + c], row[K.TB + c]
        a, b = m.fidx[i, 0], m.fidx[i, 1]
        point_rows(m.vs, pb, wb, m.frame_body[a], m.frame_body[b], row[K.P1:K.P1 + 3],
                   row[K.P2:K.P2 + 3], D, W[j], acc)
        bias[j, 0] = row[K.BIAS_N] + acc[0]
        bias[j, 1] = row[K.BIAS_T] + acc[1]
        bias[j, 2] = row[K.BIAS_T + 1] + acc[2]
        gap[j], vn[j] = row[K.GAP], row[K.VN]
        codes[j] = STICK if s.code[i] == STICKING else SLIDE
        if codes[j] == SLIDE:
            sp_ = math.hypot(row[K.VT], row[K.VT + 1])
            if sp_ > v_slip or not s.has_dir[i]:
                if sp_ > 0.0:
                    dirs[j, 0], dirs[j, 1] = row[K.VT] / sp_, row[K.VT + 1] / sp_
                else:       # no direction: the solve reports NONFINITE
                    dirs[j, 0], dirs[j, 1] = math.nan, math.nan
            else:
                dirs[j, 0], dirs[j, 1] = s.slide_dir[i, 0], s.slide_dir[i, 1]
    lr_n, lr_t = np.empty(r), np.empty((r, 2))
    status, cond = solve_modes(Problem(Minv, a0, W, bias, gap, vn, mus, mus_s), codes, dirs,
                               opt[O_OMEGA], Solution(vdot, lr_n, lr_t, gf))
    sc[S_STATUS], sc[S_COND] = status, cond
    sc[S_REPORT] = 1.0 if status != OK or sc[S_BUSH] != 0.0 else 0.0
    power = 0.0
    for j in range(r):
        i = rows[j]
        n = s.slot[i]
        lam_n[i], lam_t[i, 0], lam_t[i, 1] = lr_n[j], lr_t[j, 0], lr_t[j, 1]
        power -= lr_t[j, 0] * out[n, K.VT] + lr_t[j, 1] * out[n, K.VT + 1]
        wv[n, W_LAMBDA] = lr_n[j]
        if s.code[i] == SLIDING:
            if s.has_dir[i]:
                wv[n, W_SLIP] = out[n, K.VT] * s.slide_dir[i, 0] \
                    + out[n, K.VT + 1] * s.slide_dir[i, 1]
        else:
            wv[n, W_CONE] = opt[O_MU_S] * lr_n[j] - math.hypot(lr_t[j, 0], lr_t[j, 1])
    sc[S_FRICTION] = power
    xdot[e] = power / opt[O_ENERGY]


def toy_model():
    """A small model and modes for compiling the kernels (`warm`): two free bodies with a
    frame each, a bushing between them, one pair of each kind (CC, CS, PC, PS) between the
    frames, an edge hand-over from the CC pair to the CS pair; the CC pair tracked, the CS pair
    sliding, the PC pair sticking, the PS pair far. Returns (Model, ModeArrays, x)."""
    from drake_dock.core.kernels.jets import N_PARAMS, patch_spec
    from drake_dock.core.kernels.model import (AFFINE, CS, N_OPTIONS, N_SIZES, TRACKED, Model,
                                               ModeArrays)
    from drake_dock.core.patches import Circle, PlaneRect, Segment
    k, nq, nv = 4, 14, 12
    specs = [(CC, patch_spec(Segment((0.0, 0.0, 0.1), (1.0, 0.0, 0.1))),
              patch_spec(Segment((0.5, -1.0, 0.0), (0.5, 1.0, 0.0)))),
             (CS, patch_spec(Circle(0.3, 0.1)),
              patch_spec(PlaneRect((-1, -1, 0), (2, 0, 0), (0, 2, 0)))),
             (PC, (0, np.r_[0.1, 0.2, 0.3, 0.01, np.zeros(N_PARAMS - 4)]), patch_spec(Circle(0.3))),
             (PS, (0, np.r_[0.1, 0.2, 0.3, 0.01, np.zeros(N_PARAMS - 4)]),
              patch_spec(PlaneRect((-1, -1, 0), (2, 0, 0), (0, 2, 0))))]
    dims = np.array([2, 3, 1, 2])
    eye = np.tile(np.eye(3), (2, 1, 1))
    m = Model(np.array([0, 7]), np.array([0, 6]), np.ones(2), np.zeros((2, 3)), eye.copy(),
              eye.copy(), np.array([0.0, 0.0, -9.81]), np.array([0, 1]), eye.copy(),
              np.zeros((2, 3)), np.array([[0, 1]]), np.ones((1, 4, 3)),
              np.array([s[0] for s in specs]), np.array([s[1][0] for s in specs]),
              np.array([s[2][0] for s in specs]), np.array([s[1][1] for s in specs]),
              np.array([s[2][1] for s in specs]), np.tile([0, 1], (k, 1)),
              np.r_[0, np.cumsum(dims)], np.ones((k, 3)), np.zeros((k, 3)), np.ones((k, 3)),
              np.ones((k, 3), dtype=np.int64), np.zeros(k, dtype=np.int64),
              np.array([[0, 1]]), np.zeros((k, 3)), np.ones(k), np.zeros(k, dtype=np.int64),
              np.array([1, 0, 0, 0]), np.array([1]), np.array([[0, 1, AFFINE]]),
              np.array([[1.0, 0.0]]), np.full(N_OPTIONS, 0.5),
              np.array([nq, nv, int(dims.sum()), nq + nv + int(dims.sum()),
                        nq + nv + int(dims.sum()) + 3 + 1])[:N_SIZES])
    s = ModeArrays(np.array([TRACKED, SLIDING, STICKING, FAR]), np.ones(k), np.zeros((k, 2)),
                   np.array([0, 1, 0, 0]), np.array([1, 2]), np.ones(k), np.ones(k),
                   np.tile(np.eye(3), (k, 1, 1)), np.zeros((k, 3)), np.array([0, 0, 0, 1]),
                   np.array([0, 1, 2]), np.array([0, 1, 2, -1]))
    x = np.zeros(int(m.sizes[Z_NX]))
    x[0] = x[7] = 1.0
    x[nq + nv:nq + nv + int(dims.sum())] = 0.5
    return m, s, x


def warm():
    """Compiles or loads the engine's kernels: one evaluation of `toy_model`, its far pass and
    its witness kernels (`regular_rates`, `witness_now`)."""
    from drake_dock.core.kernels.records import pack
    from drake_dock.core.kernels.witness_values import (due_far, far_witness, regular_rates,
                                                        witness_now)
    m, s, x = toy_model()
    mp, sp = pack(m), pack(s)
    nbush, k, F = m.bush_frames.shape[0], s.code.shape[0], m.frame_body.shape[0]
    buf = np.empty(layout(int(m.sizes[Z_NX]), k, int(m.sizes[Z_NV]), F, nbush,
                          s.near.shape[0])[-1])
    evaluate(mp, sp, x, np.zeros(int(m.sizes[Z_NV])), buf)
    far_witness(mp, sp, buf)
    due_far(mp, sp, buf)
    n_near = s.near.shape[0]
    rows = buf[int(m.sizes[Z_NX]):int(m.sizes[Z_NX]) + n_near * K.ROW].reshape((n_near, K.ROW))
    regular_rates(mp, rows, s.near, np.arange(n_near), np.empty(n_near))
    at = np.arange(n_near, dtype=np.intp)     # arguments of the run's types, values aside
    witness_now(mp, rows.ravel(), rows, at, at, at * K.ROW + K.GAP, at * K.ROW + K.VN, at,
                s.near.astype(np.int64), at.astype(np.int64))
