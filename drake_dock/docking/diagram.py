"""The docking Diagram (Sect. 8): the three-body plant as the model, the rigid contact system
with the paper's 12 pairs owning the state, SceneGraph (and Meshcat when asked) for display.

Exported ports: ``state`` (the plant's [q, v]), ``couple_<name>`` for each pair, ``energy``
(`RigidContactSystem.energy_names`, with ``stewart_damper_work``), ``generalized_contact_force``,
``ring_distance`` (outputs) and ``chaser_wrench`` (input: [torque, force] on the chaser at its
mass centre, world frame), so that a controller can be connected.

Capture (docs/model.md): the axial distance between the guide rings' centres, measured along the
target APDS axis, reaching ``simulation.capture_distance``. `CaptureMonitor` declares it as a
witness function whose publish event ends the simulation (`EventStatus.ReachedTermination`), so
the capture time is located to the witness isolation accuracy."""
from __future__ import annotations

import dataclasses

from pydrake.geometry import MeshcatVisualizer, SceneGraph
from pydrake.systems.rendering import MultibodyPositionToGeometryPose
from pydrake.systems.framework import (DiagramBuilder, EventStatus, LeafSystem, PublishEvent,
                                       WitnessFunctionDirection)

from drake_dock.systems.contact_system import (ContactOptions, ContactPair, Handover,
                                                RigidContactSystem)
from drake_dock.systems.simulator import tolerances
from drake_dock.docking.plant import DockingPlant, StewartDamperPower, make_docking_plant
from drake_dock.docking.scene import pair_handovers, scenario_pairs


@dataclasses.dataclass
class DockingDiagram:
    diagram: object
    contact: RigidContactSystem
    dp: DockingPlant
    scene_graph: object
    capture: "CaptureMonitor"


def axial_ring_distance(dp: DockingPlant, plant_context) -> float:
    """Distance from the target's ring centre to the chaser's, along the target APDS axis."""
    XT = dp.apds_frames["target_apds"].CalcPoseInWorld(plant_context)
    XC = dp.apds_frames["chaser_apds"].CalcPoseInWorld(plant_context)
    return float(XT.rotation().matrix()[:, 2] @ (XC.translation() - XT.translation()))


class CaptureMonitor(LeafSystem):
    """Input ``state`` (the plant's [q, v]); output ``ring_distance`` (m); a witness on
    ring_distance - capture_distance whose publish event ends the simulation. A run that
    starts captured is not ended (the witness fires only on a crossing)."""

    def __init__(self, dp: DockingPlant, capture_distance: float):
        super().__init__()
        self.dp = dp
        self.capture_distance = float(capture_distance)
        self._pc = dp.plant.CreateDefaultContext()
        n = dp.plant.num_positions() + dp.plant.num_velocities()
        self._state = self.DeclareVectorInputPort("state", n)
        self.DeclareVectorOutputPort("ring_distance", 1,
                                     lambda c, o: o.SetFromVector([self.distance(c)]))
        self._witness = self.MakeWitnessFunction(
            "capture", WitnessFunctionDirection.kPositiveThenNonPositive,
            lambda c: self.distance(c) - self.capture_distance,
            PublishEvent(lambda c, e: EventStatus.ReachedTermination(self, "capture")))

    def distance(self, context) -> float:
        x = self._state.Eval(context)
        self.dp.plant.SetPositions(self._pc, x[:self.dp.plant.num_positions()])
        return axial_ring_distance(self.dp, self._pc)

    def DoGetWitnessFunctions(self, context):
        return [self._witness]

    def witness_values(self, context) -> dict:
        return {"capture": self.distance(context) - self.capture_distance}


def build_docking_diagram(scenario, meshcat=None, options=None) -> DockingDiagram:
    builder = DiagramBuilder()
    scene_graph = builder.AddSystem(SceneGraph())
    dp = make_docking_plant(scenario, scene_graph)
    frames = dp.apds_frames
    specs = scenario_pairs(scenario)
    pairs = [ContactPair(p.name, p.kind, frames[p.body1], p.patch1, frames[p.body2], p.patch2)
             for p in specs]
    if options is None:
        # LZB's accuracy follows the simulator's (`drake_dock.systems.simulator.tolerances`).
        options = ContactOptions(impact_rtol=tolerances(scenario.simulator_config).impact_rtol)
    contact = builder.AddSystem(RigidContactSystem(
        dp.plant, pairs, scenario.contact, options,
        wrench_bodies=("chaser",),
        extra_powers=[("stewart_damper_work", StewartDamperPower(dp))],
        energy_scale=0.5 * scenario.bodies.chaser.mass * scenario.initial.chaser_speed ** 2
        or 1.0, handovers=[Handover(*h) for h in pair_handovers(scenario.geometry, specs)]))
    contact.set_name("rigid_contact")
    to_pose = builder.AddSystem(MultibodyPositionToGeometryPose(dp.plant,
                                                                input_multibody_state=True))
    builder.Connect(contact.GetOutputPort("state"), to_pose.get_input_port())
    builder.Connect(to_pose.get_output_port(),
                    scene_graph.get_source_pose_port(dp.plant.get_source_id()))
    capture = builder.AddSystem(CaptureMonitor(dp, scenario.simulation.capture_distance))
    capture.set_name("capture")
    builder.Connect(contact.GetOutputPort("state"), capture.get_input_port())
    builder.ExportOutput(capture.get_output_port(), "ring_distance")
    builder.ExportInput(contact.GetInputPort("chaser_wrench"), "chaser_wrench")
    for k in range(contact.num_output_ports()):
        port = contact.get_output_port(k)
        builder.ExportOutput(port, port.get_name())
    if meshcat is not None:
        MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
    return DockingDiagram(builder.Build(), contact, dp, scene_graph, capture)
