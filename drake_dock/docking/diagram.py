"""The docking Diagram (Sect. 8): the three-body plant as the model, the rigid contact system
with the paper's 12 pairs owning the state, SceneGraph (and Meshcat when asked) for display.

Exported ports: ``state`` (the plant's [q, v]), ``couple_<name>`` for each pair, ``energy``
(`RigidContactSystem.energy_names`, with ``stewart_damper_work``), ``generalized_contact_force``,
``ring_distance`` (outputs) and ``chaser_wrench`` (input: [torque, force] on the chaser at its
mass centre, world frame), so that a controller can be connected.

Capture (docs/model.md): the rings within the latches' tolerances (`CaptureRule`): the axial
distance between the guide rings' centres, measured along the target APDS axis, within
``simulation.capture_distance``, their lateral offset and the tilt between their axes within
``simulation.capture_lateral`` and ``capture_tilt_deg``. `CaptureMonitor` declares it as a
witness function on the distance to capture whose publish event ends the simulation
(`EventStatus.ReachedTermination`), so the capture time is located to the witness isolation
accuracy."""
from __future__ import annotations

import dataclasses

import numpy as np

from pydrake.geometry import MeshcatVisualizer, SceneGraph
from pydrake.systems.rendering import MultibodyPositionToGeometryPose
from pydrake.systems.framework import (DiagramBuilder, EventStatus, LeafSystem, PublishEvent,
                                       WitnessFunctionDirection)

from drake_dock.core.kernels.free_bodies import frame_poses
from drake_dock.systems.contact_system import (ContactOptions, ContactPair, Handover,
                                                RigidContactSystem)
from drake_dock.systems.simulator import tolerances
from drake_dock.docking.outcome import CaptureRule, misalignment
from drake_dock.docking.plant import DockingPlant, make_docking_plant
from drake_dock.docking.pairs import pair_handovers, scenario_pairs
from drake_dock.docking.thrust import ThrustSchedule, ThrustSystem


@dataclasses.dataclass
class DockingDiagram:
    diagram: object
    contact: RigidContactSystem
    dp: DockingPlant
    scene_graph: object
    capture: "CaptureMonitor"
    thrust: ThrustSystem | None = None     # the scenario's post-contact thrust, if any


def ring_poses(dp: DockingPlant, plant_context):
    """World rotation and centre of the target's and the chaser's ring (APDS) frames."""
    XT = dp.apds_frames["target_apds"].CalcPoseInWorld(plant_context)
    XC = dp.apds_frames["chaser_apds"].CalcPoseInWorld(plant_context)
    return XT.rotation().matrix(), XT.translation(), XC.rotation().matrix(), XC.translation()


def axial_ring_distance(dp: DockingPlant, plant_context) -> float:
    """Distance from the target's ring centre to the chaser's, along the target APDS axis."""
    return misalignment(*ring_poses(dp, plant_context))[0]


class CaptureMonitor(LeafSystem):
    """Input ``state`` (the plant's [q, v]); output ``ring_distance`` (m, axial); a witness on
    `CaptureRule.to_go` - capture_distance whose publish event ends the simulation. A run that
    starts captured is not ended (the witness fires only on a crossing)."""

    def __init__(self, dp: DockingPlant, rule: CaptureRule):
        super().__init__()
        self.dp = dp
        self.rule = rule
        self.capture_distance = float(rule.axial)
        self._nq = dp.plant.num_positions()
        self._last = (None, None)           # (positions as bytes, their misalignment)
        # The two ring frames' poses from q in compiled code (`free_bodies.frame_poses`).
        frames = (dp.apds_frames["target_apds"], dp.apds_frames["chaser_apds"])
        bodies = [f.body() for f in frames]
        self._qs = np.array([b.floating_positions_start() for b in bodies], dtype=np.int64)
        self._fb = np.arange(2, dtype=np.int64)
        X = [f.GetFixedPoseInBodyFrame() for f in frames]
        self._R_BF = np.array([x.rotation().matrix() for x in X])
        self._p_BF = np.array([x.translation() for x in X])
        n = dp.plant.num_positions() + dp.plant.num_velocities()
        self._state = self.DeclareVectorInputPort("state", n)
        self.DeclareVectorOutputPort("ring_distance", 1,
                                     lambda c, o: o.SetFromVector([self.distance(c)]))
        self._witness = self.MakeWitnessFunction(
            "capture", WitnessFunctionDirection.kPositiveThenNonPositive,
            lambda c: self.to_go(c) - self.rule.axial,
            PublishEvent(lambda c, e: EventStatus.ReachedTermination(self, "capture")))

    def misalignment(self, context) -> tuple[float, float, float]:
        """Axial and lateral offset (m) and tilt (rad) of the chaser ring (`misalignment`); the
        axial offset is `axial_ring_distance`."""
        return self.misalignment_of(self._state.Eval(context)[:self._nq])

    def misalignment_of(self, q) -> tuple[float, float, float]:
        """`misalignment` at the plant's positions q."""
        key = q.tobytes()
        if key != self._last[0]:
            # Drake asks again at equal positions (the witness at a step's end, the monitor,
            # the ring distance output): the last answer is kept.
            R, o = np.empty((2, 3, 3)), np.empty((2, 3))
            frame_poses(self._qs, q, self._fb, self._R_BF, self._p_BF, R, o)
            self._last = (key, misalignment(R[0], o[0], R[1], o[1]))
        return self._last[1]

    def distance(self, context) -> float:
        """The axial ring-centre distance (m)."""
        return self.misalignment(context)[0]

    def to_go(self, context) -> float:
        """The distance to capture (m, `CaptureRule.to_go`); the axial distance itself when the
        rule tests nothing else."""
        return self.rule.to_go(*self.misalignment(context))

    def DoGetWitnessFunctions(self, context):
        return [self._witness]

    def witness_values(self, context) -> dict:
        return {"capture": self.to_go(context) - self.rule.axial}

    def witness_layout(self, context):
        return ("capture",)

    def witness_array(self, context):
        return np.array([self.to_go(context) - self.rule.axial])


def contact_options(scenario, options: ContactOptions | None = None) -> ContactOptions:
    """The contact system's options for the scenario: ``options``, by default ContactOptions
    with LZB's accuracy following the simulator's (`drake_dock.systems.simulator.tolerances`);
    where their ``broad_phase`` is None, the scene's policy: the broad phase screens the far
    pairs of every set but `paper`, whose 12 pairs are sought as in Sect. 5.1 (docs/model.md,
    "Hybrid simulation"). An explicit True or False is kept."""
    if options is None:
        options = ContactOptions(impact_rtol=tolerances(scenario.simulator_config).impact_rtol)
    if options.broad_phase is None:
        options = dataclasses.replace(options, broad_phase=scenario.contact.pairs != "paper")
    return options


def build_docking_diagram(scenario, meshcat=None, options=None,
                          handovers=True) -> DockingDiagram:
    """The Diagram of the scenario, its contact system with `contact_options` (scenario,
    options): given options keep their fields, and a ``broad_phase`` left None takes the
    scene's policy as the default options do. ``handovers`` declares the edge/surface hand-overs
    among the scenario's pairs (`pair_handovers`: those of the `complete` set; the paper's 12
    have none; docs/model.md, "Hand-over between an edge and a surface")."""
    builder = DiagramBuilder()
    scene_graph = builder.AddSystem(SceneGraph())
    dp = make_docking_plant(scenario, scene_graph)
    frames = dp.apds_frames
    specs = scenario_pairs(scenario)
    pairs = [ContactPair(p.name, p.kind, frames[p.body1], p.patch1, frames[p.body2], p.patch2,
                         p.sigma) for p in specs]
    options = contact_options(scenario, options)
    schedule = ThrustSchedule.of(scenario.thrust)
    contact = builder.AddSystem(RigidContactSystem(
        dp.plant, pairs, scenario.contact, options,
        wrench_bodies=("chaser",) + ((("chaser_thrust", "chaser"),) if schedule else ()),
        dampers=[("stewart_damper_work", dp.bushing)],
        energy_scale=0.5 * scenario.bodies.chaser.mass * scenario.initial.chaser_speed ** 2
        or 1.0, handovers=[Handover(*h) for h in pair_handovers(scenario.geometry, specs)]
        if handovers else []))
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
        builder.Connect(thrust.get_output_port(), contact.GetInputPort("chaser_thrust"))
    capture = builder.AddSystem(CaptureMonitor(dp, CaptureRule.of(scenario.simulation,
                                                                  scenario.geometry)))
    capture.set_name("capture")
    builder.Connect(contact.GetOutputPort("state"), capture.get_input_port())
    builder.ExportOutput(capture.get_output_port(), "ring_distance")
    builder.ExportInput(contact.GetInputPort("chaser_wrench"), "chaser_wrench")
    for k in range(contact.num_output_ports()):
        port = contact.get_output_port(k)
        builder.ExportOutput(port, port.get_name())
    if meshcat is not None:
        MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
    return DockingDiagram(builder.Build(), contact, dp, scene_graph, capture, thrust)
