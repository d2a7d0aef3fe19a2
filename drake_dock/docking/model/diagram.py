"""The docking Diagram (Sect. 8), built of a `DiagramSpec`: the three-body plant as the model, the
rigid contact system with the scene's pairs owning the state, SceneGraph (and Meshcat when
asked) for display.

Exported ports: ``state`` (the plant's [q, v]), ``couple_<name>`` for each pair, ``energy``
(`RigidContactSystem.energy_names`, with ``stewart_damper_work``), ``generalized_contact_force``,
``ring_distance`` (outputs) and ``chaser_wrench`` (input: [torque, force] on the chaser at its
mass centre, world frame), so that a controller can be connected.

Capture is watched by `drake_dock.docking.model.capture.CaptureMonitor` (docs/model.md,
"Capture")."""
from __future__ import annotations

import dataclasses

from pydrake.geometry import MeshcatVisualizer, SceneGraph
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.rendering import MultibodyPositionToGeometryPose

from drake_dock.core.contact_law import ContactLaw
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.capture import CaptureMonitor
from drake_dock.docking.model.outcome import CaptureRule
from drake_dock.docking.model.plant import DockingPlant, PlantSpec, make_docking_plant
from drake_dock.docking.model.thrust import ThrustSchedule, ThrustSystem, follower_of
from drake_dock.errors import InputError
from drake_dock.systems.contact_system import (ContactOptions, ContactPair, Handover,
                                                RigidContactSystem)
from drake_dock.systems.simulator import tolerances


@dataclasses.dataclass
class DockingDiagram:
    diagram: object
    contact: RigidContactSystem
    dp: DockingPlant
    scene_graph: object
    capture: CaptureMonitor
    spec: "DiagramSpec"                    # what it was built of
    thrust: ThrustSystem | None = None     # the scenario's post-contact thrust, if any

    @property
    def scene(self) -> DockingScene:
        """The `DockingScene` whose pairs the contact system holds."""
        return self.spec.scene


def _fields(obj) -> tuple:
    """A dataclass's fields as ((name, value), ...), frozen."""
    return tuple((f.name, getattr(obj, f.name)) for f in dataclasses.fields(obj))


@dataclasses.dataclass(frozen=True)
class DiagramSpec:
    """Exactly what `build_docking_diagram` reads of a scenario, frozen and hashable (the
    campaign's Diagram cache keys on it): the scene (its pairs, patches and hand-overs: the
    geometry and ``contact.pairs``), the plant (`PlantSpec`), the contact law's fields, the
    contact system's options (`of`), the thrust schedule, the capture rule (the capture
    tolerances and the ring radius), the energy scale of the error control (the chaser's
    kinetic energy at its closing speed) and whether the hand-overs are declared."""

    scene: DockingScene
    plant: PlantSpec
    law: tuple                 # ContactLaw's fields, ((name, value), ...)
    options: tuple             # ContactOptions' fields, ((name, value), ...)
    thrust: ThrustSchedule | None
    capture: CaptureRule
    energy_scale: float
    handovers: bool = True

    @classmethod
    def of(cls, scenario, *, scene: DockingScene | None = None,
           options: ContactOptions | None = None, handovers: bool = True) -> "DiagramSpec":
        """The spec of a scenario. ``scene``: the scenario's `DockingScene` where the caller
        has it (made here where None; `InputError` for another scene's). ``options``: the
        contact system's options, by default ContactOptions with LZB's accuracy following the
        simulator's (`drake_dock.systems.simulator.tolerances`) and the far pairs' reseek
        horizon its step cap (no step is cut short to end where a far pair falls due); where their ``broad_phase``
        is None, the scene's policy: the broad phase screens the far pairs of every set but
        `paper`, whose 12 pairs are sought as in Sect. 5.1 (docs/model.md, "Hybrid
        simulation"); an explicit True or False is kept. ``handovers`` declares the
        edge/surface hand-overs among the scene's pairs (those of the `complete` set; the
        paper's 12 have none; docs/model.md, "Hand-over between an edge and a surface")."""
        if scene is None:
            scene = DockingScene.of(scenario)
        elif scene.key != DockingScene.key_of(scenario.geometry, scenario.contact.pairs):
            raise InputError("scene", scene, "the scenario's DockingScene (its geometry and "
                             "contact.pairs)", "another scene's")
        if options is None:
            options = ContactOptions(
                impact_rtol=tolerances(scenario.simulator_config).impact_rtol,
                reseek_horizon=scenario.simulator_config.max_step_size)
        if options.broad_phase is None:
            options = dataclasses.replace(options, broad_phase=scenario.contact.pairs != "paper")
        law = ContactLaw(**{f.name: getattr(scenario.contact, f.name)
                            for f in dataclasses.fields(ContactLaw)})
        return cls(scene, PlantSpec.of(scenario), _fields(law), _fields(options),
                   ThrustSchedule.of(scenario.thrust),
                   CaptureRule.of(scenario.simulation, scenario.geometry),
                   0.5 * scenario.bodies.chaser.mass * scenario.initial.chaser_speed ** 2 or 1.0,
                   handovers)

    def contact_law(self) -> ContactLaw:
        return ContactLaw(**dict(self.law))

    def contact_options(self) -> ContactOptions:
        return ContactOptions(**dict(self.options))


def build_docking_diagram(spec: DiagramSpec, meshcat=None) -> DockingDiagram:
    """The Diagram of ``spec`` (`DiagramSpec.of` a scenario): the plant, the rigid contact
    system with the scene's pairs (and their hand-overs where ``spec.handovers``), the
    thrust, the capture monitor, SceneGraph, and Meshcat's visualizer where ``meshcat`` is
    given. The scene travels on the result (`DockingDiagram.scene`)."""
    law, options, schedule, scene = spec.contact_law(), spec.contact_options(), spec.thrust, \
        spec.scene
    builder = DiagramBuilder()
    scene_graph = builder.AddSystem(SceneGraph())
    dp = make_docking_plant(spec.plant, scene_graph)
    frames = dp.apds_frames
    pairs = [ContactPair(p.name, p.kind, frames[p.body1], p.patch1, frames[p.body2], p.patch2,
                         p.sigma) for p in scene.pairs]
    contact = builder.AddSystem(RigidContactSystem(
        dp.plant, pairs, law, options,
        wrench_bodies=("chaser",),
        dampers=[("stewart_damper_work", dp.bushing)], energy_scale=spec.energy_scale,
        handovers=[Handover(h.edge_pair.name, h.surface_pair.name, h.edge)
                   for h in scene.handovers] if spec.handovers else [],
        followers=[follower_of(dp, schedule)] if schedule else []))
    contact.set_name("rigid_contact")
    to_pose = builder.AddSystem(MultibodyPositionToGeometryPose(dp.plant,
                                                                input_multibody_state=True))
    builder.Connect(contact.GetOutputPort("state"), to_pose.get_input_port())
    builder.Connect(to_pose.get_output_port(),
                    scene_graph.get_source_pose_port(dp.plant.get_source_id()))
    thrust = None
    if schedule is not None:
        thrust = builder.AddSystem(ThrustSystem(dp, schedule))
        thrust.set_name("thrust")
        builder.Connect(contact.GetOutputPort("state"), thrust.GetInputPort("state"))
        builder.Connect(contact.GetOutputPort("first_contact_time"),
                        thrust.GetInputPort("first_contact_time"))
    capture = builder.AddSystem(CaptureMonitor(dp, spec.capture))
    capture.set_name("capture")
    builder.Connect(contact.GetOutputPort("state"), capture.get_input_port())
    builder.ExportOutput(capture.get_output_port(), "ring_distance")
    builder.ExportInput(contact.GetInputPort("chaser_wrench"), "chaser_wrench")
    for k in range(contact.num_output_ports()):
        port = contact.get_output_port(k)
        builder.ExportOutput(port, port.get_name())
    if meshcat is not None:
        MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
    return DockingDiagram(builder.Build(), contact, dp, scene_graph, capture, spec, thrust)
