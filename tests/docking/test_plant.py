"""The three-body plant with the Stewart element alone (no contact): conservation laws and the
closed-form two-body frequency."""
import copy
import math

import numpy as np
import pytest
from pydrake.math import RigidTransform, RotationMatrix, RollPitchYaw
from pydrake.multibody.math import SpatialVelocity
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.framework import DiagramBuilder

from drake_dock.docking.model.plant import PlantSpec, add_docking_plant, body_momenta
from drake_dock.systems.simulator import make_simulator


def _build(scenario):
    builder = DiagramBuilder()
    dp = add_docking_plant(builder, PlantSpec.of(scenario))
    diagram = builder.Build()
    return diagram, dp


def _simulator(diagram, context, accuracy):
    sim = make_simulator(diagram, SimulatorConfig(integration_scheme="runge_kutta5",
                                                  accuracy=accuracy, max_step_size=0.01),
                         context=context)
    sim.Initialize()
    return sim


def test_free_flight_conserves_momentum(paper_scenario):
    diagram, dp = _build(paper_scenario)
    ctx = diagram.CreateDefaultContext()
    pc = dp.plant.GetMyContextFromRoot(ctx)
    rng = np.random.default_rng(3)
    # Every body moves and spins; the APDS starts off its equilibrium (spring loaded).
    poses = {"target": RigidTransform(RollPitchYaw(0.1, -0.2, 0.3), [0.1, -0.2, 0.05]),
             "chaser": RigidTransform(RollPitchYaw(math.pi + 0.05, 0.1, 2.0), [0.2, 0.1, 9.0])}
    X_TA = RigidTransform(RollPitchYaw(0.05, -0.04, 0.08), [0.01, -0.02, 5.05])
    poses["target_apds"] = poses["target"] @ X_TA
    for name, X in poses.items():
        dp.plant.SetFreeBodyPose(pc, dp.bodies[name], X)
        dp.plant.SetFreeBodySpatialVelocity(
            pc, dp.bodies[name], SpatialVelocity(rng.normal(0, 0.3, 3), rng.normal(0, 0.5, 3)))
    P0, L0, sP, sL = body_momenta(dp, pc)
    sim = _simulator(diagram, ctx, 1e-11)
    sim.AdvanceTo(1.0)
    P1, L1, _, _ = body_momenta(dp, pc)
    assert np.abs(P1 - P0).max() <= 1e-9 * sP
    assert np.abs(L1 - L0).max() <= 1e-9 * sL
    # The bushing did work: the state really moved and exchanged momentum between bodies.
    v_apds = dp.plant.EvalBodySpatialVelocityInWorld(pc, dp.bodies["target_apds"])
    assert np.linalg.norm(v_apds.translational()) > 1e-3


def test_undamped_axial_two_body_frequency(paper_scenario):
    s = copy.deepcopy(paper_scenario)
    s.stewart.force_damping = [0.0, 0.0, 0.0]
    s.stewart.torque_damping = [0.0, 0.0, 0.0]
    diagram, dp = _build(s)
    ctx = diagram.CreateDefaultContext()
    pc = dp.plant.GetMyContextFromRoot(ctx)
    c = s.stewart.p_TA[2]
    dp.plant.SetFreeBodyPose(pc, dp.bodies["target"], RigidTransform())
    dp.plant.SetFreeBodyPose(pc, dp.bodies["target_apds"], RigidTransform([0, 0, c + 0.01]))
    dp.plant.SetFreeBodyPose(pc, dp.bodies["chaser"],
                             RigidTransform(RotationMatrix.MakeXRotation(math.pi), [0, 0, 20]))
    sim = _simulator(diagram, ctx, 1e-12)
    dt, T = 1e-3, 12.0
    t = np.arange(0.0, T + dt / 2, dt)
    x = np.empty_like(t)
    for k, tk in enumerate(t):
        sim.AdvanceTo(tk)
        za = dp.plant.EvalBodyPoseInWorld(pc, dp.bodies["target_apds"]).translation()[2]
        zt = dp.plant.EvalBodyPoseInWorld(pc, dp.bodies["target"]).translation()[2]
        x[k] = za - zt - c
    # Zero crossings by linear interpolation (the error vanishes at an inflection point).
    i = np.flatnonzero(np.sign(x[:-1]) != np.sign(x[1:]))
    tc = t[i] - x[i] * dt / (x[i + 1] - x[i])
    half_periods = np.diff(tc)
    omega = math.pi / half_periods.mean()
    m1, m2 = s.bodies.target.mass, s.bodies.target_apds.mass
    k3 = s.stewart.force_stiffness[2]
    expected = math.sqrt(k3 * (m1 + m2) / (m1 * m2))
    assert len(tc) >= 8
    assert omega == pytest.approx(expected, rel=1e-4)
