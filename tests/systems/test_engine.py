"""The compiled engine (`drake_dock.core.kernels.engine`, `drake_dock.systems.engine`) against
the MultibodyPlant, the model and reference: the frames' poses and twists, q', M, M^-1, the
velocity-product terms, the force elements (gravity, the Stewart bushing and its damper's
power), the energies and the contact rows of the docking plant and of small scenes at random
states; and whole evaluations in contact (sticking and sliding couples, an input wrench)
against the equations they solve, assembled from Drake's mass matrix, forces and Jacobians:
M v' = tau - C v + sum W lambda, the constraint rows of each mode (Eq. 48-52) and Coulomb's
law for the sliding couples."""
import math

import numpy as np
import pytest
from pydrake.multibody.tree import JacobianWrtVariable, MultibodyForces
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorConfig

from drake_dock.core.couple import closest_point_conditions
from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels.couple_row import CoupleRow
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.plant import StewartDamperPower, stewart_potential
from drake_dock.studies.small_scenes import disk_on_incline, rod_on_edge, stool
from drake_dock.systems.contact_types import ContactOptions

RNG = np.random.default_rng(11)
KV = JacobianWrtVariable.kV


@pytest.fixture(scope="module")
def docking(paper_scenario):
    dd = build_docking_diagram(DiagramSpec.of(paper_scenario))
    return dd.contact, dd.dp


def _random_state(system):
    plant = system.plant
    q = plant.GetPositions(plant.CreateDefaultContext()).copy()
    for b in system.engine.model.qs:
        a = RNG.normal(size=4)
        q[b:b + 4] = a / np.linalg.norm(a)
        q[b + 4:b + 7] = RNG.normal(0, 0.5, 3)
    return q, RNG.normal(0, 0.7, system.nv)


def _plant_context(system, q, v):
    ctx = system.plant.CreateDefaultContext()
    system.plant.SetPositions(ctx, q)
    system.plant.SetVelocities(ctx, v)
    return ctx


def _element_force(plant, ctx):
    f = MultibodyForces(plant)
    plant.CalcForceElementsContribution(ctx, f)
    return plant.CalcGeneralizedForces(ctx, f)


def test_docking_plant_is_free_bodies_with_offset_frames(docking):
    system, _ = docking
    m = system.engine.model
    assert len(m.qs) == 3 and system.nv == 18 and len(m.bush_frames) == 1
    assert np.abs(m.p_BF).max() > 0


@pytest.mark.parametrize("trial", range(3))
def test_kinematics_mass_forces_and_energy_equal_the_plants(docking, trial):
    system, dp = docking
    eng, plant = system.engine, system.plant
    q, v = _random_state(system)
    # The APDS near its anchor (the bushing's angles away from gimbal lock).
    pc = _plant_context(system, q, v)
    X_WT = dp.bodies["target"].EvalPoseInWorld(pc)
    X_TA = plant.GetFrameByName("stewart_anchor").GetFixedPoseInBodyFrame()
    tilt = RNG.normal(0, 0.3, 3)
    from pydrake.math import RigidTransform, RollPitchYaw
    X_WC = X_WT.multiply(X_TA).multiply(RigidTransform(RollPitchYaw(tilt), RNG.normal(0, 0.1, 3)))
    plant.SetFreeBodyPose(pc, dp.bodies["target_apds"], X_WC)
    q = plant.GetPositions(pc).copy()
    ctx = _plant_context(system, q, v)
    kin = eng.kinematics(q, v)
    for f, frame in enumerate(eng.frames):
        X, V = frame.CalcPoseInWorld(ctx), frame.CalcSpatialVelocityInWorld(ctx)
        np.testing.assert_allclose(kin.R[f], X.rotation().matrix(), atol=1e-14)
        np.testing.assert_allclose(kin.o[f], X.translation(), atol=1e-13)
        np.testing.assert_allclose(kin.w[f], V.rotational(), atol=1e-14)
        np.testing.assert_allclose(kin.v[f], V.translational(), atol=1e-12)
    M, Minv, a0, p_el, p_in, ke, pe = eng.dynamics(q, v, np.zeros(system.nv))
    M_ref = plant.CalcMassMatrix(ctx)
    np.testing.assert_allclose(M, M_ref, rtol=1e-13, atol=1e-10)
    np.testing.assert_allclose(Minv @ M_ref, np.eye(system.nv), atol=1e-11)
    tau = _element_force(plant, ctx)
    cv = plant.CalcInverseDynamics(ctx, np.zeros(system.nv), MultibodyForces(plant))
    np.testing.assert_allclose(M_ref @ a0, tau - cv, rtol=1e-10,
                               atol=1e-10 * np.abs(tau - cv).max())
    assert math.isclose(p_el, tau @ v, rel_tol=1e-11, abs_tol=1e-9)
    assert math.isclose(ke, plant.CalcKineticEnergy(ctx), rel_tol=1e-12)
    assert math.isclose(pe, stewart_potential(dp, ctx), rel_tol=1e-12, abs_tol=1e-12)
    # The damper's power, from the evaluation's scalars.
    modes = system.get_modes(system.CreateDefaultContext())
    x = np.zeros(eng.nx)
    x[:eng.nq], x[eng.nq:eng.nq + eng.nv] = q, v
    E = eng.evaluate(0.0, x, modes, np.zeros(system.nv))
    assert math.isclose(float(E.damper_power[0]), StewartDamperPower(dp)(q, v), rel_tol=1e-11,
                        abs_tol=1e-9)
    np.testing.assert_allclose(E.xdot[:eng.nq], plant.MapVelocityToQDot(ctx, v), atol=1e-14)


def test_gravity_and_energies_of_a_small_scene_equal_the_plants():
    system = disk_on_incline(math.radians(10.0)).system
    q, v = _random_state(system)
    ctx = _plant_context(system, q, v)
    M, Minv, a0, p_el, _, ke, pe = system.engine.dynamics(q, v, np.zeros(system.nv))
    tau = _element_force(system.plant, ctx)
    cv = system.plant.CalcInverseDynamics(ctx, np.zeros(system.nv),
                                          MultibodyForces(system.plant))
    np.testing.assert_allclose(M @ a0, tau - cv, rtol=1e-12, atol=1e-12)
    assert math.isclose(ke, system.plant.CalcKineticEnergy(ctx), rel_tol=1e-13)
    assert math.isclose(pe, system.plant.CalcPotentialEnergy(ctx), rel_tol=1e-13,
                        abs_tol=1e-13)


@pytest.mark.parametrize("trial", range(4))
def test_a_couple_is_projected_only_when_asked(docking, trial):
    """A couple evaluated unprojected (``project=False``) keeps the given u with no drift;
    projected, its drift is one Newton step on F(u) = 0 (Eq. 37-38, 40), -Fu^-1 F, from F and
    Fu of the conditions kernel (`closest_point_conditions`), and its u is u plus that step."""
    system, _ = docking
    eng = system.engine
    q, v = _random_state(system)
    kin = eng.kinematics(q, v)
    i = int(RNG.integers(len(system.pairs)))
    p = system.pairs[i]
    u = np.concatenate([0.5 * (pt.lower + pt.upper) + 0.1 * (pt.upper - pt.lower)
                        * RNG.uniform(-1, 1, pt.dim) for pt in (p.patch1, p.patch2)])
    fa, fb = eng.fidx[i]
    F, Fu = closest_point_conditions(p.kind, p.patch1, (kin.R[fa], kin.o[fa]), p.patch2,
                                     (kin.R[fb], kin.o[fb]), u)
    raw = eng.couple(i, u, kin, 1.0, project=False)
    np.testing.assert_array_equal(raw.u, u)
    np.testing.assert_array_equal(raw.drift, np.zeros(len(u)))
    c = eng.couple(i, u, kin, 1.0, project=True)
    step = -np.linalg.solve(Fu, F)
    np.testing.assert_allclose(c.drift, step, rtol=1e-8, atol=1e-12 * (1 + np.abs(u).max()))
    np.testing.assert_array_equal(c.u, u + c.drift)


@pytest.mark.parametrize("trial", range(4))
def test_contact_rows_equal_drakes_jacobians_and_bias(docking, trial):
    system, _ = docking
    eng, plant = system.engine, system.plant
    q, v = _random_state(system)
    ctx = _plant_context(system, q, v)
    kin = eng.kinematics(q, v)
    i = int(RNG.integers(len(system.pairs)))
    p = system.pairs[i]
    s1, s2 = RNG.normal(size=3), RNG.normal(size=3)          # the points in their frames
    X1, X2 = p.frame1.CalcPoseInWorld(ctx), p.frame2.CalcPoseInWorld(ctx)
    D = np.linalg.qr(RNG.normal(size=(3, 3)))[0]              # rows n, ta, tb
    row = np.zeros(K.ROW)
    row[K.P1:K.P1 + 3], row[K.P2:K.P2 + 3] = X1.multiply(s1), X2.multiply(s2)
    row[K.N:K.N + 3], row[K.TA:K.TA + 3], row[K.TB:K.TB + 3] = D
    r = eng.row(i, CoupleRow(row, 2), kin)
    world = plant.world_frame()
    J = (plant.CalcJacobianTranslationalVelocity(ctx, KV, p.frame1, s1, world, world)
         - plant.CalcJacobianTranslationalVelocity(ctx, KV, p.frame2, s2, world, world))
    ab = (plant.CalcBiasTranslationalAcceleration(ctx, KV, p.frame1, s1, world, world)
          - plant.CalcBiasTranslationalAcceleration(ctx, KV, p.frame2, s2, world, world))
    W = J.T @ D.T
    np.testing.assert_allclose(r.Wn, W[:, 0], atol=1e-13)
    np.testing.assert_allclose(r.Wt, W[:, 1:], atol=1e-13)
    np.testing.assert_allclose([r.bn, *r.bt], D @ ab.ravel(), atol=1e-12 * (1 + np.abs(ab).max()))


def _settled(make, X, V, t_end, inputs=None):
    sc = make()
    sim = Simulator(sc.system)
    ctx = sim.get_mutable_context()
    sc.set_state(ctx, X, V)
    if inputs is not None:
        inputs(sc, ctx)
    ApplySimulatorConfig(SimulatorConfig(integration_scheme="runge_kutta5", accuracy=1e-8,
                                         max_step_size=0.05), sim)
    ctx.SetAccuracy(1e-8)
    sim.Initialize()
    sim.AdvanceTo(t_end)
    return sc, ctx


@pytest.mark.parametrize("scene", ["stool", "rod"])
def test_an_evaluation_in_contact_solves_its_equations(scene):
    """Three sticking feet (offset frames on one body, the plane on the world), and a rod
    sliding on an edge under an input wrench: the engine's accelerations and forces satisfy
    the equations of motion with Drake's M, forces and Jacobians at the couples' points, each
    couple's constraint rows (Eq. 52 with Baumgarte's terms: zero normal acceleration, and
    zero tangential acceleration where it sticks), and Coulomb's law where it slides."""
    if scene == "stool":
        sc, ctx = _settled(lambda: stool(options=ContactOptions(zeno_speed=1e-2)),
                           (np.eye(3), np.array([0.0, 0.0, 0.25])),
                           (np.array([0.0, 0.0, 0.5]), np.array([0.2, 0.0, 0.0])), 0.4)
    else:
        def push(sc, ctx):
            sc.system.GetInputPort("rod_wrench").FixValue(ctx, [0.0, 0.0, 0.3, 4.0, 0.0, 0.0])
        sc, ctx = _settled(lambda: rod_on_edge(options=ContactOptions(zeno_speed=1e-2)),
                           (np.eye(3), np.array([0.0, 0.0, 0.0])),
                           (np.zeros(3), np.array([0.5, 0.0, 0.0])), 0.2, push)
    system = sc.system
    plant = system.plant
    modes = system.get_modes(ctx)
    contact = [i for i, st in enumerate(modes.pairs) if st.mode.in_contact]
    assert contact
    if scene == "stool":
        assert all(modes.pairs[i].mode == Mode.STICKING for i in contact)
    else:
        assert any(modes.pairs[i].mode == Mode.SLIDING for i in contact)
    E = system.eval(ctx)
    tau_in = system.input_force(ctx)
    if scene == "rod":
        assert np.abs(tau_in).max() > 0
    pc = _plant_context(system, E.q, E.v)
    M = plant.CalcMassMatrix(pc)
    cv = plant.CalcInverseDynamics(pc, np.zeros(system.nv), MultibodyForces(plant))
    rhs = _element_force(plant, pc) + tau_in - cv
    world = plant.world_frame()
    gf = np.zeros(system.nv)
    omega = system.options.baumgarte
    vdot = E.vdot
    for i in contact:
        p, row = system.pairs[i], E.row(i)
        P1, P2 = row[K.P1:K.P1 + 3], row[K.P2:K.P2 + 3]
        D = np.array([row[K.N:K.N + 3], row[K.TA:K.TA + 3], row[K.TB:K.TB + 3]])
        X1, X2 = p.frame1.CalcPoseInWorld(pc), p.frame2.CalcPoseInWorld(pc)
        s1, s2 = X1.inverse().multiply(P1), X2.inverse().multiply(P2)
        J = (plant.CalcJacobianTranslationalVelocity(pc, KV, p.frame1, s1, world, world)
             - plant.CalcJacobianTranslationalVelocity(pc, KV, p.frame2, s2, world, world))
        ab = (plant.CalcBiasTranslationalAcceleration(pc, KV, p.frame1, s1, world, world)
              - plant.CalcBiasTranslationalAcceleration(pc, KV, p.frame2, s2, world, world))
        W = J.T @ D.T
        lam = np.array([E.lam_n[i], *E.lam_t[i]])
        gf += W @ lam
        acc = W.T @ vdot + D @ ab.ravel() + np.array([row[K.BIAS_N], *row[K.BIAS_T:K.BIAS_T + 2]])
        gap, vn = row[K.GAP], row[K.VN]
        scale = 1 + np.abs(W).max() * np.abs(vdot).max()
        assert abs(acc[0] + 2 * omega * vn + omega ** 2 * gap) < 1e-9 * scale
        assert E.lam_n[i] > 0
        if modes.pairs[i].mode == Mode.STICKING:
            np.testing.assert_allclose(acc[1:], 0.0, atol=1e-9 * scale)
            assert np.hypot(*E.lam_t[i]) <= system.law.static_mu * E.lam_n[i] * (1 + 1e-12)
        else:
            vt = row[K.VT:K.VT + 2]
            direction = vt / np.linalg.norm(vt)
            np.testing.assert_allclose(E.lam_t[i], -system.law.mu * E.lam_n[i] * direction,
                                       rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(E.contact_force, gf, rtol=1e-10,
                               atol=1e-10 * (1 + np.abs(gf).max()))
    np.testing.assert_allclose(M @ vdot, rhs + gf, rtol=1e-10,
                               atol=1e-10 * (1 + np.abs(rhs).max() + np.abs(gf).max()))


def test_a_plant_with_a_joint_is_refused():
    """The engine describes free bodies only: a plant with a revolute joint is refused by
    name, before any simulation."""
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.multibody.tree import RevoluteJoint, SpatialInertia
    from drake_dock.core.patches import Circle, PlaneRect
    from drake_dock.systems.contact_system import ContactPair, RigidContactSystem
    plant = MultibodyPlant(0.0)
    body = plant.AddRigidBody("wheel", SpatialInertia.SolidSphereWithMass(1.0, 0.1))
    plant.AddJoint(RevoluteJoint("axle", plant.world_frame(), body.body_frame(), [0, 0, 1]))
    plant.Finalize()
    pair = ContactPair("rim", "CS", body.body_frame(), Circle(0.1), plant.world_frame(),
                       PlaneRect((-1, -1, -1), (2, 0, 0), (0, 2, 0)))
    with pytest.raises(ValueError, match="wheel.*free"):
        RigidContactSystem(plant, [pair])
