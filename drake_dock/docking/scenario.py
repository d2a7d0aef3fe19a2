"""The scenario: a typed dataclass tree loaded from YAML with Drake's ``yaml_load_typed``.

Every value is validated on load; a bad one raises `InputError` naming the dotted field, the
value and the allowed range. Unknown keys are errors too (named with their full path).
"""

import dataclasses
import math
import types
import typing
from pathlib import Path

import yaml
from pydrake.common.yaml import yaml_load_typed
from pydrake.systems.analysis import SimulatorConfig

from drake_dock.core.contact_law import ContactLaw
from drake_dock.docking.apds import PAIR_SETS, ApdsGeometry
from drake_dock.errors import InputError

MODELS_DIR = Path(__file__).resolve().parent.parent / "models"   # package data; ./models links here
PAPER_EXAMPLE = MODELS_DIR / "paper_example.yaml"


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
    """The contact law (`ContactLaw`) and the scene's contact set ``pairs``: ``paper``, the 12
    pairs of Sect. 2.2 and 8.1, or ``complete`` (the default), those and, for each APDS against the other, the
    ring's inside circle against the guide sides and tip arcs, its outside circle against the
    other ring's face, the tip arcs against the guide surfaces they can face, the petal
    corners against the ring's inside circle, and the guide sides against the non-partner
    sides and tip arcs they reach (`drake_dock.docking.pairs.apds_pairs`; docs/model.md,
    "Facing and the contact pairs")."""

    pairs: str = "complete"

    def validate(self, where: str = "contact") -> "DockingContact":
        super().validate(where)
        if self.pairs not in PAIR_SETS:
            raise InputError(f"{where}.pairs", self.pairs, f"one of {', '.join(PAIR_SETS)}")
        return self


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


def default_simulator_config() -> SimulatorConfig:
    """Drake's simulator settings of a docking run (`drake_dock.systems.simulator`): the
    fifth-order Runge-Kutta integrator with error control at ``accuracy`` (which also sets the
    witness isolation window and LZB's accuracy: `drake_dock.systems.simulator.tolerances`)
    and its step capped at ``max_step_size`` (s), which is also the sample spacing of the
    outputs. At that cap the step is mostly the cap's, so the scheme's order sets the error:
    Bogacki-Shampine (3 evaluations a step against RK5's 6) leaves the energy ledger open by
    a few 1e-6 over an off-nominal run, RK5 closes it to 1e-7 (docs/model.md, "Integration";
    bench/paper_example.py runs both)."""
    return SimulatorConfig(integration_scheme="runge_kutta5", max_step_size=0.002,
                           accuracy=1e-6, use_error_control=True)


MAX_TILT_DEG = 30.0        # initial.tilt_deg: beyond it the petals no longer guide the rings
MAX_LATERAL_SPEED = 1.0    # initial.lateral_velocity (m/s)
MAX_RATE_DEG_S = 90.0      # initial.angular_velocity_deg_s
MAX_STEPS = 1e6      # simulation.duration / simulator_config.max_step_size: a run that can end
MIN_REALTIME_RATE = 0.01   # simulator_config.target_realtime_rate, unless 0 (no pacing)
# Drake's error-controlled explicit integrators (SimulatorConfig.integration_scheme).
INTEGRATION_SCHEMES = ("bogacki_shampine3", "runge_kutta3", "runge_kutta5")


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


# Validation ---------------------------------------------------------------------------------
def _schema_fields(schema):
    """{name: type} of a dataclass or of a Drake class that Drake's YAML loader reads through
    its ``__fields__`` (SimulatorConfig); None for other types."""
    if dataclasses.is_dataclass(schema):
        return typing.get_type_hints(schema)
    if isinstance(schema, type) and hasattr(schema, "__fields__"):
        return {f.name: f.type for f in schema.__fields__}
    return None


def _check_raw(node, schema, path):
    """Walks the raw YAML against the dataclass tree, so that an unknown key or a value of the
    wrong type is named by its dotted path before Drake's loader sees it."""
    where = path.rstrip(".") or "scenario"
    hints = _schema_fields(schema)
    if hints is not None:
        if not isinstance(node, dict):
            raise InputError(where, node, "a mapping of fields")
        for key, value in node.items():
            if key not in hints:
                allowed = ", ".join(hints)
                raise InputError(f"{path}{key}", value, f"a known field of '{where}' ({allowed})",
                                 "unknown key")
            _check_raw(value, hints[key], f"{path}{key}.")
    elif schema is float:
        # Drake's typed loader applies float() to scalars (so '1.0e9', a YAML 1.1 string, loads).
        ok = isinstance(node, (int, float, str)) and not isinstance(node, bool)
        if ok and isinstance(node, str):
            try:
                float(node)
            except ValueError:
                ok = False
        if not ok:
            raise InputError(where, node, "a number")
    elif schema is str:
        if not isinstance(node, str):
            raise InputError(where, node, "a string")
    elif schema is bool:
        if not isinstance(node, bool):
            raise InputError(where, node, "true or false")
    elif typing.get_origin(schema) is list:
        if not isinstance(node, list):
            raise InputError(where, node, "a list of numbers")
        (item,) = typing.get_args(schema)
        for k, x in enumerate(node):
            _check_raw(x, item, f"{where}[{k}].")
    elif typing.get_origin(schema) is types.UnionType and node is not None:
        (item,) = [a for a in typing.get_args(schema) if a is not type(None)]   # X | None
        _check_raw(node, item, path)


def _finite(field, v):
    if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
        raise InputError(field, v, "a finite number")
    return float(v)


def _vector(field, v, n=3):
    if not isinstance(v, list) or len(v) != n:
        raise InputError(field, v, f"a list of {n} finite numbers")
    return [_finite(f"{field}[{k}]", x) for k, x in enumerate(v)]


def _positive(field, v):
    if _finite(field, v) <= 0:
        raise InputError(field, v, "> 0")


def _nonnegative(field, v):
    if _finite(field, v) < 0:
        raise InputError(field, v, ">= 0")


def _mounted_ahead(field, v, body):
    """An APDS sits on its spacecraft's docking face: its ring centre is ahead of the body's
    mass centre along the docking axis (offset z > 0). The bodies carry no contact geometry
    but their APDSes, so this is the rule that keeps each APDS outside its own body (and the
    other spacecraft out of it); the rings' clearance at t = 0 is initial.approach_travel."""
    if _vector(field, v)[2] <= 0:
        raise InputError(f"{field}[2]", v[2], "> 0 m (the APDS ahead of the mass centre of "
                         f"the {body}, towards the other spacecraft)",
                         f"the APDS would lie inside or behind the {body} body")


def validate(s: Scenario) -> Scenario:
    s.geometry.validate("geometry")
    for name in ("target", "target_apds", "chaser"):
        b = getattr(s.bodies, name)
        f = f"bodies.{name}"
        _positive(f"{f}.mass", b.mass)
        I = _vector(f"{f}.inertia", b.inertia)
        for k, x in enumerate(I):
            _positive(f"{f}.inertia[{k}]", x)
        # Principal moments of a physical body obey the triangle inequalities.
        for k in range(3):
            if I[k] > I[(k + 1) % 3] + I[(k + 2) % 3]:
                raise InputError(f"{f}.inertia", b.inertia,
                                 "principal moments with I_k <= I_i + I_j for every k",
                                 "not the inertia of a physical body")
    for name in ("force_stiffness", "force_damping", "torque_stiffness", "torque_damping"):
        for k, x in enumerate(_vector(f"stewart.{name}", getattr(s.stewart, name))):
            _nonnegative(f"stewart.{name}[{k}]", x)
    _mounted_ahead("stewart.p_TA", s.stewart.p_TA, "target")
    _mounted_ahead("chaser_apds_offset", s.chaser_apds_offset, "chaser")
    s.contact.validate("contact")
    ic = s.initial
    if not -60.0 < _finite("initial.target_yaw_deg", ic.target_yaw_deg) < 60.0:
        raise InputError("initial.target_yaw_deg", ic.target_yaw_deg, "-60 < yaw < 60 deg")
    if _finite("initial.approach_travel", ic.approach_travel) < 0:
        raise InputError("initial.approach_travel", ic.approach_travel,
                         ">= 0 m (a negative travel means initial interpenetration)")
    if _finite("initial.chaser_speed", ic.chaser_speed) <= 0:
        raise InputError("initial.chaser_speed", ic.chaser_speed,
                         "> 0 m/s (the closing speed towards the target)")
    for name, n, limit, allowed in (
            ("lateral_offset", 2, s.geometry.R, f"|offset| < the ring radius R = {s.geometry.R} m"),
            ("tilt_deg", 2, MAX_TILT_DEG, f"|tilt| < {MAX_TILT_DEG:g} deg"),
            ("lateral_velocity", 2, MAX_LATERAL_SPEED, f"|v| < {MAX_LATERAL_SPEED:g} m/s"),
            ("angular_velocity_deg_s", 3, MAX_RATE_DEG_S, f"|w| < {MAX_RATE_DEG_S:g} deg/s")):
        value = getattr(ic, name)
        if not math.hypot(*_vector(f"initial.{name}", value, n)) < limit:
            raise InputError(f"initial.{name}", value, allowed)
    _positive("simulation.duration", s.simulation.duration)
    _positive("simulation.jam_time", s.simulation.jam_time)
    _positive("simulation.capture_distance", s.simulation.capture_distance)
    if s.simulation.capture_lateral is not None and not (
            0 < _finite("simulation.capture_lateral", s.simulation.capture_lateral) < s.geometry.R):
        raise InputError("simulation.capture_lateral", s.simulation.capture_lateral,
                         f"0 < tolerance < the ring radius R = {s.geometry.R} m, or null (not tested)")
    if s.simulation.capture_tilt_deg is not None and not (
            0 < _finite("simulation.capture_tilt_deg", s.simulation.capture_tilt_deg) < 90):
        raise InputError("simulation.capture_tilt_deg", s.simulation.capture_tilt_deg,
                         "0 < tolerance < 90 deg, or null (not tested)")
    if s.thrust is not None:
        _validate_thrust(s.thrust)
    _validate_simulator_config(s.simulator_config, s.simulation.duration)
    return s


MAX_THRUST = 1e5     # N: thrust.force (a spacecraft's jets give tens to hundreds of N)


def _validate_thrust(th: ThrustParams):
    f = "thrust"
    if not 0 <= _finite(f"{f}.force", th.force) <= MAX_THRUST:
        raise InputError(f"{f}.force", th.force, f"0 <= force <= {MAX_THRUST:.0e} N (along the "
                         "chaser's docking axis, towards the target)")
    _nonnegative(f"{f}.delay", th.delay)
    if th.duration is not None:
        _positive(f"{f}.duration", th.duration)
    if not isinstance(th.pulses, list):
        raise InputError(f"{f}.pulses", th.pulses, "a list of [start, end] pairs (s)")
    if th.pulses and (th.delay != 0.0 or th.duration is not None):
        raise InputError(f"{f}.pulses", th.pulses, "pulses alone, or delay and duration "
                         "(pulses is the alternative to delay and duration)",
                         f"delay {th.delay:g} and duration {th.duration} given as well")
    last = 0.0
    for k, pulse in enumerate(th.pulses):
        start, end = _vector(f"{f}.pulses[{k}]", pulse, 2)
        if not last <= start < end:
            raise InputError(f"{f}.pulses[{k}]", pulse, f"[start, end] with {last:g} <= start < "
                             "end (s after the first contact; pulses in order, apart)")
        last = end


def _validate_simulator_config(c: SimulatorConfig, duration: float):
    f = "simulator_config"
    if c.integration_scheme not in INTEGRATION_SCHEMES:
        raise InputError(f"{f}.integration_scheme", c.integration_scheme,
                         f"one of {', '.join(INTEGRATION_SCHEMES)}")
    if not 0 < _finite(f"{f}.accuracy", c.accuracy) < 1:
        raise InputError(f"{f}.accuracy", c.accuracy, "0 < accuracy < 1")
    _positive(f"{f}.max_step_size", c.max_step_size)
    if duration / c.max_step_size > MAX_STEPS:
        raise InputError(f"{f}.max_step_size", c.max_step_size,
                         f">= simulation.duration / {MAX_STEPS:.0e} = "
                         f"{duration / MAX_STEPS:.3g} s", f"more than {MAX_STEPS:.0e} steps")
    if not c.use_error_control:
        raise InputError(f"{f}.use_error_control", c.use_error_control,
                         "true (the witness isolation and LZB's accuracy follow the accuracy)")
    if _finite(f"{f}.start_time", c.start_time) != 0.0:
        raise InputError(f"{f}.start_time", c.start_time, "0 (a run starts at t = 0)")
    rate = _finite(f"{f}.target_realtime_rate", c.target_realtime_rate)
    if rate != 0.0 and not rate >= MIN_REALTIME_RATE:
        raise InputError(f"{f}.target_realtime_rate", c.target_realtime_rate,
                         f"0 (as fast as possible) or >= {MIN_REALTIME_RATE:g}")


# Writing ---------------------------------------------------------------------------------------
def scenario_dict(node):
    """A scenario (or any part of it) as plain data: every field, the defaults filled in and
    None kept (null: a tolerance left out), in the order of the dataclasses; what
    `load_scenario` reads back to an equal scenario."""
    fields = _schema_fields(type(node))
    if fields is not None:
        return {name: scenario_dict(getattr(node, name)) for name in fields}
    if isinstance(node, (list, tuple)):
        return [scenario_dict(x) for x in node]
    return node


class _Dumper(yaml.SafeDumper):
    """Sections and fields one a line, vectors on one line ([x, y, z])."""


_Dumper.add_representer(list, lambda d, v: d.represent_sequence("tag:yaml.org,2002:seq", v,
                                                                flow_style=True))


def scenario_yaml(scenario: Scenario) -> str:
    """The full scenario as YAML (`scenario_dict`): `drake-dock run --print-scenario`."""
    return yaml.dump(scenario_dict(scenario), Dumper=_Dumper, sort_keys=False,
                     default_flow_style=False, width=100)


def load_scenario(filename=None, *, data: str | None = None) -> Scenario:
    """Loads and validates a scenario from a YAML file (default: the paper's example) or a
    string. Raises `InputError` (a ValueError) naming the field for any bad value, and for an
    unreadable file."""
    if data is None:
        filename = Path(filename) if filename is not None else PAPER_EXAMPLE
        try:
            data = filename.read_text(encoding="utf-8")
        except OSError as e:
            raise InputError("scenario file", str(filename), "a readable YAML file",
                             e.strerror or str(e)) from None
        except UnicodeDecodeError as e:
            raise InputError("scenario file", str(filename), "a YAML text file (UTF-8)",
                             f"byte {e.start} is not UTF-8 text: a binary file?") from None
    try:
        raw = yaml.safe_load(data)
    except yaml.YAMLError as e:
        raise InputError("scenario file", str(filename or "<string>"), "valid YAML",
                         str(e).splitlines()[0]) from None
    if raw is None:
        raise InputError("scenario file", str(filename or "<string>"),
                         f"a YAML mapping of sections "
                         f"({', '.join(f.name for f in dataclasses.fields(Scenario))}); "
                         f"`drake-dock run --print-scenario` prints a complete one",
                         "the file holds no YAML content (empty, or only comments)")
    if not isinstance(raw, dict):
        raise InputError("scenario", raw, "a mapping of fields")
    _check_raw(raw, Scenario, "")
    try:
        s = yaml_load_typed(schema=Scenario, data=data)
    except (RuntimeError, ValueError, TypeError) as e:
        raise InputError("scenario", str(filename or "<string>"),
                         "values of the documented types", str(e)) from None
    return validate(s)
