"""The scenario's schema: the typed dataclass tree that a scenario file is loaded into
(`drake_dock.docking.scenario.loading`), with its defaults. No ``from __future__ import
annotations`` here: Drake's ``yaml_load_typed`` reads the fields' types as objects."""

import dataclasses
import typing

from pydrake.systems.analysis import SimulatorConfig

from drake_dock.core.contact_law import ContactLaw
from drake_dock.docking.scenario.dimensions import ApdsGeometry


@dataclasses.dataclass
class RigidBodyParams:
    """Mass (kg) and principal moments of inertia about the body's x, y, z axes (kg m^2),
    about the mass centre (Table 1; its repeated 'I11' headings read as I_x, I_y, I_z). The
    defaults are the paper's example read as axisymmetric about z (docs/model.md, "Reading
    Tables 1 and 2")."""

    mass: float = 1.0
    inertia: list[float] = dataclasses.field(default_factory=lambda: [1.0, 1.0, 1.0])


@dataclasses.dataclass
class Bodies:
    target: RigidBodyParams = dataclasses.field(
        default_factory=lambda: RigidBodyParams(1000.0, [778.0, 778.0, 829.0]))
    target_apds: RigidBodyParams = dataclasses.field(
        default_factory=lambda: RigidBodyParams(150.0, [68.0, 68.0, 68.0]))
    chaser: RigidBodyParams = dataclasses.field(
        default_factory=lambda: RigidBodyParams(7600.0, [40226.5, 40226.5, 6402.0]))


@dataclasses.dataclass
class StewartParams:
    """The Stewart spring-damper (Eq. 9-10, Table 2) between a frame on the target at
    p_TA = (a, b, c) and the target APDS frame; gains per axis of that frame (z = docking axis)."""

    p_TA: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0, 5.03])
    force_stiffness: list[float] = dataclasses.field(default_factory=lambda: [938., 7.14e4, 947.])
    force_damping: list[float] = dataclasses.field(default_factory=lambda: [520.0, 0.0, 532.0])
    torque_stiffness: list[float] = dataclasses.field(default_factory=lambda: [105., 105., 938.])
    torque_damping: list[float] = dataclasses.field(default_factory=lambda: [10.0, 10.0, 520.0])


@dataclasses.dataclass
class InitialCondition:
    """The initial contact conditions, in the target APDS frame (z: the docking axis, towards
    the chaser). Sect. 8.2 is the default: coaxial APDSes with matched petals, the target (with
    its APDS) turned by target_yaw_deg (the relative roll) about the axis, the chaser moving at
    chaser_speed towards the target. The misalignment is the chaser's at first contact:
    lateral_offset (m) of its ring centre from the docking axis, tilt_deg (deg) its rotation
    through its ring centre as a rotation vector in the x-y plane; lateral_velocity (m/s) of its
    ring centre and angular_velocity_deg_s (deg/s) of the chaser add to the closing speed. The
    chaser starts approach_travel (m) back along its straight relative motion from the pose at
    which the first couple closes (docs/model.md, "Initial conditions")."""

    target_yaw_deg: float = 5.0
    approach_travel: float = 0.01
    chaser_speed: float = 1.0
    lateral_offset: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0])
    tilt_deg: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0])
    lateral_velocity: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0])
    angular_velocity_deg_s: list[float] = dataclasses.field(
        default_factory=lambda: [0.0, 0.0, 0.0])


@dataclasses.dataclass
class DockingContact(ContactLaw):
    """The contact law (`ContactLaw`) and the scene's contact set ``pairs``: ``paper``, the 12 pairs
    of Sect. 2.2 and 8.1, or ``complete`` (the default), those and, for each APDS against the other,
    the ring's inside circle against the guide sides and tip arcs, its outside circle against the
    other ring's face, the tip arcs against the guide surfaces they can face, the petal corners
    against the ring's inside circle, and the guide sides against the non-partner sides and tip arcs
    they reach (`drake_dock.docking.geometry.pairs`; docs/model.md, "Facing and the contact
    pairs")."""

    pairs: str = "complete"           # one of `PAIR_SETS`


@dataclasses.dataclass
class ThrustParams:
    """Post-contact thrust (docs/model.md, "Post-contact thrust"): ``force`` (N) on the chaser
    along its docking axis, towards the target, from ``delay`` (s after the first contact) for
    ``duration`` (s; null: until the run ends), or in the ``pulses`` [start, end] (s after the
    first contact), the alternative to delay and duration."""

    force: float = 0.0
    delay: float = 0.0
    duration: typing.Optional[float] = None
    pulses: list[list[float]] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class SimulationParams:
    duration: float = 10.0           # the timeout (s): a run ends earlier at a named outcome
    jam_time: float = 2.0            # s without 1 mm of progress of the rings: "jammed"
    capture_distance: float = 0.005  # axial ring-centre distance ending the capture phase (m)
    # The latches' other tolerances (docs/model.md, "Capture"); null leaves one out of the test.
    capture_lateral: typing.Optional[float] = 0.01    # lateral ring-centre offset (m)
    capture_tilt_deg: typing.Optional[float] = 0.5    # tilt between the docking axes (deg)
    # The outputs' sample spacing (s): the record holds the states at its multiples, from the
    # integrator's dense output within each step, with the states just before and after each
    # impact and the last; null: one sample at the end of every integration step.
    output_period: typing.Optional[float] = None


def default_simulator_config() -> SimulatorConfig:
    """Drake's simulator settings of a docking run (`drake_dock.systems.simulator`): the
    fifth-order Runge-Kutta integrator with error control at ``accuracy`` (which also sets the
    witness isolation window and LZB's accuracy: `drake_dock.systems.simulator.tolerances`)
    and its step capped at ``max_step_size`` (s), which is also the sample spacing of the
    outputs unless ``simulation.output_period`` sets its own. At that cap the step is mostly the cap's, so the scheme's order sets the error:
    Bogacki-Shampine (3 evaluations a step against RK5's 6) leaves the energy ledger open by
    a few 1e-6 over an off-nominal run, RK5 closes it to 1e-7 (docs/algorithms.md, "Integration";
    bench/paper_example.py runs both)."""
    return SimulatorConfig(integration_scheme="runge_kutta5", max_step_size=0.002,
                           accuracy=1e-6, use_error_control=True)


@dataclasses.dataclass
class Scenario:
    geometry: ApdsGeometry = dataclasses.field(default_factory=ApdsGeometry)
    bodies: Bodies = dataclasses.field(default_factory=Bodies)
    stewart: StewartParams = dataclasses.field(default_factory=StewartParams)
    chaser_apds_offset: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0, 1.9])
    contact: DockingContact = dataclasses.field(default_factory=DockingContact)
    initial: InitialCondition = dataclasses.field(default_factory=InitialCondition)
    simulation: SimulationParams = dataclasses.field(default_factory=SimulationParams)
    thrust: ThrustParams | None = None          # absent: no thrust
    simulator_config: SimulatorConfig = dataclasses.field(
        default_factory=default_simulator_config)

    def __getstate__(self):
        """Pickles (for Dask workers) with Drake's SimulatorConfig as its fields, which pickle."""
        state = dict(self.__dict__)
        c = state["simulator_config"]
        state["simulator_config"] = {f.name: getattr(c, f.name)
                                     for f in SimulatorConfig.__fields__}
        return state

    def __eq__(self, other):
        """Field by field, SimulatorConfig by its fields (Drake's struct has no ==)."""
        return type(other) is type(self) and self.__getstate__() == other.__getstate__()

    def __setstate__(self, state):
        state = dict(state)
        state["simulator_config"] = SimulatorConfig(**state["simulator_config"])
        self.__dict__.update(state)
