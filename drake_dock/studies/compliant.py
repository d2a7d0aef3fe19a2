"""The docking scene with Drake's own compliant contact: the baseline of the speed-accuracy study.

The same three bodies, Stewart element (`plant.populate_plant`), friction and initial state as the
rigid model; the contact is MultibodyPlant's, between collision geometry made from the same
analytic patches (`apds.py`):

- each petal's guide surface is cut into ``n_around`` x ``n_height`` cells; a cell is the
  convex hull of 3 x 3 points on the surface and the same points moved ``thickness`` along the
  outward normal (away from the axis: the opposite ring and petals touch the petal's
  axis-facing side, which is the analytic surface). A hull face is a chord of the cone, so the
  piece stands proud of the surface by at most the sagitta (0.5 mm at the default 12 cells
  per 60 deg petal at 0.5 m radius);
- the ring is ``n_ring`` convex sectors of the annulus Rs <= rho <= Rs + ``ring_width``, depth
  ``ring_depth`` below zeta = 0, whose inner top edge is the ring circle (the sagitta again
  bounds the polygonal error: 0.4 mm at 72 sectors).

Contact models: ``hydroelastic`` (compliant convex pieces, hydroelastic modulus ``stiffness``
in Pa) or ``point`` (penetration-based, ``stiffness`` in N/m), both with Hunt-Crossley
dissipation ``dissipation`` (s/m) and Coulomb friction (mu_s, mu). Time stepping: discrete SAP
at ``time_step`` > 0, or continuous (``time_step`` = 0) with error-controlled Runge-Kutta 3 at
``accuracy``.

A simulator monitor records the time, the axial ring-centre distance (for capture) and the
plant's state after every step. After the run (outside its wall time) the states give the
chaser's velocity, the APDS's angular velocity, the Stewart stroke, and the net contact force
on the chaser from its momentum change over each step (the chaser feels no other force: no
gravity, no Stewart element). The capture time and the values at capture are interpolated
linearly between the two steps around it.
"""
import dataclasses
import math
import time as _time

import numpy as np
from pydrake.common import MemoryFile
from pydrake.geometry import (AddCompliantHydroelasticProperties, AddContactMaterial, Convex,
                              InMemoryMesh, ProximityProperties)
from pydrake.math import RigidTransform
from pydrake.multibody.plant import (AddMultibodyPlantSceneGraph, ContactModel, CoulombFriction,
                                     DiscreteContactApproximation)
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.framework import DiagramBuilder, EventStatus
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.spatial import ConvexHull

from drake_dock.docking.apds import guide_surface
from drake_dock.docking.diagram import axial_ring_distance
from drake_dock.docking.plant import (DockingPlant, populate_plant, set_initial_state,
                                      stewart_history)
from drake_dock.errors import InputError
from drake_dock.systems.simulator import make_simulator


@dataclasses.dataclass
class CompliantConfig:
    model: str = "hydroelastic"     # "hydroelastic" | "point"
    stiffness: float = 1e8          # hydroelastic modulus [Pa] or point stiffness [N/m]
    time_step: float = 1e-4         # > 0: discrete SAP; 0: continuous RK3
    accuracy: float = 1e-4          # continuous only
    dissipation: float | None = None   # Hunt-Crossley [s/m]; None: matched to restitution
    n_around: int = 12
    n_height: int = 4
    n_ring: int = 72
    thickness: float = 0.002
    offset: str = "inward"          # petal plates grow from the surface: "inward" | "outward"
    ring_width: float = 0.05
    ring_depth: float = 0.04

    def label(self) -> str:
        step = (f"SAP h={self.time_step:.0e}" if self.time_step > 0
                else f"RK3 acc={self.accuracy:.0e}")
        unit = "Pa" if self.model == "hydroelastic" else "N/m"
        return f"{self.model} k={self.stiffness:.0e} {unit}, {step}"

    def simulator_config(self) -> SimulatorConfig:
        """Discrete (SAP): Drake's default Simulator (the plant's own step sets the steps);
        continuous: error-controlled Runge-Kutta 3 at ``accuracy``."""
        if self.time_step > 0:
            return SimulatorConfig()
        return SimulatorConfig(integration_scheme="runge_kutta3", accuracy=self.accuracy,
                               use_error_control=True)

    def validate(self):
        if self.model not in ("hydroelastic", "point"):
            raise InputError("compliant.model", self.model, "hydroelastic or point")
        for name in ("stiffness", "thickness", "ring_width", "ring_depth"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"compliant.{name}", v, "> 0 and finite")
        if not (math.isfinite(self.time_step) and self.time_step >= 0):
            raise InputError("compliant.time_step", self.time_step, ">= 0 s (0 = continuous)")
        return self


def hunt_crossley_dissipation(restitution: float, impact_speed: float) -> float:
    """The Hunt-Crossley dissipation d (s/m) for which a linear spring with force
    k x (1 + d xdot) rebounds at ``restitution`` from ``impact_speed``. Restitution of this law
    depends on d v only (scale k and m out), so one root find on a unit oscillator gives it."""
    if not 0 < restitution < 1:
        raise InputError("contact.restitution", restitution, "0 < e < 1 for a compliant match")

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


def apds_pieces(g, cfg: CompliantConfig) -> list:
    """Convex pieces of one APDS in its frame: lists of points (see module docstring)."""
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
    for a in range(cfg.n_ring):
        t3 = np.linspace(th[a], th[a + 1], 3)
        pts = [np.stack([r * np.cos(t3), r * np.sin(t3), np.full(3, zz)], axis=-1)
               for r in (g.Rs, g.Rs + cfg.ring_width) for zz in (0.0, -cfg.ring_depth)]
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


@dataclasses.dataclass
class CompliantDiagram:
    diagram: object
    dp: DockingPlant
    n_pieces: int


def build_compliant_diagram(scenario, cfg: CompliantConfig) -> CompliantDiagram:
    cfg.validate()
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=cfg.time_step)
    if cfg.time_step > 0:
        plant.set_discrete_contact_approximation(DiscreteContactApproximation.kSap)
    plant.set_contact_model(ContactModel.kHydroelastic if cfg.model == "hydroelastic"
                            else ContactModel.kPoint)
    props = _properties(scenario, cfg)
    pieces = [_convex(p) for p in apds_pieces(scenario.geometry, cfg)]
    n = [0]

    def collision(plant, bodies):
        X_CA = RigidTransform(np.array(scenario.chaser_apds_offset, dtype=float))
        for body, X in ((bodies["target_apds"], RigidTransform()), (bodies["chaser"], X_CA)):
            for i, shape in enumerate(pieces):
                plant.RegisterCollisionGeometry(body, X, shape, f"{body.name()}_piece{i}",
                                                props)
                n[0] += 1

    dp = populate_plant(plant, scene_graph, scenario, collision=collision)
    return CompliantDiagram(builder.Build(), dp, n[0])


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


def run_compliant(scenario, state, cfg: CompliantConfig, *, t_max: float,
                  cd: CompliantDiagram | None = None, wall_limit: float = math.inf
                  ) -> CompliantRun:
    """Runs until capture, ``t_max`` or ``wall_limit`` seconds of wall time (``stopped``);
    wall time covers Initialize and AdvanceTo."""
    cd = cd or build_compliant_diagram(scenario, cfg)
    dp = cd.dp
    plant = dp.plant
    sim = make_simulator(cd.diagram, cfg.simulator_config(), lambda root: set_initial_state(
        dp, plant.GetMyMutableContextFromRoot(root), state))
    root = sim.get_mutable_context()
    e3 = state.X_WB["target_apds"][0][:, 2].copy()
    m_c = scenario.bodies.chaser.mass
    cap = scenario.simulation.capture_distance
    rec = {"t": [], "d": [], "x": []}

    def sample():
        c = plant.GetMyContextFromRoot(root)
        rec["t"].append(root.get_time())
        rec["d"].append(axial_ring_distance(dp, c))
        rec["x"].append(plant.GetPositionsAndVelocities(c))

    stopped = [False]

    def monitor(r):
        sample()
        if rec["d"][-1] <= cap < rec["d"][-2]:
            return EventStatus.ReachedTermination(cd.diagram, "capture")
        if _time.perf_counter() - w0 > wall_limit:
            stopped[0] = True
            return EventStatus.ReachedTermination(cd.diagram, "wall limit")
        return EventStatus.Succeeded()

    error = None
    w0 = _time.perf_counter()
    try:
        sim.Initialize()
        sample()
        sim.set_monitor(monitor)
        sim.AdvanceTo(t_max)
    except RuntimeError as exc:      # e.g. a step failure of the continuous integrator
        error = str(exc).splitlines()[0]
    wall = _time.perf_counter() - w0
    t = np.array(rec["t"])
    d = np.array(rec["d"])
    v, w, stroke = _step_ends(dp, rec["x"])
    force = m_c * np.diff(v, axis=0) / np.maximum(np.diff(t), 1e-300)[:, None]
    captured = len(d) > 1 and d[-1] <= cap < d[-2]
    t_c = spin = v_c = s_c = peak = None
    if captured:
        a = (d[-2] - cap) / (d[-2] - d[-1])
        t_c = float(t[-2] + a * (t[-1] - t[-2]))
        spin = float(((1 - a) * w[-2] + a * w[-1]) @ e3)
        v_c = (1 - a) * v[-2] + a * v[-1]
        s_c = float((1 - a) * stroke[-2] + a * stroke[-1])
        tm = 0.5 * (t[1:] + t[:-1])
        win = (tm >= 0.5 * t_c) & (tm <= t_c)
        peak = float(np.linalg.norm(force[win], axis=1).max()) if win.any() else None
    return CompliantRun(cfg, captured, t_c, spin, None if v_c is None else float(v_c @ e3), peak,
                        v_c, s_c, wall, len(t) - 1, t, force, d, stroke, error, stopped[0])


def _step_ends(dp, X):
    """The chaser's velocity [N, 3], the target APDS's angular velocity [N, 3] and the
    Stewart element's |deflection| [N] at the recorded plant states X."""
    plant = dp.plant
    pc = plant.CreateDefaultContext()
    n = len(X)
    v, w = np.zeros((n, 3)), np.zeros((n, 3))
    for k, x in enumerate(X):
        plant.SetPositionsAndVelocities(pc, x)
        v[k] = plant.EvalBodySpatialVelocityInWorld(pc, dp.bodies["chaser"]).translational()
        w[k] = plant.EvalBodySpatialVelocityInWorld(pc, dp.bodies["target_apds"]).rotational()
    return v, w, stewart_history(dp, X)[0]
