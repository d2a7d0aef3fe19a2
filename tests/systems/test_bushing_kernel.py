"""The compiled bushing (`drake_dock.core.kernels.bushing`) against Drake's
LinearBushingRollPitchYaw in the docking plant (the Stewart element between the target's
`stewart_anchor` A and the target APDS's body frame C), at random states: unit quaternions,
positions and velocities of the three bodies, the APDS tilted up to 40 deg about a random axis
from the anchor and displaced up to 0.2 m. Compared: the spatial force on C
(`CalcBushingSpatialForceOnFrameC`, which Drake expresses in C) and on A
(`CalcBushingSpatialForceOnFrameA`, expressed in A); the plant's generalized forces of its
force elements against those assembled from F_C and F_A; the damping part against a context
with the stiffnesses set to zero, and its power against `StewartDamperPower`; pitch angles
near gimbal lock, and the gimbal lock itself (Drake throws, the kernel flags).

Relative errors: |kernel - Drake| / |Drake| for each 3-vector (torque, force; each body's
torque and force slots). Measured (200 states): F_C and F_A below 1e-14; the generalized
forces below 2e-13, in the APDS's torque slot alone (Drake forms it by shifting F_A to the
target's origin and then 5 m to the APDS's, terms that cancel; the other slots below 1e-15);
asserted 1e-12."""
import math

import numpy as np
import pytest
from pydrake.common.eigen_geometry import AngleAxis, Quaternion
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.math import SpatialVelocity
from pydrake.multibody.tree import MultibodyForces

from drake_dock.core.kernels.bushing import GIMBAL_LOCK, OK, bushing_wrenches
from drake_dock.core.kernels.frames import frame
from drake_dock.docking.model.plant import PlantSpec, StewartDamperPower, make_docking_plant

RNG = np.random.default_rng(2024)
N_STATES = 200
RTOL = 1e-12


@pytest.fixture(scope="module")
def dp(paper_scenario):
    return make_docking_plant(PlantSpec.of(paper_scenario))


def _unit_quaternion():
    a = RNG.normal(size=4)
    return Quaternion(a / np.linalg.norm(a))


def _set_state(dp, ctx, R_AC=None, tilt=math.radians(40.0), stroke=0.2):
    """Random poses and velocities of the three bodies, the APDS at R_AC (default: a random
    axis, an angle up to `tilt`) and a random offset up to `stroke` from the anchor."""
    plant = dp.plant
    X_WT = RigidTransform(RotationMatrix(_unit_quaternion()), RNG.normal(0, 2.0, 3))
    plant.SetFreeBodyPose(ctx, dp.bodies["target"], X_WT)
    plant.SetFreeBodyPose(ctx, dp.bodies["chaser"],
                          RigidTransform(RotationMatrix(_unit_quaternion()), RNG.normal(0, 2, 3)))
    if R_AC is None:
        axis = RNG.normal(size=3)
        R_AC = RotationMatrix(AngleAxis(RNG.uniform(0, tilt), axis / np.linalg.norm(axis)))
    d = RNG.normal(size=3)
    p_AC = d / np.linalg.norm(d) * stroke * RNG.uniform() ** (1 / 3)   # uniform in the ball
    X_TA = dp.bushing.frameA().GetFixedPoseInBodyFrame()
    plant.SetFreeBodyPose(ctx, dp.bodies["target_apds"], X_WT @ X_TA @ RigidTransform(R_AC, p_AC))
    for body in dp.bodies.values():
        plant.SetFreeBodySpatialVelocity(
            ctx, body, SpatialVelocity(RNG.normal(0, 0.5, 3), RNG.normal(0, 0.5, 3)))
    return plant.GetPositions(ctx), plant.GetVelocities(ctx)


def _frame(drake_frame, ctx):
    X = drake_frame.CalcPoseInWorld(ctx)
    V = drake_frame.CalcSpatialVelocityInWorld(ctx)
    return [np.ascontiguousarray(X.rotation().matrix()), np.array(X.translation()),
            np.array(V.rotational()), np.array(V.translational())]


def _constants(bushing):
    return [np.array(c, dtype=float) for c in (
        bushing.torque_stiffness_constants(), bushing.torque_damping_constants(),
        bushing.force_stiffness_constants(), bushing.force_damping_constants())]


def _kernel(dp, ctx):
    """(status, F_C, F_A, F_C_damp, F_A_damp, frame A's inputs, frame C's inputs)."""
    A = _frame(dp.bushing.frameA(), ctx)
    C = _frame(dp.bushing.frameC(), ctx)
    out = np.full((4, 6), -1.0)
    status = bushing_wrenches(frame(*A), frame(*C), np.array(_constants(dp.bushing)), out)
    return (status, *out, A, C)


def _in_world(F, R):
    return np.r_[R @ F.rotational(), R @ F.translational()]


def _rel(x, ref):
    """max over the 3-vector blocks of |x - ref| / |ref|."""
    x, ref = np.asarray(x).reshape(-1, 3), np.asarray(ref).reshape(-1, 3)
    return max(np.linalg.norm(a - b) / np.linalg.norm(b) for a, b in zip(x, ref))


def _generalized(dp, ctx, F_C, F_A):
    """The generalized forces of F_C (at Co) and F_A (at Ao): [tau + (p_P - p_Bo) x f, f] in each
    body's velocity slots (quaternion floating joints: v = [w_WB, v_WBo] in the world frame)."""
    plant = dp.plant
    g = np.zeros(plant.num_velocities())
    for frame, F in ((dp.bushing.frameA(), F_A), (dp.bushing.frameC(), F_C)):
        body = frame.body()
        p_P = frame.CalcPoseInWorld(ctx).translation()
        p_Bo = plant.EvalBodyPoseInWorld(ctx, body).translation()
        i = body.floating_velocities_start_in_v()
        g[i:i + 3] += F[:3] + np.cross(p_P - p_Bo, F[3:])
        g[i + 3:i + 6] += F[3:]
    return g


def _plant_generalized(plant, ctx):
    f = MultibodyForces(plant)
    plant.CalcForceElementsContribution(ctx, f)
    return plant.CalcGeneralizedForces(ctx, f)


def _slots(dp, g):
    """The target's and the target APDS's velocity slots (the chaser's are checked zero)."""
    idx = [dp.bodies[n].floating_velocities_start_in_v() for n in ("target", "target_apds")]
    return np.concatenate([g[i:i + 6] for i in idx])


def test_force_on_each_frame_matches_drake(dp):
    ctx = dp.plant.CreateDefaultContext()
    worst_C = worst_A = 0.0
    for _ in range(N_STATES):
        _set_state(dp, ctx)
        status, F_C, F_A, _, _, A, C = _kernel(dp, ctx)
        assert status == OK
        ref_C = _in_world(dp.bushing.CalcBushingSpatialForceOnFrameC(ctx), C[0])   # in C
        ref_A = _in_world(dp.bushing.CalcBushingSpatialForceOnFrameA(ctx), A[0])   # in A
        worst_C = max(worst_C, _rel(F_C, ref_C))
        worst_A = max(worst_A, _rel(F_A, ref_A))
    print(f"\nF_C max rel err {worst_C:.2e}, F_A (at Ao) max rel err {worst_A:.2e}")
    assert worst_C < RTOL and worst_A < RTOL


def test_generalized_forces_match_the_plant(dp):
    plant = dp.plant
    ctx = plant.CreateDefaultContext()
    chaser = dp.bodies["chaser"].floating_velocities_start_in_v()
    worst = 0.0
    for _ in range(N_STATES):
        _set_state(dp, ctx)
        status, F_C, F_A, _, _, _, _ = _kernel(dp, ctx)
        assert status == OK
        g, ref = _generalized(dp, ctx, F_C, F_A), _plant_generalized(plant, ctx)
        assert not ref[chaser:chaser + 6].any() and not g[chaser:chaser + 6].any()
        worst = max(worst, _rel(_slots(dp, g), _slots(dp, ref)))
    print(f"\ngeneralized forces max rel err {worst:.2e}")
    assert worst < RTOL


def test_damping_part_and_its_power(dp):
    plant = dp.plant
    ctx = plant.CreateDefaultContext()
    ctx0 = plant.CreateDefaultContext()
    dp.bushing.SetForceStiffnessConstants(ctx0, np.zeros(3))
    dp.bushing.SetTorqueStiffnessConstants(ctx0, np.zeros(3))
    damper_power = StewartDamperPower(dp)
    worst_F = worst_g = worst_P = 0.0
    for _ in range(N_STATES):
        q, v = _set_state(dp, ctx)
        plant.SetPositionsAndVelocities(ctx0, np.r_[q, v])
        status, _, _, F_Cd, F_Ad, A, C = _kernel(dp, ctx)
        assert status == OK
        ref_C = _in_world(dp.bushing.CalcBushingSpatialForceOnFrameC(ctx0), C[0])
        worst_F = max(worst_F, _rel(F_Cd, ref_C))
        g = _generalized(dp, ctx, F_Cd, F_Ad)
        worst_g = max(worst_g, _rel(_slots(dp, g), _slots(dp, _plant_generalized(plant, ctx0))))
        P_ref = damper_power(q, v)
        P_g = g @ v
        P_twist = F_Cd @ np.r_[C[2], C[3]] + F_Ad @ np.r_[A[2], A[3]]   # the frames' twists
        assert P_g <= 0.0 and P_ref <= 0.0
        worst_P = max(worst_P, abs(P_g - P_ref) / abs(P_ref), abs(P_twist - P_ref) / abs(P_ref))
    print(f"\ndamping: F_C max rel err {worst_F:.2e}, generalized {worst_g:.2e}, "
          f"power {worst_P:.2e}")
    assert worst_F < RTOL and worst_g < RTOL and worst_P < RTOL


@pytest.mark.parametrize("pitch_deg", [75.0, 88.0, 89.5, -89.5])
def test_large_pitch_still_matches_drake(dp, pitch_deg):
    """Up to Drake's gimbal-lock tolerance (|cos pitch| >= 0.008, |pitch| <= 89.54 deg), where
    1 / cos(pitch) amplifies the round-off by up to 125: RTOL, or RTOL x 0.1 / cos(pitch)
    beyond 84 deg (measured at 89.5 deg: 8e-13)."""
    ctx = dp.plant.CreateDefaultContext()
    worst = 0.0
    for _ in range(20):
        R_AC = RotationMatrix(RollPitchYaw(RNG.uniform(-0.5, 0.5), math.radians(pitch_deg),
                                           RNG.uniform(-0.5, 0.5)))
        _set_state(dp, ctx, R_AC=R_AC)
        status, F_C, F_A, _, _, A, C = _kernel(dp, ctx)
        assert status == OK
        worst = max(worst, _rel(F_C, _in_world(dp.bushing.CalcBushingSpatialForceOnFrameC(ctx),
                                               C[0])))
        g = _generalized(dp, ctx, F_C, F_A)
        worst = max(worst, _rel(_slots(dp, g), _slots(dp, _plant_generalized(dp.plant, ctx))))
    print(f"\npitch {pitch_deg} deg: max rel err {worst:.2e}")
    assert worst < RTOL * max(1.0, 0.1 / math.cos(math.radians(pitch_deg)))


@pytest.mark.parametrize("pitch_deg", [89.6, 90.0, -90.0])
def test_gimbal_lock_drake_throws_and_the_kernel_flags(dp, pitch_deg):
    ctx = dp.plant.CreateDefaultContext()
    _set_state(dp, ctx, R_AC=RotationMatrix(RollPitchYaw(0.2, math.radians(pitch_deg), -0.3)))
    with pytest.raises(RuntimeError, match="gimbal-lock"):
        dp.bushing.CalcBushingSpatialForceOnFrameC(ctx)
    with pytest.raises(RuntimeError, match="gimbal-lock"):
        _plant_generalized(dp.plant, ctx)
    status, F_C, F_A, F_Cd, F_Ad, _, _ = _kernel(dp, ctx)
    assert status == GIMBAL_LOCK
    assert all(np.isnan(F).all() for F in (F_C, F_A, F_Cd, F_Ad))
