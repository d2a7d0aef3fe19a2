"""The docking Diagram (Sect. 8): the three-body plant as the model, the rigid contact system
with the paper's 12 pairs owning the state, SceneGraph (and Meshcat when asked) for display.

Exported ports: ``state`` (the plant's [q, v]), ``couple_<name>`` for each pair, ``energy``,
``generalized_contact_force`` (outputs) and ``chaser_wrench`` (input: [torque, force] on the
chaser at its mass centre, world frame), so that a controller can be connected."""
from __future__ import annotations

import dataclasses

from pydrake.geometry import MeshcatVisualizer, SceneGraph
from pydrake.systems.rendering import MultibodyPositionToGeometryPose
from pydrake.systems.framework import DiagramBuilder

from drake_dock.contact_system import ContactLaw, ContactOptions, ContactPair, RigidContactSystem
from drake_dock.docking.plant import DockingPlant, make_docking_plant
from drake_dock.docking.scene import apds_pairs


@dataclasses.dataclass
class DockingDiagram:
    diagram: object
    contact: RigidContactSystem
    dp: DockingPlant
    scene_graph: object


def contact_law(scenario) -> ContactLaw:
    c = scenario.contact
    return ContactLaw(mu=c.mu, mu_s=c.mu_s, restitution=c.restitution, stiffness=c.stiffness,
                      eta=c.eta)


def build_docking_diagram(scenario, meshcat=None, options=None) -> DockingDiagram:
    builder = DiagramBuilder()
    scene_graph = builder.AddSystem(SceneGraph())
    dp = make_docking_plant(scenario, scene_graph)
    frames = dp.apds_frames
    pairs = [ContactPair(p.name, p.kind, frames[p.body1], p.patch1, frames[p.body2], p.patch2)
             for p in apds_pairs(scenario.geometry)]
    contact = builder.AddSystem(RigidContactSystem(
        dp.plant, pairs, contact_law(scenario), options or ContactOptions(),
        wrench_bodies=("chaser",)))
    contact.set_name("rigid_contact")
    to_pose = builder.AddSystem(MultibodyPositionToGeometryPose(dp.plant,
                                                                input_multibody_state=True))
    builder.Connect(contact.GetOutputPort("state"), to_pose.get_input_port())
    builder.Connect(to_pose.get_output_port(),
                    scene_graph.get_source_pose_port(dp.plant.get_source_id()))
    builder.ExportInput(contact.GetInputPort("chaser_wrench"), "chaser_wrench")
    for k in range(contact.num_output_ports()):
        port = contact.get_output_port(k)
        builder.ExportOutput(port, port.get_name())
    if meshcat is not None:
        MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
    return DockingDiagram(builder.Build(), contact, dp, scene_graph)
