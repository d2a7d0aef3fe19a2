"""Drake's `LinearBushingRollPitchYaw` force element in compiled code, on its two frames given as
`frames.Frame` records: the spatial forces the bushing applies on them, and their damping part
alone.

Written from the formulas of Drake's documentation (v1.51; the class documentation of
LinearBushingRollPitchYaw, its methods CalcBushingSpatialForceOnFrameA/C, and of
math::RollPitchYaw), and tested against Drake itself (tests/systems/test_bushing_kernel.py)
and against closed forms (tests/core/test_bushing_closed_forms.py). Drake's documentation
numbers no equations; the references [D1]-[D7] below are to its named statements:

[D1] class doc: "Frame B is the bushing frame whose origin Bo is halfway between Ao and Co and
     whose unit vectors are 'halfway' (in an angle-axis sense) between those of A and C";
[D2] class doc: the gimbal torques tau = -K012 q - D012 q', q = [q0 q1 q2] the roll-pitch-yaw
     angles of R_AC (range -pi < q0 <= pi, -pi/2 <= q1 <= pi/2, -pi < q2 <= pi);
[D3] class doc: r = p_AoCo = [x y z]_B, f = [fx fy fz]_B = -Kxyz [x y z] - Dxyz [x' y' z'];
[D4] class doc, "Advanced: Relationship of t to tau": t = [tx ty tz]_A = Np^T tau, found by
     equating powers t . w_AC = tau . q';
[D5] math::RollPitchYaw::CalcMatrixRelatingRpyDtToAngularVelocityInParent: q' = Np w_AC_A,
     Np = [[cy/cp, sy/cp, 0], [-sy, cy, 0], [cy tp, sy tp, 1]] (c, s, t: cos, sin, tan of
     pitch p and yaw y);
[D6] CalcBushingSpatialForceOnFrameA/C: the forces on C are a torque t on C and the force f at
     the point Cp of C; those on A a torque -t and the force -f at the point Ap of A; Ap and Cp
     coincide with Bo. F_A = [-t + p_AoAp x (-f), -f] about Ao, F_C = [t + p_CoCp x f, f]
     about Co;
[D7] math::RollPitchYaw::DoesCosPitchAngleViolateGimbalLockTolerance: |cos p| < 0.008
     (pitch within 0.458 deg of +-90 deg): Drake throws std::runtime_error there.

The computation (A, C the two frames, W the world; all inputs in W):

1. R_AC = R_WA^T R_WC, r_A = R_WA^T (p_WC - p_WA), w_AC_A = R_WA^T (w_WC - w_WA) and
   v_ACo_A = R_WA^T (v_WC - v_WA - w_WA x (p_WC - p_WA)) (Co's velocity in A).
2. Half-angle frame B [D1]: e = [e0, e_v] the quaternion of R_AC with e0 >= 0; the quaternion
   of R_AB (angle theta/2 about the same axis) is [sqrt((1 + e0)/2), e_v / (2 sqrt((1 + e0)/2))].
   No singularity: e0 >= 0 keeps the half-angle's cosine >= sqrt(1/2).
3. [x y z] = R_AB^T r_A [D3] and, as Drake takes frame B's angular velocity in A to be
   w_AC / 2 (CalcBushing_xyzDt), [x' y' z'] = R_AB^T (v_ACo_A - w_AC_A / 2 x r_A): the
   derivative in B of r. (It is the exact time derivative of [x y z] when R_AC turns about a
   fixed axis; otherwise B's angular velocity differs from w_AC / 2 and so does this rate.)
4. q = rpy(R_AC) [D2]: pitch = atan2(-R_AC[2,0], sqrt((R22^2 + R21^2 + R10^2 + R00^2) / 2)),
   roll = atan2(R21, R22), yaw = atan2(R10, R00); q' = Np w_AC_A [D5].
5. tau = -k_t q - d_t q' [D2], t_A = Np^T tau [D4]; f_B = -k_f [x y z] - d_f [x' y' z'],
   f_A = R_AB f_B [D3].
6. In W (t = R_WA t_A, f = R_WA f_A, r = p_WC - p_WA, Bo = Ao + r / 2) [D6]:
   F_C = [t - r/2 x f, f] at Co and F_A = [-t - r/2 x f, -f] at Ao.
   So F_A shifted to Co is exactly -F_C (F_A's torque about Co is -t - r/2 x f + r x f):
   action and reaction, the force -f acting on A at the point Ap coincident with Bo (the
   midpoint of Ao and Co), neither at Ao nor at the point of A coincident with Co. Drake's
   CalcBushingSpatialForceOnFrameA returns F_A about Ao expressed in A, and
   CalcBushingSpatialForceOnFrameC returns F_C about Co expressed in C (not in W).

The force is linear in the constants: the damping part (the k's set to zero) is
F_damp = [t_d -/+ r/2 x f_d, +/- f_d] with tau_d = -d_t q', f_d = -d_f [x' y' z']; the spring
part is F - F_damp. The power of the whole (F_C . V_C + F_A . V_A, V = [w, v_origin]) is
tau . q' + f_B . [x' y' z'].

Singularity: Np has 1 / cos(pitch); at pitch = +-90 deg (gimbal lock) the rates q' and the
torque t are undefined, and near it they lose accuracy. Where Drake throws [D7]
(|cos pitch| < GIMBAL_LOCK_COS_PITCH = 0.008), `bushing_wrenches` writes NaN into all four
rows of F and returns GIMBAL_LOCK; it returns NONFINITE if the inputs make any output non-finite
(NaN or inf in, say); OK otherwise. A caller must check the status (the NaNs propagate if it
does not). A 180 deg rotation (e0 = 0) is not singular but B's sign is ambiguous there, as in
Drake (a measure-zero set; the sign of e_v then decides).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from drake_dock.core.kernels.frames import Frame

OK, GIMBAL_LOCK, NONFINITE = 0, 1, 2
GIMBAL_LOCK_COS_PITCH = 0.008     # Drake's RollPitchYaw::kGimbalLockToleranceCosPitchAngle


@njit(cache=True)
def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True)
def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True)
def _mv(R, a):
    """R a, R a row-major 9-tuple."""
    return (R[0] * a[0] + R[1] * a[1] + R[2] * a[2],
            R[3] * a[0] + R[4] * a[1] + R[5] * a[2],
            R[6] * a[0] + R[7] * a[1] + R[8] * a[2])


@njit(cache=True)
def _mtv(R, a):
    """R^T a, R a row-major 9-tuple."""
    return (R[0] * a[0] + R[3] * a[1] + R[6] * a[2],
            R[1] * a[0] + R[4] * a[1] + R[7] * a[2],
            R[2] * a[0] + R[5] * a[1] + R[8] * a[2])


@njit(cache=True)
def _tuple9(R):
    return (R[0, 0], R[0, 1], R[0, 2], R[1, 0], R[1, 1], R[1, 2], R[2, 0], R[2, 1], R[2, 2])


@njit(cache=True)
def _vec(a):
    return (a[0], a[1], a[2])


@njit(cache=True, inline="always")
def _mtm(A, B):
    """A^T B for row-major 9-tuples."""
    return (A[0] * B[0] + A[3] * B[3] + A[6] * B[6], A[0] * B[1] + A[3] * B[4] + A[6] * B[7],
            A[0] * B[2] + A[3] * B[5] + A[6] * B[8], A[1] * B[0] + A[4] * B[3] + A[7] * B[6],
            A[1] * B[1] + A[4] * B[4] + A[7] * B[7], A[1] * B[2] + A[4] * B[5] + A[7] * B[8],
            A[2] * B[0] + A[5] * B[3] + A[8] * B[6], A[2] * B[1] + A[5] * B[4] + A[8] * B[7],
            A[2] * B[2] + A[5] * B[5] + A[8] * B[8])


@njit(cache=True)
def quaternion(R):
    """The unit quaternion (w, x, y, z), w >= 0, of the rotation R (row-major 9-tuple), by the
    largest of 1 + trace and 1 + 2 R_ii - trace (Shepperd's choice)."""
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = R
    tr = m00 + m11 + m22
    if tr >= m00 and tr >= m11 and tr >= m22:
        s = 2.0 * math.sqrt(1.0 + tr)
        w, x, y, z = 0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s
    elif m00 >= m11 and m00 >= m22:
        s = 2.0 * math.sqrt(1.0 + 2.0 * m00 - tr)
        w, x, y, z = (m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s
    elif m11 >= m22:
        s = 2.0 * math.sqrt(1.0 + 2.0 * m11 - tr)
        w, x, y, z = (m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s
    else:
        s = 2.0 * math.sqrt(1.0 + 2.0 * m22 - tr)
        w, x, y, z = (m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if w < 0.0:
        n = -n
    return w / n, x / n, y / n, z / n


@njit(cache=True)
def half_rotation(R):
    """R_AB = R^(1/2), the rotation by half the angle about the same axis, of R = R_AC
    (row-major 9-tuples) [D1]."""
    w, x, y, z = quaternion(R)
    e0 = math.sqrt(0.5 * (1.0 + w))
    h = 0.5 / e0
    e1, e2, e3 = x * h, y * h, z * h
    return (1.0 - 2.0 * (e2 * e2 + e3 * e3), 2.0 * (e1 * e2 - e0 * e3), 2.0 * (e1 * e3 + e0 * e2),
            2.0 * (e1 * e2 + e0 * e3), 1.0 - 2.0 * (e1 * e1 + e3 * e3), 2.0 * (e2 * e3 - e0 * e1),
            2.0 * (e1 * e3 - e0 * e2), 2.0 * (e2 * e3 + e0 * e1), 1.0 - 2.0 * (e1 * e1 + e2 * e2))


@njit(cache=True)
def roll_pitch_yaw(R):
    """Drake's roll-pitch-yaw angles (space-fixed X-Y-Z) of R (row-major 9-tuple): R = Rz(yaw)
    Ry(pitch) Rx(roll), -pi < roll <= pi, -pi/2 <= pitch <= pi/2, -pi < yaw <= pi [D2]."""
    c = math.sqrt(0.5 * (R[8] * R[8] + R[7] * R[7] + R[3] * R[3] + R[0] * R[0]))
    return math.atan2(R[7], R[8]), math.atan2(-R[6], c), math.atan2(R[3], R[0])


@njit(cache=True)
def _relative(R_WA, p_WA, R_WC, p_WC):
    RA = _tuple9(R_WA)
    R_AC = _mtm(RA, _tuple9(R_WC))
    d_W = _sub(_vec(p_WC), _vec(p_WA))
    return RA, R_AC, d_W, _mtv(RA, d_W)


@njit(cache=True)
def bushing_coordinates(A, C, xyz, rpy):
    """The bushing's coordinates between its frames A and C (`frames.Frame`s; their poses are
    read): xyz (3,) <- [x y z], the position of Co from Ao in the
    half-angle frame B [D3]; rpy (3,) <- the roll-pitch-yaw angles of R_AC [D2]. The potential
    energy is 1/2 k_f . xyz^2 + 1/2 k_t . rpy^2. Returns OK, or GIMBAL_LOCK where the angles'
    rates are undefined (|cos pitch| < GIMBAL_LOCK_COS_PITCH; the coordinates are written)."""
    _, R_AC, _, r_A = _relative(A.R, A.o, C.R, C.o)
    b = _mtv(half_rotation(R_AC), r_A)
    q = roll_pitch_yaw(R_AC)
    for i in range(3):
        xyz[i] = b[i]
        rpy[i] = q[i]
    return GIMBAL_LOCK if abs(math.cos(q[1])) < GIMBAL_LOCK_COS_PITCH else OK


@njit(cache=True)
def _pair(tau, f_B, a, b, cy, sy, sp, RA, R_AB, half, F_C, F_A):
    """F_C <- [t - r/2 x f, f] about Co and F_A <- [-t - r/2 x f, -f] about Ao, in W, from the
    gimbal torques tau and the force f_B in B [D4, D6]."""
    t_A = (a * tau[0] - sy * tau[1] + a * sp * tau[2],       # Np^T tau
           b * tau[0] + cy * tau[1] + b * sp * tau[2],
           tau[2])
    t = _mv(RA, t_A)
    f = _mv(RA, _mv(R_AB, f_B))
    m = _cross(half, f)
    for i in range(3):
        F_C[i] = t[i] - m[i]
        F_C[3 + i] = f[i]
        F_A[i] = -t[i] - m[i]
        F_A[3 + i] = -f[i]


@njit(cache=True)
def bushing_wrenches(A, C, gains, F):
    """The spatial forces [torque, force] (6,) in the world frame that Drake's
    LinearBushingRollPitchYaw(frameA, frameC, k_t, d_t, k_f, d_f) applies, into the rows of F
    (4, 6): F_C on frame C about its origin Co, F_A on frame A about its origin Ao, then
    F_C_damp and F_A_damp, their damping parts (the same with k_t = k_f = 0). Inputs: the
    frames A and C (`frames.Frame`s: world rotation, origin, angular velocity and origin
    velocity, all in the world frame) and ``gains`` (4, 3), the rows k_t, d_t, k_f, d_f as
    given to Drake's constructor. Returns OK; GIMBAL_LOCK (outputs NaN) where Drake throws,
    |cos pitch| < GIMBAL_LOCK_COS_PITCH; NONFINITE if an output is not finite. Formulas: the
    module docstring."""
    R_WA, p_WA, w_WA, v_WA = A
    R_WC, p_WC, w_WC, v_WC = C
    k_t, d_t, k_f, d_f = gains[0], gains[1], gains[2], gains[3]
    F_C, F_A, F_C_damp, F_A_damp = F[0], F[1], F[2], F[3]
    RA, R_AC, d_W, r_A = _relative(R_WA, p_WA, R_WC, p_WC)
    w_A = _mtv(RA, _sub(_vec(w_WC), _vec(w_WA)))
    v_rel = _sub(_sub(_vec(v_WC), _vec(v_WA)), _cross(_vec(w_WA), d_W))
    v_A = _mtv(RA, v_rel)
    R_AB = half_rotation(R_AC)
    xyz = _mtv(R_AB, r_A)
    h = _cross((0.5 * w_A[0], 0.5 * w_A[1], 0.5 * w_A[2]), r_A)
    xyz_dt = _mtv(R_AB, _sub(v_A, h))
    roll, pitch, yaw = roll_pitch_yaw(R_AC)
    cp, sp = math.cos(pitch), math.sin(pitch)
    if abs(cp) < GIMBAL_LOCK_COS_PITCH:
        for i in range(6):
            F_C[i] = F_A[i] = F_C_damp[i] = F_A_damp[i] = np.nan
        return GIMBAL_LOCK
    cy, sy = math.cos(yaw), math.sin(yaw)
    a, b = cy / cp, sy / cp                       # Np = [[a, b, 0], [-sy, cy, 0], [a sp, b sp, 1]]
    q_dt = (a * w_A[0] + b * w_A[1], -sy * w_A[0] + cy * w_A[1],
            sp * (a * w_A[0] + b * w_A[1]) + w_A[2])
    q = (roll, pitch, yaw)
    tau_d = (-d_t[0] * q_dt[0], -d_t[1] * q_dt[1], -d_t[2] * q_dt[2])
    tau = (tau_d[0] - k_t[0] * q[0], tau_d[1] - k_t[1] * q[1], tau_d[2] - k_t[2] * q[2])
    f_d = (-d_f[0] * xyz_dt[0], -d_f[1] * xyz_dt[1], -d_f[2] * xyz_dt[2])
    f = (f_d[0] - k_f[0] * xyz[0], f_d[1] - k_f[1] * xyz[1], f_d[2] - k_f[2] * xyz[2])
    half = (0.5 * d_W[0], 0.5 * d_W[1], 0.5 * d_W[2])
    _pair(tau, f, a, b, cy, sy, sp, RA, R_AB, half, F_C, F_A)
    _pair(tau_d, f_d, a, b, cy, sy, sp, RA, R_AB, half, F_C_damp, F_A_damp)
    for i in range(6):
        if not (math.isfinite(F_C[i]) and math.isfinite(F_A[i])
                and math.isfinite(F_C_damp[i]) and math.isfinite(F_A_damp[i])):
            return NONFINITE
    return OK


def warm():
    """Compiles (or loads) the kernels with the argument types of the compiled engine's calls
    (`forces.element_forces`): frames whose rotations are views of a stacked array, the
    gains (4, 3) and the forces (4, 6) C-contiguous, the coordinates views of a row."""
    R, z = np.tile(np.eye(3), (2, 1, 1)), (0.0, 0.0, 0.0)
    A, C = Frame(R[0], z, z, z), Frame(R[1], z, z, z)
    bush = np.zeros((1, 6))
    bushing_wrenches(A, C, np.ones((4, 3)), np.zeros((4, 6)))
    bushing_coordinates(A, C, bush[0, 0:3], bush[0, 3:6])
