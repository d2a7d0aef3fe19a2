"""The docking scene with Drake's own compliant contact: the baseline of the speed-accuracy study
and the referee of the crosscheck (`drake_dock.studies.crosscheck`).

The same three bodies, Stewart element (`plant.populate_plant`), friction, post-contact thrust
and initial state as the rigid model; the contact is MultibodyPlant's, between collision
geometry made from the same analytic patches (`apds.py`):

- each petal's guide surface (`apds.guide_surface`: the cone from the petal root radius
  ``geometry.petal_root_radius``, Rp, at zeta = 0 to the tip at zeta = H) is cut into
  ``n_around`` x ``n_height`` cells; a cell is the convex hull of 3 x 3 points on the surface
  and the same points moved ``thickness`` along the normal, inwards (towards the axis) by
  default (``offset``). The analytic surface is then the plate's outer face, the side that the
  other APDS's ring and petals touch (grown outwards, the plates would touch early: the cone's
  outward normal leans towards the other APDS). The outer faces of a hull are chords between
  neighbouring points, so the piece lies inside the surface by at most their sagitta (0.13 mm
  at 12 cells across a 60 deg petal root at 0.55 m radius: points 2.5 deg apart);
- the ring is ``n_ring`` convex sectors of the annulus Rs <= rho <= Rs + ``ring_width``, depth
  ``ring_depth`` below zeta = 0: its top face is the ring face, its inner top edge the ring's
  inside circle. A sector's inner face is the chord of its arc: it stands inside the circle by
  at most the sagitta (0.13 mm at 144 sectors and Rs = 0.55 m, 0.52 mm at 72). ``ring_width``
  None follows the scenario's contact set (`ring_width`): the whole annulus Rs..R where the ring
  face is a contact feature (``complete``), `PAPER_RING_WIDTH` with the paper's 12 pairs, which
  hold the ring's inside circle only (in the paper's example the other APDS's petals cross the
  ring face's outer part, and no pair stops them).

Contact models: ``hydroelastic`` (compliant convex pieces, hydroelastic modulus ``stiffness``
in Pa) or ``point`` (penetration-based, ``stiffness`` in N/m per geometry: two pieces in
contact combine in series, k / 2), with Coulomb friction (mu_s, mu; ``similar`` and
``lagged`` regularize it below the slip speed ``stiction_tolerance``) and dissipation
``dissipation`` (s/m): Hunt-Crossley for point contact with the discrete approximations
``similar`` and ``lagged`` and for continuous time. Drake's ``sap`` approximation models
dissipation as linear Kelvin-Voigt with a relaxation time instead and ignores it. Time
stepping: discrete at ``time_step`` > 0 with the approximation ``approximation``, or
continuous (``time_step`` = 0) with error-controlled Runge-Kutta 3 at ``accuracy``.

Post-contact thrust (the scenario's ``thrust`` section, `drake_dock.docking.model.thrust`):
`CompliantThrust` applies F e3 (e3 the chaser APDS frame's docking axis) at the chaser's mass
centre through the plant's applied spatial force input, in the schedule's windows after the
run's own first contact: the end of the first step with a non-zero contact force, which the
run's monitor latches into the system's state.

A simulator monitor records the time and the plant's state after every step and applies the
outcome rules of the rigid model (`drake_dock.docking.model.outcome`): ``captured`` when the
distance to capture (`CaptureRule.to_go`) reaches the axial tolerance, the capture time
interpolated linearly between the two steps around it; ``missed``, ``rebound`` and ``jammed``
by `OutcomeWatch`; ``timeout`` at ``t_max``. After the run (outside its wall time) the states
give the chaser's velocity, the APDS's angular velocity, the Stewart stroke, and the net
contact force on the chaser from its momentum change over each step less the thrust's (the
chaser feels no other force: no gravity, no Stewart element). Contact acts between the
chaser and the target APDS only, so the force on the target APDS, the interface force, is its
opposite.
"""
import dataclasses
import math
import time as _time

import numpy as np
from pydrake.common import MemoryFile
from pydrake.common.value import AbstractValue
from pydrake.geometry import (AddCompliantHydroelasticProperties, AddContactMaterial, Convex,
                              InMemoryMesh, ProximityProperties)
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import (AddMultibodyPlantSceneGraph, ContactModel, CoulombFriction,
                                     DiscreteContactApproximation,
                                     ExternallyAppliedSpatialForce)
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.framework import DiagramBuilder, EventStatus, LeafSystem
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.spatial import ConvexHull

from drake_dock.docking.geometry.apds import guide_surface
from drake_dock.docking.model.capture import ring_poses
from drake_dock.docking.model.outcome import CaptureRule, OutcomeWatch, misalignment
from drake_dock.docking.model.plant import (DockingPlant, PlantSpec, populate_plant,
                                            set_initial_state, stewart_history)
from drake_dock.docking.model.thrust import ThrustSchedule
from drake_dock.errors import InputError
from drake_dock.systems.simulator import make_simulator

APPROXIMATIONS = {"sap": DiscreteContactApproximation.kSap,
                  "similar": DiscreteContactApproximation.kSimilar,
                  "lagged": DiscreteContactApproximation.kLagged}


@dataclasses.dataclass
class CompliantConfig:
    model: str = "hydroelastic"     # "hydroelastic" | "point"
    stiffness: float = 1e8          # hydroelastic modulus [Pa] or point stiffness [N/m]
    time_step: float = 1e-4         # > 0: discrete; 0: continuous RK3
    accuracy: float = 1e-4          # continuous only
    dissipation: float | None = None   # Hunt-Crossley [s/m]; None: matched to restitution
    n_around: int = 12
    n_height: int = 4
    n_ring: int = 72
    thickness: float = 0.002
    offset: str = "inward"          # petal plates grow from the surface: "inward" | "outward"
    ring_width: float | None = None   # m; None: by the contact set (`ring_width`)
    ring_depth: float = 0.04
    approximation: str = "sap"      # discrete only: "sap" | "similar" | "lagged"
    stiction_tolerance: float | None = None   # m/s (similar, lagged); None: Drake's default

    def label(self) -> str:
        step = (f"{self.approximation.upper()} h={self.time_step:.0e}" if self.time_step > 0
                else f"RK3 acc={self.accuracy:.0e}")
        unit = "Pa" if self.model == "hydroelastic" else "N/m"
        return f"{self.model} k={self.stiffness:.0e} {unit}, {step}"

    def simulator_config(self) -> SimulatorConfig:
        """Discrete: Drake's default Simulator (the plant's own step sets the steps);
        continuous: error-controlled Runge-Kutta 3 at ``accuracy``."""
        if self.time_step > 0:
            return SimulatorConfig()
        return SimulatorConfig(integration_scheme="runge_kutta3", accuracy=self.accuracy,
                               use_error_control=True)

    def refined(self, stiffness_factor: float = 4.0, step_factor: float = 0.5):
        """The configuration with the stiffness times ``stiffness_factor`` and the step (or
        the continuous accuracy) times ``step_factor``."""
        return dataclasses.replace(
            self, stiffness=self.stiffness * stiffness_factor,
            time_step=self.time_step * step_factor,
            accuracy=self.accuracy * (step_factor if self.time_step == 0 else 1.0))

    def validate(self):
        if self.model not in ("hydroelastic", "point"):
            raise InputError("compliant.model", self.model, "hydroelastic or point")
        if self.approximation not in APPROXIMATIONS:
            raise InputError("compliant.approximation", self.approximation,
                             " or ".join(APPROXIMATIONS))
        for name in ("stiffness", "thickness", "ring_depth", "accuracy"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"compliant.{name}", v, "> 0 and finite")
        if self.ring_width is not None and not (math.isfinite(self.ring_width)
                                                and self.ring_width > 0):
            raise InputError("compliant.ring_width", self.ring_width,
                             "> 0 m and finite, or None (the annulus Rs..R)")
        if not (math.isfinite(self.time_step) and self.time_step >= 0):
            raise InputError("compliant.time_step", self.time_step, ">= 0 s (0 = continuous)")
        if self.stiction_tolerance is not None and not (
                math.isfinite(self.stiction_tolerance) and self.stiction_tolerance > 0):
            raise InputError("compliant.stiction_tolerance", self.stiction_tolerance,
                             "> 0 m/s and finite, or None (Drake's default)")
        if self.dissipation is not None and not (math.isfinite(self.dissipation)
                                                 and self.dissipation >= 0):
            raise InputError("compliant.dissipation", self.dissipation, ">= 0 s/m and finite")
        for name in ("n_around", "n_height", "n_ring"):
            v = getattr(self, name)
            if not (isinstance(v, int) and v >= (3 if name == "n_ring" else 1)):
                raise InputError(f"compliant.{name}", v,
                                 "an integer >= 3" if name == "n_ring" else "an integer >= 1")
        return self


def hunt_crossley_dissipation(restitution: float, impact_speed: float) -> float:
    """The Hunt-Crossley dissipation d (s/m) for which a linear spring with force
    k x (1 + d xdot) rebounds at ``restitution`` from ``impact_speed``. Restitution of this law
    depends on d v only (scale k and m out), so one root find on a unit oscillator gives it."""
    if not 0 < restitution < 1:
        raise InputError("contact.restitution", restitution, "0 < e < 1 for a compliant match")
    if not (math.isfinite(impact_speed) and impact_speed > 0):
        raise InputError("impact speed", impact_speed, "> 0 m/s and finite")

    def e_of(dv):
        def f(t, y):
            x, xd = y
            return [xd, -max(x, 0.0) * (1.0 + dv * xd)] if x > 0 else [xd, 0.0]

        def out(t, y):
            return y[0]
        out.terminal, out.direction = True, -1
        sol = solve_ivp(f, (0, 50), [1e-12, 1.0], events=out, rtol=1e-10, atol=1e-13,
                        max_step=0.01)
        return -sol.y_events[0][0][1] if sol.y_events[0].size else 0.0
    dv = brentq(lambda a: e_of(a) - restitution, 1e-3, 20.0, xtol=1e-8)
    return dv / impact_speed


def _convex(points) -> Convex:
    hull = ConvexHull(points)
    V = hull.points[hull.vertices]
    index = {int(k): i for i, k in enumerate(hull.vertices)}
    lines = [f"v {x:.12g} {y:.12g} {z:.12g}" for x, y, z in V]
    for f in hull.simplices:
        a, b, c = (index[int(k)] + 1 for k in f)
        lines.append(f"f {a} {b} {c}")
    return Convex(InMemoryMesh(mesh_file=MemoryFile("\n".join(lines) + "\n", ".obj",
                                                     "piece.obj")))


PAPER_RING_WIDTH = 0.05     # m: the ring's width with the paper's 12 pairs (`ring_width`)


def ring_width(g, cfg: CompliantConfig, pairs: str = "complete") -> float:
    """The compliant ring's radial width (m): ``cfg.ring_width``, or where None, R - Rs with
    the ``complete`` contact set and min(`PAPER_RING_WIDTH`, R - Rs) with ``paper``."""
    if cfg.ring_width is not None:
        return cfg.ring_width
    return min(PAPER_RING_WIDTH, g.R - g.Rs) if pairs == "paper" else g.R - g.Rs


def apds_pieces(g, cfg: CompliantConfig, pairs: str = "complete") -> list:
    """Convex pieces of one APDS in its frame: lists of points (see module docstring);
    ``pairs``: the scenario's contact set, which sets the ring's width (`ring_width`)."""
    pieces = []
    s = np.linspace(0.0, 1.0, cfg.n_around + 1)
    z = np.linspace(0.0, g.H, cfg.n_height + 1)
    for k in (1, 2, 3):
        P = guide_surface(g, k)
        for a in range(cfg.n_around):
            for b in range(cfg.n_height):
                ss = np.linspace(s[a], s[a + 1], 3)
                zz = np.linspace(z[b], z[b + 1], 3)
                S, Z = np.meshgrid(ss, zz, indexing="ij")
                u = np.stack([S, Z], axis=-1).reshape(-1, 2)
                X = P.position(u)
                T = P.first(u)
                n = np.cross(T[..., 0], T[..., 1])
                n /= np.linalg.norm(n, axis=-1, keepdims=True)
                n *= np.sign(np.einsum("ix,ix->i", n[:, :2], X[:, :2]))[:, None]
                side = 1.0 if cfg.offset == "outward" else -1.0
                pieces.append(np.vstack([X, X + side * cfg.thickness * n]))
    th = np.linspace(0.0, 2 * math.pi, cfg.n_ring + 1)
    outer = g.Rs + ring_width(g, cfg, pairs)
    for a in range(cfg.n_ring):
        t3 = np.linspace(th[a], th[a + 1], 3)
        pts = [np.stack([r * np.cos(t3), r * np.sin(t3), np.full(3, zz)], axis=-1)
               for r in (g.Rs, outer) for zz in (0.0, -cfg.ring_depth)]
        pieces.append(np.vstack(pts))
    return pieces


def _properties(scenario, cfg: CompliantConfig) -> ProximityProperties:
    c = scenario.contact
    props = ProximityProperties()
    friction = CoulombFriction(c.static_mu, c.mu)
    if cfg.model == "hydroelastic":
        AddContactMaterial(cfg.dissipation, None, friction, props)
        AddCompliantHydroelasticProperties(cfg.thickness, cfg.stiffness, props)
    else:
        AddContactMaterial(cfg.dissipation, cfg.stiffness, friction, props)
    return props


class CompliantThrust(LeafSystem):
    """Input ``state`` (the plant's [q, v]); discrete state: the first contact's time (s, +inf
    before it; written by the run's monitor, `run_compliant`); output ``applied_spatial_force``
    for the plant: F e3 on the chaser at its mass centre (e3 the chaser APDS frame's docking
    axis, world frame) while the `ThrustSchedule` acts, zero otherwise."""

    def __init__(self, dp: DockingPlant, schedule: ThrustSchedule):
        super().__init__()
        self.dp, self.schedule = dp, schedule
        self._pc = dp.plant.CreateDefaultContext()
        self._nq = dp.plant.num_positions()
        self._index = dp.bodies["chaser"].index()
        n = self._nq + dp.plant.num_velocities()
        self._state = self.DeclareVectorInputPort("state", n)
        self._contact = self.DeclareDiscreteState([math.inf])
        self.DeclareAbstractOutputPort(
            "applied_spatial_force",
            lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]), self._out)

    def first_contact_time(self, context) -> float:
        return float(context.get_discrete_state(self._contact).GetAtIndex(0))

    def set_first_contact_time(self, context, t: float):
        context.get_mutable_discrete_state(self._contact).SetAtIndex(0, t)

    def force(self, context) -> np.ndarray:
        """The thrust on the chaser (N, world frame) in ``context``."""
        tc = self.first_contact_time(context)
        if not (math.isfinite(tc) and self.schedule.on(context.get_time() - tc)):
            return np.zeros(3)
        self.dp.plant.SetPositions(self._pc, self._state.Eval(context)[:self._nq])
        axis = self.dp.apds_frames["chaser_apds"].CalcPoseInWorld(self._pc).rotation().col(2)
        return self.schedule.force * np.asarray(axis)

    def _out(self, context, out):
        f = ExternallyAppliedSpatialForce()
        f.body_index = self._index
        f.p_BoBq_B = np.zeros(3)
        f.F_Bq_W = SpatialForce(np.zeros(3), self.force(context))
        out.set_value([f])


@dataclasses.dataclass
class CompliantDiagram:
    diagram: object
    dp: DockingPlant
    n_pieces: int
    thrust: CompliantThrust | None = None


def build_compliant_diagram(scenario, cfg: CompliantConfig) -> CompliantDiagram:
    cfg.validate()
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=cfg.time_step)
    if cfg.time_step > 0:
        plant.set_discrete_contact_approximation(APPROXIMATIONS[cfg.approximation])
    if cfg.stiction_tolerance is not None:
        plant.set_stiction_tolerance(cfg.stiction_tolerance)
    plant.set_contact_model(ContactModel.kHydroelastic if cfg.model == "hydroelastic"
                            else ContactModel.kPoint)
    props = _properties(scenario, cfg)
    pieces = [_convex(p) for p in apds_pieces(scenario.geometry, cfg,
                                               scenario.contact.pairs)]
    n = [0]

    def collision(plant, bodies):
        X_CA = RigidTransform(np.array(scenario.chaser_apds_offset, dtype=float))
        for body, X in ((bodies["target_apds"], RigidTransform()), (bodies["chaser"], X_CA)):
            for i, shape in enumerate(pieces):
                plant.RegisterCollisionGeometry(body, X, shape, f"{body.name()}_piece{i}",
                                                props)
                n[0] += 1

    dp = populate_plant(plant, scene_graph, PlantSpec.of(scenario), collision=collision)
    schedule = ThrustSchedule.of(scenario.thrust)
    thrust = None
    if schedule is not None:
        thrust = builder.AddSystem(CompliantThrust(dp, schedule))
        thrust.set_name("thrust")
        builder.Connect(plant.get_state_output_port(), thrust.get_input_port())
        builder.Connect(thrust.get_output_port(), plant.get_applied_spatial_force_input_port())
    return CompliantDiagram(builder.Build(), dp, n[0], thrust)


@dataclasses.dataclass
class CompliantRun:
    config: CompliantConfig
    captured: bool
    capture_time: float | None
    apds_spin_rate: float | None       # target APDS angular velocity . e3 at capture [rad/s]
    chaser_axial_velocity: float | None   # chaser velocity . e3 at capture [m/s]
    peak_force: float | None           # peak |net contact force on the chaser| in [t_c/2, t_c]
    chaser_velocity: np.ndarray | None   # at capture [m/s]
    stroke_at_capture: float | None    # |Stewart deflection| at capture [m]
    wall_time: float
    steps: int
    t: np.ndarray                      # step ends
    force: np.ndarray                  # [N, 3] net contact force on the chaser over each step
    ring_distance: np.ndarray
    stroke: np.ndarray                 # |Stewart deflection| at the step ends [m]
    error: str | None = None
    stopped: bool = False              # ended by the wall-time limit
    outcome: str = "timeout"           # `drake_dock.docking.model.outcome.OUTCOMES`, or "error"
    reason: str = ""
    first_contact_time: float = math.inf   # end of the first step with a contact force [s]
    peak_interface_force: float = 0.0  # peak |net contact force on the target APDS| [N]
    chaser_velocities: np.ndarray | None = None   # [N, 3] at the step ends [m/s]
    thrust_force: np.ndarray | None = None        # [N - 1, 3] on the chaser over each step
    lateral: np.ndarray | None = None  # [N] the rings' lateral offset at the step ends [m]
    tilt: np.ndarray | None = None     # [N] the tilt between the docking axes [rad]
    states: np.ndarray | None = None   # [N, nq + nv] the plant's state at the step ends


def _in_contact(plant, plant_context) -> bool:
    """Whether the plant's contact results hold a non-zero force."""
    cr = plant.get_contact_results_output_port().Eval(plant_context)
    for k in range(cr.num_point_pair_contacts()):
        if np.any(cr.point_pair_contact_info(k).contact_force() != 0.0):
            return True
    for k in range(cr.num_hydroelastic_contacts()):
        if np.any(cr.hydroelastic_contact_info(k).F_Ac_W().translational() != 0.0):
            return True
    return False


def run_compliant(scenario, state, cfg: CompliantConfig, *, t_max: float,
                  cd: CompliantDiagram | None = None, wall_limit: float = math.inf
                  ) -> CompliantRun:
    """Runs until a named outcome (module docstring), ``t_max`` (``timeout``) or
    ``wall_limit`` seconds of wall time (``timeout``, ``stopped``); wall time covers
    Initialize and AdvanceTo. A failure of Drake's integration ends the run with outcome
    ``error`` and its message in ``error``."""
    cd = cd or build_compliant_diagram(scenario, cfg)
    dp = cd.dp
    plant = dp.plant
    sim = make_simulator(cd.diagram, cfg.simulator_config(), lambda root: set_initial_state(
        dp, plant.GetMyMutableContextFromRoot(root), state))
    root = sim.get_mutable_context()
    e3 = state.X_WB["target_apds"][0][:, 2].copy()
    m_c = scenario.bodies.chaser.mass
    g, sp = scenario.geometry, scenario.simulation
    rule = CaptureRule.of(sp, g)
    thrust = cd.thrust
    schedule = None if thrust is None else thrust.schedule
    rec = {"t": [], "d": [], "lateral": [], "tilt": [], "to_go": [], "x": []}
    pc = plant.GetMyContextFromRoot(root)
    tc_ctx = None if thrust is None else thrust.GetMyMutableContextFromRoot(root)
    first = [math.inf]

    def sample():
        pose = misalignment(*ring_poses(dp, pc))
        rec["t"].append(root.get_time())
        rec["d"].append(pose[0])
        rec["lateral"].append(pose[1])
        rec["tilt"].append(pose[2])
        rec["to_go"].append(rule.to_go(*pose))
        rec["x"].append(plant.GetPositionsAndVelocities(pc))
        return pose

    stopped, ended = [False], []

    def monitor(r):
        pose = sample()
        t = rec["t"][-1]
        if not math.isfinite(first[0]) and _in_contact(plant, pc):
            first[0] = t
            if tc_ctx is not None:
                thrust.set_first_contact_time(tc_ctx, t)
        if rec["to_go"][-1] <= rule.axial < rec["to_go"][-2]:
            ended.append(("captured", rule.describe()))
            return EventStatus.ReachedTermination(cd.diagram, "capture")
        driven = schedule is not None and schedule.still_to_act(t - first[0])
        end = watch.update(t, pose[0], pose[1], rec["to_go"][-1], driven)
        if end is not None:
            ended.append(end)
            return EventStatus.ReachedTermination(cd.diagram, end[0])
        if _time.perf_counter() - w0 > wall_limit:
            stopped[0] = True
            return EventStatus.ReachedTermination(cd.diagram, "wall limit")
        return EventStatus.Succeeded()

    error = None
    w0 = _time.perf_counter()
    try:
        sim.Initialize()
        sample()
        watch = OutcomeWatch.of(rec["d"][0], sp, g)
        sim.set_monitor(monitor)
        sim.AdvanceTo(t_max)
    except (Exception, SystemExit) as exc:    # a step failure of the continuous integrator,
        # SAP's, or a C++ failure inside a Python callback (which arrives as SystemExit
        # carrying its message): the run ends with outcome "error"
        if isinstance(exc, SystemExit) and not isinstance(exc.code, str):
            raise
        error = f"{type(exc).__name__}: {(str(exc).splitlines() or [''])[0]}"
    wall = _time.perf_counter() - w0
    t = np.array(rec["t"])
    d = np.array(rec["to_go"])
    v, w, stroke, axis = _step_ends(dp, rec["x"])
    F_thrust = np.zeros((max(len(t) - 1, 0), 3))
    if schedule is not None and math.isfinite(first[0]):
        on = np.array([schedule.on(tk - first[0]) for tk in t[:-1]], dtype=bool)
        F_thrust[on] = schedule.force * axis[:-1][on]
    force = (m_c * np.diff(v, axis=0) / np.maximum(np.diff(t), 1e-300)[:, None] - F_thrust
             if len(t) > 1 else np.zeros((0, 3)))
    outcome, reason = ended[0] if ended else (
        ("error", error) if error else
        ("timeout", f"{'the wall-time limit' if stopped[0] else 't_max'} reached at "
                    f"{t[-1] if len(t) else 0.0:.4g} s"))
    captured = outcome == "captured"
    t_c = spin = v_c = s_c = peak = None
    if captured:
        a = (d[-2] - rule.axial) / (d[-2] - d[-1])
        t_c = float(t[-2] + a * (t[-1] - t[-2]))
        spin = float(((1 - a) * w[-2] + a * w[-1]) @ e3)
        v_c = (1 - a) * v[-2] + a * v[-1]
        s_c = float((1 - a) * stroke[-2] + a * stroke[-1])
        tm = 0.5 * (t[1:] + t[:-1])
        win = (tm >= 0.5 * t_c) & (tm <= t_c)
        peak = float(np.linalg.norm(force[win], axis=1).max()) if win.any() else None
    peak_if = float(np.linalg.norm(force, axis=1).max()) if len(force) else 0.0
    return CompliantRun(cfg, captured, t_c, spin, None if v_c is None else float(v_c @ e3), peak,
                        v_c, s_c, wall, len(t) - 1, t, force, np.array(rec["d"]), stroke, error,
                        stopped[0], outcome, reason, first[0], peak_if, v, F_thrust,
                        np.array(rec["lateral"]), np.array(rec["tilt"]), np.array(rec["x"]))


def _step_ends(dp, X):
    """The chaser's velocity [N, 3], the target APDS's angular velocity [N, 3], the Stewart
    element's |deflection| [N] and the chaser APDS's docking axis [N, 3] at the recorded plant
    states X."""
    plant = dp.plant
    pc = plant.CreateDefaultContext()
    n = len(X)
    v, w, axis = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    for k, x in enumerate(X):
        plant.SetPositionsAndVelocities(pc, x)
        v[k] = plant.EvalBodySpatialVelocityInWorld(pc, dp.bodies["chaser"]).translational()
        w[k] = plant.EvalBodySpatialVelocityInWorld(pc, dp.bodies["target_apds"]).rotational()
        axis[k] = dp.apds_frames["chaser_apds"].CalcPoseInWorld(pc).rotation().col(2)
    stroke = stewart_history(dp, X)[0] if n else np.zeros(0)
    return v, w, stroke, axis
