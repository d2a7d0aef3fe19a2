"""The scenario's validation: every value in its range, or `InputError` naming the dotted
field, the value and the allowed range (`validate`; `drake_dock.docking.scenario.loading`
validates every file it loads)."""

import math

from pydrake.systems.analysis import SimulatorConfig

from drake_dock.docking.scenario.dimensions import PAIR_SETS
from drake_dock.docking.scenario.schema import Scenario, ThrustParams
from drake_dock.errors import InputError

MAX_TILT_DEG = 30.0        # initial.tilt_deg: beyond it the petals no longer guide the rings
MAX_LATERAL_SPEED = 1.0    # initial.lateral_velocity (m/s)
MAX_RATE_DEG_S = 90.0      # initial.angular_velocity_deg_s
MAX_STEPS = 1e6      # simulation.duration / simulator_config.max_step_size: a run that can end
MIN_REALTIME_RATE = 0.01   # simulator_config.target_realtime_rate, unless 0 (no pacing)
# Drake's error-controlled explicit integrators (SimulatorConfig.integration_scheme).
INTEGRATION_SCHEMES = ("bogacki_shampine3", "runge_kutta3", "runge_kutta5")


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
    if s.contact.pairs not in PAIR_SETS:
        raise InputError("contact.pairs", s.contact.pairs, f"one of {', '.join(PAIR_SETS)}")
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
    period = s.simulation.output_period
    if period is not None:
        _positive("simulation.output_period", period)
        if s.simulation.duration / period > MAX_STEPS:
            raise InputError("simulation.output_period", period,
                             f">= simulation.duration / {MAX_STEPS:.0e} = "
                             f"{s.simulation.duration / MAX_STEPS:.3g} s, or null (every step end)",
                             f"more than {MAX_STEPS:.0e} samples")
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
