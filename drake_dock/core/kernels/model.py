"""The records of the compiled engine (`drake_dock.core.kernels.engine`): `Model` (what the
engine knows of a system, built once) and `ModeArrays` (the pairs' modes and far-pair data,
built once per sealed set of modes), their unpacking from `records.Packed`, the layout of an
evaluation's result buffer, and the codes they use."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels.records import f1, f2, f3, i1, i2

# Pair kinds (`couples`; `drake_dock.core.relations` maps the kinds to them).
CC, CS, PC, PS = K.CC, K.CS, K.PC, K.PS
# Modes (`drake_dock.core.hybrid.Mode`).
FAR, TRACKED, SLIDING, STICKING = 0, 1, 2, 3
# Witness kinds, in the order of `drake_dock.systems.witnesses.WITNESSES`: the impact (the gap
# of a tracked couple while positive, its rate while not), the couple's regularity (its least
# domain-end margin or conditioning margin), lambda_n, slip, the friction cone, the hand-over
# guard and a point-curve couple's side.
W_IMPACT, W_REGULAR, W_LAMBDA, W_SLIP, W_CONE, W_HANDOVER, W_SIDE = range(7)
NW = 7
# Hand-over edge maps (`drake_dock.core.handover.SurfaceEdge.kernel_map`): the surface's free
# parameter at the edge's parameter e is alpha e + beta, or component c of the edge curve's
# point (its frame's coordinates).
AFFINE, COMPONENT = 0, 1
# Options (`Model.options`).
O_MU, O_MU_S, O_OMEGA, O_V_SLIP, O_DRIFT_FB, O_DRIFT_TOL, O_COND_MIN, O_ENERGY, O_GUARD, \
    O_EARLY, O_HORIZON = range(11)
N_OPTIONS = 11
# Sizes (`Model.sizes`).
Z_NQ, Z_NV, Z_NU, Z_IE, Z_NX = range(5)
N_SIZES = 5
# Scalars of the results (section SC of `layout`), then each bushing's damper power; S_REPORT is
# 1 when the evaluation has something to report (S_BAD_PC, S_BUSH or S_STATUS), else 0.
S_STATUS, S_COND, S_BAD_PC, S_FAR_EARLY, S_FRICTION, S_P_EL, S_P_IN, S_FAR, S_KE, S_PE, \
    S_DUE, S_DRIFTING, S_BUSH, S_REPORT, S_DAMP = range(15)
# Per bushing in section BUSH: deflection x (3), roll-pitch-yaw (3), spatial force on C (6).
BUSH_ROW = 12


class Model(NamedTuple):
    """What the engine knows of a system, built once (`drake_dock.systems.engine`).
    Bodies b (`free_bodies` layout): qs, vs, mass, com (body frame), inertia about the centre
    of mass and its inverse (body frame); gravity (3,). Frames f: frame_body (-1: the world),
    R_BF, p_BF. Bushings n: bush_frames (frames A, C), bush_gains (torque stiffness, torque
    damping, force stiffness, force damping). Pairs i: pair_kind (CC ... PS), the patches'
    kernel kinds and parameters (`jets`; a point's prm1 is its coordinates and radius), fidx
    (frames 1, 2), uoff (their couples' places in u*), spans, lower, upper and bounded (1: not
    periodic) of u = (u1, u2); the far-pair data: frame_pair (index into frame_pairs) and the
    bounding sphere (centre1, radius1) of patch 1. Hand-over edges e of edge pair i:
    edge_first[i], edge_count[i]; edge_surface[e] the surface pair, edge_info[e] = (fixed,
    upper, map kind), edge_map[e] = (alpha, beta) or (component, 0). options (`O_*`) and
    sizes (`Z_*`)."""

    qs: np.ndarray
    vs: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    inertia_inv: np.ndarray
    gravity: np.ndarray
    frame_body: np.ndarray
    R_BF: np.ndarray
    p_BF: np.ndarray
    bush_frames: np.ndarray
    bush_gains: np.ndarray
    pair_kind: np.ndarray
    kind1: np.ndarray
    kind2: np.ndarray
    prm1: np.ndarray
    prm2: np.ndarray
    fidx: np.ndarray
    uoff: np.ndarray
    spans: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    bounded: np.ndarray
    frame_pair: np.ndarray
    frame_pairs: np.ndarray
    centre1: np.ndarray
    radius1: np.ndarray
    edge_first: np.ndarray
    edge_count: np.ndarray
    edge_surface: np.ndarray
    edge_info: np.ndarray
    edge_map: np.ndarray
    options: np.ndarray
    sizes: np.ndarray


@njit(cache=True)
def unpack_model(p):
    return Model(i1(p, 0), i1(p, 1), f1(p, 2), f2(p, 3), f3(p, 4), f3(p, 5), f1(p, 6),
                 i1(p, 7), f3(p, 8), f2(p, 9), i2(p, 10), f3(p, 11), i1(p, 12), i1(p, 13),
                 i1(p, 14), f2(p, 15), f2(p, 16), i2(p, 17), i1(p, 18), f2(p, 19), f2(p, 20),
                 f2(p, 21), i2(p, 22), i1(p, 23), i2(p, 24), f2(p, 25), f1(p, 26), i1(p, 27),
                 i1(p, 28), i1(p, 29), i2(p, 30), f2(p, 31), f1(p, 32), i1(p, 33))


class ModeArrays(NamedTuple):
    """The pairs' modes (`FAR` ... `STICKING`), orientation sigma, held sliding direction
    (has_dir 1 where one is held), the pairs in contact (rows, ascending), the pairs not far
    (near, ascending) and each pair's place among them (slot, -1 for a far pair: the couple rows
    and witness values of an evaluation are the near pairs' only), and per pair its far-pair
    data: clearance, distance at the last seek, the relative pose (R0, p0) of its frame 1 in
    its frame 2 then, and whether it was ever sought; built once per sealed set of modes."""

    code: np.ndarray
    sigma: np.ndarray
    slide_dir: np.ndarray
    has_dir: np.ndarray
    rows: np.ndarray
    clearance: np.ndarray
    distance: np.ndarray
    R0: np.ndarray
    p0: np.ndarray
    sought: np.ndarray
    near: np.ndarray
    slot: np.ndarray


@njit(cache=True)
def unpack_modes(p):
    return ModeArrays(i1(p, 0), f1(p, 1), f2(p, 2), i1(p, 3), i1(p, 4), f1(p, 5), f1(p, 6),
                      f3(p, 7), f2(p, 8), i1(p, 9), i1(p, 10), i1(p, 11))


@njit(cache=True)
def layout(nx, k, nv, nframes, nbush, nn):
    """The offsets of the result buffer's sections: xdot, the near pairs' couple rows
    (nn, couples.ROW, by `ModeArrays.slot`), lambda_n (k), lambda_t (k, 2), generalized contact
    force (nv), the near pairs' witness values (nn, NW), far travel bounds (k), the frames' R
    (F, 3, 3), o, w, v (F, 3), the scalars (`S_*` and the damper powers), the bushings
    (nbush, BUSH_ROW); and the total size."""
    XD = 0
    OUT = XD + nx
    LN = OUT + nn * K.ROW
    LT = LN + k
    GF = LT + 2 * k
    WV = GF + nv
    BD = WV + nn * NW
    FR = BD + k
    FO = FR + 9 * nframes
    FW = FO + 3 * nframes
    FV = FW + 3 * nframes
    SC = FV + 3 * nframes
    BU = SC + S_DAMP + nbush
    END = BU + BUSH_ROW * nbush
    return XD, OUT, LN, LT, GF, WV, BD, FR, FO, FW, FV, SC, BU, END
