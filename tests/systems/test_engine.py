"""The compiled engine (`drake_dock.core.kernels.engine`, `drake_dock.systems.engine`) against
the MultibodyPlant, the model and reference: the frames' poses and twists, q', M^-1, the
velocity-product terms and the contact rows of the docking plant at random states (bodies with
offset centres of mass and offset frames); and whole evaluations in contact (sticking and
sliding couples, an input wrench) equal to the plant-as-calculator path's."""
import math

import numpy as np
import pytest
from pydrake.multibody.tree import JacobianWrtVariable, MultibodyForces
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorConfig

from drake_dock.core.kernels.free_bodies import (body_kinematics, frame_kinematics,
                                                 mass_inverse_and_bias, point_rows, qdot)
from drake_dock.docking.diagram import build_docking_diagram
from drake_dock.studies.small_scenes import rod_on_edge, stool
from drake_dock.systems.contact_types import ContactOptions

RNG = np.random.default_rng(11)
KV = JacobianWrtVariable.kV


@pytest.fixture(scope="module")
def docking(paper_scenario):
    return build_docking_diagram(paper_scenario).contact.evaluator


def _random_state(ev):
    q = ev.plant.GetPositions(ev.plant.CreateDefaultContext()).copy()
    for b in ev.engine[0].qs:
        a = RNG.normal(size=4)
        q[b:b + 4] = 1.3 * a / np.linalg.norm(a)       # not unit: Drake normalises
        q[b + 4:b + 7] = RNG.normal(0, 0.5, 3)
    return q, RNG.normal(0, 0.7, ev.nv)


def _kinematics(B, q, v, F):
    nb = len(B.qs)
    Rb, pb, wb, vb = (np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3)),
                      np.empty((nb, 3)))
    body_kinematics(B.qs, B.vs, q, v, Rb, pb, wb, vb)
    R, o, w, vf = np.empty((F, 3, 3)), np.empty((F, 3)), np.empty((F, 3)), np.empty((F, 3))
    frame_kinematics(B.fb, B.R_BF, B.p_BF, Rb, pb, wb, vb, R, o, w, vf)
    return (Rb, pb, wb, vb), (R, o, w, vf)


def test_docking_plant_is_free_bodies_with_offset_frames(docking):
    B = docking.engine[0]
    assert len(B.qs) == 3 and docking.nv == 18
    assert np.abs(B.p_BF).max() > 0 or np.abs(B.c_B).max() > 0


@pytest.mark.parametrize("trial", range(3))
def test_kinematics_mass_and_bias_equal_the_plants(docking, trial):
    ev = docking
    B = ev.engine[0]
    q, v = _random_state(ev)
    ctx = ev.set_scratch(q, v)
    (Rb, pb, wb, vb), (R, o, w, vf) = _kinematics(B, q, v, len(ev.frames))
    for f, frame in enumerate(ev.frames):
        X, V = frame.CalcPoseInWorld(ctx), frame.CalcSpatialVelocityInWorld(ctx)
        np.testing.assert_allclose(R[f], X.rotation().matrix(), atol=1e-14)
        np.testing.assert_allclose(o[f], X.translation(), atol=1e-14)
        np.testing.assert_allclose(w[f], V.rotational(), atol=1e-14)
        np.testing.assert_allclose(vf[f], V.translational(), atol=1e-13)
    qd = np.empty(ev.nq)
    qdot(B.qs, B.vs, q, v, qd)
    np.testing.assert_allclose(qd, ev.plant.MapVelocityToQDot(ctx, v), atol=1e-14)
    Minv, cv = np.zeros((ev.nv, ev.nv)), np.zeros(ev.nv)
    mass_inverse_and_bias(B.vs, B.m, B.c_B, B.I_B_inv, B.I_B, Rb, wb, Minv, cv)
    M = ev.plant.CalcMassMatrix(ctx)
    np.testing.assert_allclose(Minv @ M, np.eye(ev.nv), atol=1e-11)
    ref = ev.plant.CalcInverseDynamics(ctx, np.zeros(ev.nv), MultibodyForces(ev.plant))
    np.testing.assert_allclose(cv, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())


@pytest.mark.parametrize("pair", range(4))
def test_contact_rows_equal_drakes_jacobians_and_bias(docking, pair):
    ev = docking
    B = ev.engine[0]
    q, v = _random_state(ev)
    ctx = ev.set_scratch(q, v)
    (Rb, pb, wb, vb), _ = _kinematics(B, q, v, len(ev.frames))
    i = RNG.integers(len(ev.pairs))
    p = ev.pairs[i]
    a, b = ev.fidx[i]
    s1, s2 = RNG.normal(size=3), RNG.normal(size=3)          # the points in their frames
    X1, X2 = p.frame1.CalcPoseInWorld(ctx), p.frame2.CalcPoseInWorld(ctx)
    p1, p2 = X1.multiply(s1), X2.multiply(s2)
    D = np.linalg.qr(RNG.normal(size=(3, 3)))[0]
    W, acc = np.empty((ev.nv, 3)), np.empty(3)
    point_rows(B.vs, pb, wb, B.fb[a], B.fb[b], p1, p2, D, W, acc)
    world = ev.plant.world_frame()
    J = (ev.plant.CalcJacobianTranslationalVelocity(ctx, KV, p.frame1, s1, world, world)
         - ev.plant.CalcJacobianTranslationalVelocity(ctx, KV, p.frame2, s2, world, world))
    ab = (ev.plant.CalcBiasTranslationalAcceleration(ctx, KV, p.frame1, s1, world, world)
          - ev.plant.CalcBiasTranslationalAcceleration(ctx, KV, p.frame2, s2, world, world))
    np.testing.assert_allclose(W, J.T @ D.T, atol=1e-13)
    np.testing.assert_allclose(acc, D @ ab.ravel(), atol=1e-12 * (1 + np.abs(ab).max()))


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
def test_an_evaluation_in_contact_equals_the_plant_path(scene):
    """Three sticking feet (offset frames on one body, the plane on the world), and a rod
    sliding on an edge under an input wrench: the engine's derivative, forces and couples
    equal those of the plant as calculator to round-off."""
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
    ev = system.evaluator
    assert ev.engine is not None
    modes = system.get_modes(ctx)
    assert any(st.mode.in_contact for st in modes.pairs)
    t = ctx.get_time()
    x = ctx.get_continuous_state_vector().CopyToVector()
    inputs = system._inputs(ctx)
    if scene == "rod":
        assert inputs[1] and np.abs(inputs[1][0][1]).max() > 0
    E1 = ev.evaluate(t, x, modes, inputs)
    engine, ev.engine = ev.engine, None
    try:
        E0 = ev.evaluate(t, x, modes, inputs)
    finally:
        ev.engine = engine
    scale = 1 + np.abs(E0.xdot).max()
    np.testing.assert_allclose(E1.xdot, E0.xdot, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(E1.lam_n, E0.lam_n, rtol=0, atol=1e-11 * (1 + E0.lam_n.max()))
    np.testing.assert_allclose(E1.contact_force, E0.contact_force, rtol=0,
                               atol=1e-11 * (1 + np.abs(E0.contact_force).max()))
    assert math.isclose(E1.external_power, E0.external_power, rel_tol=1e-12, abs_tol=1e-12)
    for c1, c0 in zip(E1.evals, E0.evals):
        assert (c1 is None) == (c0 is None)
        if c0 is not None:
            np.testing.assert_allclose(c1.p1, c0.p1, atol=1e-13)
            assert math.isclose(c1.gap, c0.gap, abs_tol=1e-13)
