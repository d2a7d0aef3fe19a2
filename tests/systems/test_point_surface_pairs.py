"""A point-surface pair (kind "PS") in the contact system against closed forms: a point mass
(a petal corner, radius 0) on an inclined face, sliding with Coulomb friction (x = v0 t + g
(sin theta - mu cos theta) t^2 / 2) or stuck (mu > tan theta), and dropped onto the face
(plastic impact at the free-fall time sqrt(2 h / g cos theta))."""
import math

import numpy as np
import pytest

from drake_dock.core.patches import PlaneRect, Point

THETA = math.radians(25.0)


def point_on_incline(mu, *, v0=0.0, height=0.0, sigma=None):
    """A point mass (1 kg, its origin a bare `Point`) on the plane z = 0 under gravity g tilted
    by THETA (down-slope +x), started at ``height`` above it moving down-slope at ``v0``;
    returns the initialized `SmallRun`."""
    from pydrake.multibody.tree import RotationalInertia, SpatialInertia
    from drake_dock.core.contact_law import ContactLaw
    from drake_dock.studies.small_scenes import G, SmallRun, SmallScene, _plant
    from drake_dock.systems.contact_system import ContactPair, RigidContactSystem
    plant = _plant(G * np.array([math.sin(THETA), 0.0, -math.cos(THETA)]))
    body = plant.AddRigidBody("corner", SpatialInertia.MakeFromCentralInertia(
        1.0, np.zeros(3), RotationalInertia(1e-3, 1e-3, 1e-3)))
    plant.Finalize()
    plane = PlaneRect([-50.0, -5.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], size=(100.0, 10.0))
    pair = ContactPair("ps", "PS", body.body_frame(), Point((0.0, 0.0, 0.0)),
                       plant.world_frame(), plane, sigma=sigma)
    sc = SmallScene(plant, RigidContactSystem(plant, [pair], ContactLaw(mu=mu)), body, {})
    X = (np.eye(3), np.array([0.0, 0.0, height]))
    V = (np.zeros(3), np.array([v0, 0.0, 0.0]))
    return SmallRun(sc.system, lambda root: sc.set_state(root, X, V), accuracy=1e-10)


def position(run):
    return run.ctx.get_continuous_state_vector().CopyToVector()[4:7]


@pytest.mark.parametrize("mu, v0", [(0.2, 0.0), (0.3, 0.5)])
def test_sliding_point_follows_closed_form(mu, v0):
    from drake_dock.studies.small_scenes import G
    run = point_on_incline(mu, v0=v0)
    t = 0.8
    run.sim.AdvanceTo(t)
    x = v0 * t + 0.5 * G * (math.sin(THETA) - mu * math.cos(THETA)) * t ** 2
    np.testing.assert_allclose(position(run), [x, 0.0, 0.0], atol=1e-8)
    c = run.couple("ps")
    assert c["lambda_n"] == pytest.approx(G * math.cos(THETA), rel=1e-8)


def test_point_sticks_where_mu_exceeds_tan_theta():
    run = point_on_incline(0.6)                   # tan(25 deg) = 0.466
    run.sim.AdvanceTo(0.5)
    np.testing.assert_allclose(position(run), 0.0, atol=1e-9)


def test_dropped_point_bounces_at_the_closed_form_times():
    """Released 5 cm above a frictionless face (e = 0.1): impacts on the pair at the free-fall
    time t1 = sqrt(2 h / (g cos theta)), then after each flight of 2 e^k v1 / (g cos theta)
    (a frictionless single impact with energetic restitution e reverses e times the normal
    velocity, v1 = g cos(theta) t1); x keeps the free acceleration g sin(theta) throughout."""
    from drake_dock.studies.small_scenes import G
    h, e, gc = 0.05, 0.1, G * math.cos(THETA)
    run = point_on_incline(0.0, height=h)
    t1 = math.sqrt(2 * h / gc)
    t = t1 + 0.2
    run.sim.AdvanceTo(t)
    times = [i.t for i in run.impacts]
    assert all(i.couples == ["ps"] for i in run.impacts)
    want = t1 + np.cumsum([0.0] + [2 * e ** k * gc * t1 / gc for k in (1, 2)])
    np.testing.assert_allclose(times[:3], want, atol=1e-7)
    np.testing.assert_allclose(position(run), [0.5 * G * math.sin(THETA) * t ** 2, 0.0, 0.0],
                               atol=1e-7)
