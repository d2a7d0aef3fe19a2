"""The three-body docking plant (Sect. 2-3) in Drake.

A continuous-time MultibodyPlant with three floating bodies (quaternion floating joints; the
paper's z-x-z Euler angles are singular at the example's attitude):

- ``target``: the target spacecraft, frame at its mass centre;
- ``target_apds``: the target's APDS, frame = APDS frame (ring centre = mass centre);
- ``chaser``: the chaser spacecraft with its APDS fixed; the frame ``chaser_apds`` is welded at
  ``chaser_apds_offset`` (a1, b1, c1) in the chaser frame, axes parallel.

The Stewart element (Eq. 9-10) is Drake's LinearBushingRollPitchYaw between the frame
``stewart_anchor`` on the target at p_TA = (a, b, c) and the APDS frame, which matches the
paper's per-axis spring-damper to first order in the angles. No gravity (free flight in orbit).
Visual geometry is generated from the same analytic patches as the contact model.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from pydrake.common import MemoryFile
from pydrake.geometry import Cylinder, InMemoryMesh, Mesh
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.multibody.tree import (FixedOffsetFrame, LinearBushingRollPitchYaw, MultibodyForces,
                                    RotationalInertia, SpatialInertia)
from pydrake.multibody.math import SpatialVelocity

from drake_dock.docking.geometry.display_mesh import apds_mesh, mesh_to_obj
from drake_dock.docking.model.initial_state import InitialState
from drake_dock.docking.scenario.dimensions import ApdsGeometry

BODY_NAMES = ("target", "target_apds", "chaser")
APDS_NAMES = ("target_apds", "chaser_apds")

_COLORS = {"target": [0.75, 0.75, 0.78, 1.0], "chaser": [0.85, 0.8, 0.6, 1.0],
           "target_apds": [0.25, 0.45, 0.85, 1.0], "chaser_apds": [0.85, 0.4, 0.2, 1.0]}


@dataclasses.dataclass
class DockingPlant:
    plant: object
    scene_graph: object
    bodies: dict          # name -> RigidBody
    apds_frames: dict     # "target_apds" / "chaser_apds" -> Frame
    bushing: object


@dataclasses.dataclass(frozen=True)
class PlantSpec:
    """What the plant reads of a scenario, frozen: each body's mass (kg) and principal moments
    (kg m^2) in `BODY_NAMES` order, the Stewart element (the anchor p_TA on the target and its
    gains, Eq. 9-10), the chaser APDS frame's offset in the chaser frame, and the APDS's
    dimensions (`ApdsGeometry`'s fields, for its display mesh)."""

    bodies: tuple            # ((name, mass, (I_x, I_y, I_z)), ...)
    p_TA: tuple
    force_stiffness: tuple
    force_damping: tuple
    torque_stiffness: tuple
    torque_damping: tuple
    chaser_apds_offset: tuple
    apds: tuple              # dataclasses.astuple of the ApdsGeometry

    @classmethod
    def of(cls, scenario) -> "PlantSpec":
        b, st = scenario.bodies, scenario.stewart
        return cls(tuple((n, float(getattr(b, n).mass), tuple(map(float, getattr(b, n).inertia)))
                         for n in BODY_NAMES), *(tuple(map(float, v)) for v in (
                   st.p_TA, st.force_stiffness, st.force_damping, st.torque_stiffness,
                   st.torque_damping, scenario.chaser_apds_offset)),
                   dataclasses.astuple(scenario.geometry))

    @property
    def geometry(self) -> ApdsGeometry:
        return ApdsGeometry(*self.apds)


def _spatial_inertia(mass, inertia):
    return SpatialInertia.MakeFromCentralInertia(mass, np.zeros(3), RotationalInertia(*inertia))


def _apds_visual(geometry):
    verts, faces = apds_mesh(geometry)
    data = MemoryFile(mesh_to_obj(verts, faces), ".obj", "apds.obj")
    return Mesh(InMemoryMesh(mesh_file=data))


def add_docking_plant(builder, spec: PlantSpec) -> DockingPlant:
    """Adds the plant and SceneGraph of the three bodies of ``spec`` to ``builder``; finalized.
    (Drake integrates this plant itself: free flight with the Stewart element, no contact.)"""
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    return populate_plant(plant, scene_graph, spec)


def make_docking_plant(spec: PlantSpec, scene_graph=None) -> DockingPlant:
    """The same plant, not added to a diagram: the rigid contact system owns its state and uses
    it as a calculator. With ``scene_graph`` (in the caller's builder) its visual geometry is
    registered there, for MultibodyPositionToGeometryPose."""
    plant = MultibodyPlant(0.0)
    if scene_graph is not None:
        plant.RegisterAsSourceForSceneGraph(scene_graph)
    return populate_plant(plant, scene_graph, spec)


def populate_plant(plant, scene_graph, spec: PlantSpec, collision=None) -> DockingPlant:
    """Adds the three bodies of ``spec``, the Stewart element and (with a registered geometry
    source) the visual geometry to ``plant``, then finalizes it. ``collision(plant, bodies)``,
    if given, registers collision geometry before Finalize (the compliant baseline,
    `drake_dock.studies.compliant`)."""
    plant.mutable_gravity_field().set_gravity_vector(np.zeros(3))
    bodies = {name: plant.AddRigidBody(name, _spatial_inertia(mass, inertia))
              for name, mass, inertia in spec.bodies}
    anchor = plant.AddFrame(FixedOffsetFrame(
        "stewart_anchor", bodies["target"].body_frame(), RigidTransform(np.array(spec.p_TA))))
    chaser_apds = plant.AddFrame(FixedOffsetFrame(
        "chaser_apds", bodies["chaser"].body_frame(),
        RigidTransform(np.array(spec.chaser_apds_offset))))
    bushing = plant.AddForceElement(LinearBushingRollPitchYaw(
        anchor, bodies["target_apds"].body_frame(),
        np.array(spec.torque_stiffness), np.array(spec.torque_damping),
        np.array(spec.force_stiffness), np.array(spec.force_damping)))
    if plant.geometry_source_is_registered():
        mesh = _apds_visual(spec.geometry)
        plant.RegisterVisualGeometry(bodies["target_apds"], RigidTransform(), mesh,
                                     "target_apds_visual", np.array(_COLORS["target_apds"]))
        plant.RegisterVisualGeometry(bodies["chaser"], RigidTransform(
            np.array(spec.chaser_apds_offset)), mesh, "chaser_apds_visual",
            np.array(_COLORS["chaser_apds"]))
        # Spacecraft hulls, for orientation only (not contact geometry).
        # The target's runs from 1 m behind its mass centre to 2 m behind its APDS (0.5 m long
        # when the APDS is within 1 m of the mass centre).
        length = float(spec.p_TA[2]) - 1.0
        length = length if length > 0 else 0.5
        plant.RegisterVisualGeometry(bodies["target"], RigidTransform([0, 0, length / 2 - 1.0]),
                                     Cylinder(1.2, length), "target_hull",
                                     np.array(_COLORS["target"]))
        off = float(spec.chaser_apds_offset[2])
        plant.RegisterVisualGeometry(bodies["chaser"], RigidTransform([0, 0, off - 1.0 - 1.5]),
                                     Cylinder(1.2, 3.0), "chaser_hull",
                                     np.array(_COLORS["chaser"]))
    if collision is not None:
        collision(plant, bodies)
    plant.Finalize()
    return DockingPlant(plant, scene_graph, bodies,
                        {"target_apds": bodies["target_apds"].body_frame(),
                         "chaser_apds": chaser_apds}, bushing)


def set_initial_state(dp: DockingPlant, plant_context, state: InitialState):
    """Writes the poses and spatial velocities of `InitialState` into the plant context."""
    for name, (R, p) in state.X_WB.items():
        dp.plant.SetFreeBodyPose(plant_context, dp.bodies[name],
                                 RigidTransform(RotationMatrix(R), p))
        w, v = state.V_WB[name]
        dp.plant.SetFreeBodySpatialVelocity(plant_context, dp.bodies[name],
                                            SpatialVelocity(w, v))


def body_momenta(dp: DockingPlant, plant_context, about=np.zeros(3)):
    """Total linear momentum and angular momentum about ``about`` (world frame) of the three
    bodies, and their scales: sum |m v| and sum |m p x v| + |I w| over the bodies."""
    P = np.zeros(3)
    L = np.zeros(3)
    sP = sL = 0.0
    for name, body in dp.bodies.items():
        X = dp.plant.EvalBodyPoseInWorld(plant_context, body)
        V = dp.plant.EvalBodySpatialVelocityInWorld(plant_context, body)
        m = body.default_mass()
        I_B = body.default_rotational_inertia().CopyToFullMatrix3()
        R = X.rotation().matrix()
        p = X.translation() - about
        mv = m * V.translational()
        Iw = R @ I_B @ R.T @ V.rotational()
        P += mv
        L += np.cross(p, mv) + Iw
        sP += np.linalg.norm(mv)
        sL += np.linalg.norm(np.cross(p, mv)) + np.linalg.norm(Iw)
    return P, L, sP, sL


def relative_kinetic_energy(dp: DockingPlant, plant_context) -> float:
    """The kinetic energy in the centre-of-mass frame of the three bodies (J): the total
    1/2 v^T M v less the centre of mass's |P|^2 / (2 m). This is what contact can take or
    give: about 1/2 mu v^2 for a closing speed v, mu the reduced mass of the two spacecraft."""
    P, _, _, _ = body_momenta(dp, plant_context)
    m = sum(b.default_mass() for b in dp.bodies.values())
    return float(dp.plant.CalcKineticEnergy(plant_context) - P @ P / (2.0 * m))


# The Stewart element's energy -------------------------------------------------------------
def _half_rotation(R):
    """R^(1/2): the rotation by half the angle about the same axis."""
    from pydrake.common.eigen_geometry import AngleAxis
    aa = RotationMatrix(R).ToAngleAxis()
    return AngleAxis(0.5 * aa.angle(), aa.axis()).rotation()


def stewart_deflection(dp: DockingPlant, plant_context):
    """The Stewart element's deflection, the coordinates of LinearBushingRollPitchYaw: the
    position of the APDS frame C from the anchor A expressed in the 'half-way' frame B
    (R_AB = R_AC^(1/2)), and the roll-pitch-yaw angles of R_AC."""
    from pydrake.math import RollPitchYaw
    X_AC = dp.bodies["target_apds"].body_frame().CalcPose(plant_context, dp.bushing.frameA())
    R = X_AC.rotation().matrix()
    x = _half_rotation(R).T @ X_AC.translation()
    return x, RollPitchYaw(X_AC.rotation()).vector()


def stewart_force(dp: DockingPlant, plant_context) -> np.ndarray:
    """The Stewart element's force on the target APDS (N, world frame): the translational part
    of the bushing's spatial force on its frame C."""
    return dp.bushing.CalcBushingSpatialForceOnFrameC(plant_context).translational()


def stewart_history(dp: DockingPlant, X) -> tuple[np.ndarray, np.ndarray]:
    """The Stewart element's stroke |x| (m, the translational deflection of
    `stewart_deflection`) and the magnitude of its force on the target APDS (N) at each plant
    state [q, v] of X [N, nq + nv]."""
    pc = dp.plant.CreateDefaultContext()
    stroke, force = np.empty(len(X)), np.empty(len(X))
    for k, x in enumerate(X):
        dp.plant.SetPositionsAndVelocities(pc, x)
        stroke[k] = np.linalg.norm(stewart_deflection(dp, pc)[0])
        force[k] = np.linalg.norm(stewart_force(dp, pc))
    return stroke, force


def stewart_potential(dp: DockingPlant, plant_context) -> float:
    """Potential of the Stewart springs, 1/2 sum k x^2 + 1/2 sum k_t theta^2 (Eq. 9), with
    Drake's bushing coordinates. Drake 1.51 does not implement the bushing's potential; the
    rotational part of this one is exact for Drake's torque law, the translational part is
    exact when R_AC turns about one axis of the bushing (the paper's example) and conservative
    to second order in the tilt otherwise."""
    x, rpy = stewart_deflection(dp, plant_context)
    b = dp.bushing
    k = np.asarray(b.force_stiffness_constants())
    kt = np.asarray(b.torque_stiffness_constants())
    return float(0.5 * k @ x**2 + 0.5 * kt @ rpy**2)


class StewartDamperPower:
    """f(q, v) -> the power of the Stewart element's dampers (<= 0): the bushing's generalized
    forces with its stiffnesses set to zero, dotted with v. Uses its own plant context."""

    def __init__(self, dp: DockingPlant):
        self.plant = dp.plant
        self.bushing = dp.bushing
        self.ctx = dp.plant.CreateDefaultContext()
        z = np.zeros(3)
        self.bushing.SetForceStiffnessConstants(self.ctx, z)
        self.bushing.SetTorqueStiffnessConstants(self.ctx, z)
        self.forces = MultibodyForces(dp.plant)

    def __call__(self, q, v) -> float:
        self.plant.SetPositions(self.ctx, q)
        self.plant.SetVelocities(self.ctx, v)
        f = self.forces
        f.SetZero()
        self.plant.CalcForceElementsContribution(self.ctx, f)
        return float(self.plant.CalcGeneralizedForces(self.ctx, f) @ v)
