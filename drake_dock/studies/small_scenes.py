"""Small scenes with known answers for the generic contact core (tests, benchmarks, tutorial):
a disk rolling or sliding on an inclined plane (C-S), a rod lying across a fixed edge (C-C),
Painleve's rod with a rounded tip (C-S), and a three-footed stool (three C-S couples).

Each builder returns a `SmallScene`: a finalized continuous MultibodyPlant (not in a diagram;
the contact system owns the state), the `RigidContactSystem`, and a function that writes an
initial state into the system's context. Gravity is tilted instead of the plane (an incline of
angle theta is a horizontal plane under g = 9.81 (sin theta, 0, -cos theta)). `SmallRun` runs a
scene's system.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import FixedOffsetFrame, RotationalInertia, SpatialInertia
from pydrake.systems.analysis import SimulatorConfig

from drake_dock.core.contact_law import ContactLaw
from drake_dock.core.handover import SurfaceEdge
from drake_dock.core.patches import Annulus, Circle, PlaneRect, Segment
from drake_dock.docking.geometry.rotations import rot_x
from drake_dock.systems.contact_system import (COUPLE_SLICES, ContactOptions, ContactPair,
                                               Handover, RigidContactSystem)
from drake_dock.systems.simulator import make_simulator, make_witness_approach

G = 9.81
PAINLEVE_THETA = math.radians(30.0)
ANNULUS_CENTRE_Y = 5.0    # m: `disk_on_incline`'s ring face is centred at y = -this
# The small scenes integrate at SMALL_SCENE_ACCURACY (RK5) and locate their events to 1e-2 of
# a context accuracy of at least WITNESS_ACCURACY_FLOOR, in seconds; `ContactOptions`' default
# impact_rtol (1e-10) is `drake_dock.systems.simulator.tolerances`' value for it.
SMALL_SCENE_ACCURACY = 1e-10
WITNESS_ACCURACY_FLOOR = 1e-8


@dataclasses.dataclass
class SmallScene:
    plant: object
    system: RigidContactSystem
    body: object
    params: dict

    def set_state(self, context, X_WB, V_WB):
        """Pose (R, p) and world spatial velocity (w, v) of the scene's moving body."""
        ctx = self.plant.CreateDefaultContext()
        R, p = X_WB
        self.plant.SetFreeBodyPose(ctx, self.body, RigidTransform(RotationMatrix(R), p))
        from pydrake.multibody.math import SpatialVelocity
        self.plant.SetFreeBodySpatialVelocity(ctx, self.body, SpatialVelocity(*V_WB))
        self.system.set_from_plant_context(context, ctx)


def _plant(gravity):
    plant = MultibodyPlant(0.0)
    plant.mutable_gravity_field().set_gravity_vector(np.asarray(gravity, dtype=float))
    return plant


def disk_on_incline(theta, *, mass=2.0, radius=0.3, mu=0.3, mu_s=None, restitution=0.0,
                    plane_end=50.0, face="plane", edge=False, edge_first=False,
                    options=ContactOptions()) -> SmallScene:
    """A uniform disk (rim = a Circle, C-S) on a plane inclined by theta, its axle along y;
    down-slope is +x; the plane patch ends at x = ``plane_end``. I_axle = m r^2 / 2.
    ``face="annulus"`` takes a ring face instead of the plane: the `Annulus` 1 <= rho <= 100
    (u = (rho, theta), a polar parametrisation) centred at y = -``ANNULUS_CENTRE_Y``, so that the
    disk's path along x runs across it near rho = 5. With ``edge`` (on the plane) the plane's
    end is an edge too: the pair "rim_edge" (C-C, the segment x = plane_end) with a hand-over
    from and to "rim_plane" (`drake_dock.core.handover`), declared after it (``edge_first``:
    before it, the pairs' other order)."""
    if face == "annulus" and edge:
        raise ValueError("disk_on_incline: the edge is the plane's (face='plane')")
    plant = _plant(G * np.array([math.sin(theta), 0.0, -math.cos(theta)]))
    I_ax = 0.5 * mass * radius ** 2
    I_d = 0.25 * mass * radius ** 2
    body = plant.AddRigidBody("disk", SpatialInertia.MakeFromCentralInertia(
        mass, np.zeros(3), RotationalInertia(I_d, I_ax, I_d)))
    rim = plant.AddFrame(FixedOffsetFrame("rim", body.body_frame(),
                                          RigidTransform(RotationMatrix(rot_x(math.pi / 2)),
                                                         np.zeros(3))))
    if face == "annulus":
        frame2 = plant.AddFrame(FixedOffsetFrame("face", plant.world_frame(), RigidTransform(
            np.array([0.0, -ANNULUS_CENTRE_Y, 0.0]))))
        plane = Annulus(1.0, 100.0)
    else:
        frame2 = plant.world_frame()
        plane = PlaneRect([-50.0, -5.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
                          size=(50.0 + plane_end, 10.0))
    plant.Finalize()
    circle = Circle(radius)
    pairs = [ContactPair("rim_plane", "CS", rim, circle, frame2, plane, sigma=1.0)]
    handovers = []
    if edge:
        # The plane's parameters are (x + 50, y + 5); the segment's e gives y = 10 e - 5.
        pairs.insert(0 if edge_first else 1, ContactPair(
            "rim_edge", "CC", rim, circle, plant.world_frame(),
            Segment([plane_end, -5.0, 0.0], [plane_end, 5.0, 0.0])))
        handovers.append(Handover("rim_edge", "rim_plane", SurfaceEdge(
            0, True, lambda e: 10.0 * e, lambda f: 0.1 * f, ("affine", 10.0, 0.0))))
    system = RigidContactSystem(plant, pairs, ContactLaw(mu=mu, mu_s=mu_s,
                                                         restitution=restitution), options,
                                handovers=handovers)
    return SmallScene(plant, system, body, dict(theta=theta, mass=mass, radius=radius,
                                                I_axle=I_ax, mu=mu,
                                                mu_s=system.law.static_mu))


def rod_on_edge(*, mass=1.5, half_length=0.4, mu=0.2, mu_s=None, wrench=True,
                options=ContactOptions()) -> SmallScene:
    """A rod (a Segment along its body y axis, through its mass centre) lying across a fixed
    edge along the world x axis at height 0 (C-C); gravity -z. Input ``rod_wrench`` pushes or
    pulls it."""
    plant = _plant([0.0, 0.0, -G])
    body = plant.AddRigidBody("rod", SpatialInertia.MakeFromCentralInertia(
        mass, np.zeros(3), RotationalInertia(mass * half_length ** 2 / 3, 1e-3 * mass,
                                             mass * half_length ** 2 / 3)))
    plant.Finalize()
    L = half_length
    rod = Segment([0.0, -L, 0.0], [0.0, L, 0.0])
    edge = Segment([-20.0, 0.0, 0.0], [20.0, 0.0, 0.0])
    # n = sigma t1 x t2 must point up, from the edge (body 2) to the rod (body 1): y x x = -z.
    pair = ContactPair("rod_edge", "CC", body.body_frame(), rod, plant.world_frame(), edge,
                       sigma=-1.0)
    system = RigidContactSystem(plant, [pair], ContactLaw(mu=mu, mu_s=mu_s, restitution=0.0),
                                options, wrench_bodies=("rod",) if wrench else ())
    return SmallScene(plant, system, body, dict(mass=mass, mu=mu,
                                                mu_s=system.law.static_mu))


def painleve_rod(theta, *, mass=1.0, half_length=0.5, tip_radius=0.01, mu=1.0,
                 options=ContactOptions()) -> SmallScene:
    """A uniform rod (axis = body x, mass centre at the origin, I = m l^2 / 3) with a rounded
    tip: a Circle of radius ``tip_radius`` centred at (-l, 0, 0) in the body x-z plane, on the
    horizontal plane z = 0 (C-S); gravity -z. The rod makes the angle theta with the plane."""
    plant = _plant([0.0, 0.0, -G])
    l = half_length
    I = mass * l ** 2 / 3
    body = plant.AddRigidBody("rod", SpatialInertia.MakeFromCentralInertia(
        mass, np.zeros(3), RotationalInertia(1e-4 * I, I, I)))
    tip = plant.AddFrame(FixedOffsetFrame("tip", body.body_frame(), RigidTransform(
        RotationMatrix(rot_x(math.pi / 2)), np.array([-l, 0.0, 0.0]))))
    plant.Finalize()
    plane = PlaneRect([-50.0, -5.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], size=(100.0, 10.0))
    pair = ContactPair("tip_plane", "CS", tip, Circle(tip_radius), plant.world_frame(), plane,
                       sigma=1.0)
    system = RigidContactSystem(plant, [pair], ContactLaw(mu=mu, restitution=0.0), options)
    return SmallScene(plant, system, body, dict(theta=theta, mass=mass, l=l, I=I,
                                                rho=tip_radius, mu=mu))


def painleve_state(sc, omega=0.0):
    """Pose and twist of `painleve_rod`'s rod with its tip on the plane sliding at 1 m/s
    towards -x (v_z = 0 at the tip), spinning at ``omega`` about y."""
    th, l, rho = sc.params["theta"], sc.params["l"], sc.params["rho"]
    ax = np.array([math.cos(th), 0, math.sin(th)])
    R = np.array([[math.cos(th), 0, -math.sin(th)], [0, 1, 0],
                  [math.sin(th), 0, math.cos(th)]])
    com = np.array([0, 0, rho]) + l * ax
    w = np.array([0, omega, 0])
    r = -l * ax - np.array([0, 0, rho])
    return (R, com), (w, np.array([-1.0, 0, 0]) - np.cross(w, r))


def painleve_closed_form(mu, *, theta=PAINLEVE_THETA, mass=1.0, l=0.5, rho=0.01):
    """(lambda_n, mu_c) of the sliding rod at rest in rotation (planar form): the tip's normal
    acceleration is A lambda_n - g with A = 1/m + l c (l c - mu (l s + rho)) / I; consistent
    sliding needs A > 0, i.e. mu < mu_c."""
    I = mass * l * l / 3
    c, s = math.cos(theta), math.sin(theta)
    A = 1 / mass + l * c * (l * c - mu * (l * s + rho)) / I
    mu_c = (I / mass + l * l * c * c) / (l * c * (l * s + rho))
    return (G / A if A > 0 else math.nan), mu_c


def stool(*, mass=3.0, foot_radius=0.05, leg_radius=0.25, mu=0.3, restitution=0.0,
          options=ContactOptions()) -> SmallScene:
    """A body with three rounded feet (Circles in vertical planes, 120 deg apart) on the plane
    z = 0: three C-S couples."""
    plant = _plant([0.0, 0.0, -G])
    body = plant.AddRigidBody("stool", SpatialInertia.MakeFromCentralInertia(
        mass, np.zeros(3), RotationalInertia(0.1, 0.1, 0.15)))
    plane = PlaneRect([-50.0, -50.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], size=(100., 100.))
    pairs = []
    for k in range(3):
        a = 2 * math.pi * k / 3
        R = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0],
                      [0, 0, 1]]) @ rot_x(math.pi / 2)
        foot = plant.AddFrame(FixedOffsetFrame(f"foot{k}", body.body_frame(), RigidTransform(
            RotationMatrix(R), np.array([leg_radius * math.cos(a), leg_radius * math.sin(a),
                                         -0.2]))))
        pairs.append(ContactPair(f"foot{k}_plane", "CS", foot, Circle(foot_radius),
                                 plant.world_frame(), plane, sigma=1.0))
    plant.Finalize()
    system = RigidContactSystem(plant, pairs, ContactLaw(mu=mu, restitution=restitution),
                                options)
    return SmallScene(plant, system, body, dict(mass=mass, foot_radius=foot_radius))


class SmallRun:
    """A small scene's ``system`` in a Simulator (`make_simulator`: RK5 at ``accuracy``, the
    step capped at ``max_step``) with `WitnessApproach`, initialized; ``couple(name)`` reads a
    couple's output, ``samples`` holds (t, gap of the first pair, x[:13]) after each step."""

    def __init__(self, system, set_state, *, accuracy=SMALL_SCENE_ACCURACY, max_step=0.01):
        self.system = system
        config = SimulatorConfig(integration_scheme="runge_kutta5", accuracy=accuracy,
                                 max_step_size=max_step)
        witness = max(accuracy, WITNESS_ACCURACY_FLOOR)
        self.sim = make_simulator(system, config, set_state, witness_accuracy=witness)
        self.ctx = self.sim.get_mutable_context()
        approach = make_witness_approach(self.sim, [system], config, witness_accuracy=witness)
        self.samples = []

        def monitor(root):
            self.samples.append((root.get_time(), self.couple(system.pairs[0].name)["gap"],
                                 root.get_continuous_state_vector().CopyToVector()[:13]))
            approach(root)
        self.sim.Initialize()
        self.sim.set_monitor(monitor)

    def couple(self, name):
        y = self.system.get_couple_output_port(name).Eval(self.ctx)
        return {k: (float(y[s][0]) if len(y[s]) == 1 else y[s])
                for k, s in COUPLE_SLICES.items()}

    @property
    def impacts(self):
        return self.system.get_modes(self.ctx).impacts
