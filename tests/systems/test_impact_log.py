"""The impact log of one event with two impulses: Painleve's rod (mu = 3 > mu_c) landing on its
tip while it slides, its LZB impact made frictionless (`frictionless_lzb`; with mu = 3 the LZB
impact itself stops the slip), so that it stops the approach only and the sliding that
follows has no consistent mode, resolved by an impact without collision at the same instant. Each
impulse's logged states against the momentum balance of the rod written out (linear and
angular momentum about the mass centre), and the recorder of `drake_dock.docking.model.simulate`
replaying them; `max_impacts` counting both kinds."""
import math
import types

import numpy as np
import pytest
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from drake_dock.errors import ZenoError
from drake_dock.studies.small_scenes import (PAINLEVE_THETA, WITNESS_ACCURACY_FLOOR,
                                             painleve_rod, painleve_state)
from drake_dock.systems.contact_system import ContactOptions
from drake_dock.systems.simulator import make_simulator

VZ = -0.05       # m/s: the tip's approach speed at t = 0


@pytest.fixture
def frictionless_lzb(monkeypatch):
    """LZB impacts without friction (`solve_lzb` with mu = 0): they leave the tip sliding."""
    from drake_dock.systems import impacts
    real = impacts.solve_lzb
    monkeypatch.setattr(impacts, "solve_lzb", lambda *a, **k: real(*a, **{**k, "mu": 0.0}))


def landing_rod(options=ContactOptions()):
    """The rod as `painleve_state` puts it (tip on the plane, sliding at 1 m/s towards -x), its
    tip also moving down at VZ; in a diagram exporting the ports the recorder reads. Returns
    (scene, diagram, set_state(root), lever r of the tip's contact point from the mass
    centre, the world inertia)."""
    sc = painleve_rod(PAINLEVE_THETA, mu=3.0, options=options)
    (R, com), (w, v) = painleve_state(sc)
    v = v + np.array([0.0, 0.0, VZ])
    p = sc.params
    ax = R[:, 0]
    r = -p["l"] * ax - np.array([0.0, 0.0, p["rho"]])
    I_W = R @ np.diag([1e-4 * p["I"], p["I"], p["I"]]) @ R.T
    b = DiagramBuilder()
    system = b.AddSystem(sc.system)
    b.ExportOutput(system.GetOutputPort("state"), "state")
    b.ExportOutput(system.GetOutputPort("energy"), "energy")
    b.ExportOutput(b.AddSystem(ConstantVectorSource([0.0])).get_output_port(), "ring_distance")
    diagram = b.Build()

    def set_state(root):
        sc.set_state(system.GetMyMutableContextFromRoot(root), (R, com), (w, v))
    return sc, diagram, set_state, r, I_W


def initialized(options=ContactOptions()):
    sc, diagram, set_state, r, I_W = landing_rod(options)
    sim = make_simulator(diagram, SimulatorConfig(integration_scheme="runge_kutta5",
                                                  accuracy=1e-10, max_step_size=0.05),
                         set_state, witness_accuracy=WITNESS_ACCURACY_FLOOR)
    sim.Initialize()
    return sc, diagram, sim, r, I_W


def test_two_impulses_in_one_event_carry_their_states(frictionless_lzb):
    """At t = 0 the event logs the LZB impact, then the impact without collision. Each entry's
    states just before and after it (v = x[7:13] = [w, v]) satisfy the momentum balance of its
    impulse P = P_n z + P_ta x + P_tb y at the tip (the plane's frame): m dv = P and
    I dw = r x P; the kinetic energy drops by its energy_lost; the second starts where the
    first ends, and ends with the tip at rest (sticking). The recorder replays both."""
    from drake_dock.docking.model.simulate import POST_IMPACT, STEP, _Recorder
    sc, diagram, sim, r, I_W = initialized()
    root = sim.get_context()
    imp = sc.system.get_modes(sc.system.GetMyContextFromRoot(root)).impacts
    assert len(imp) == 2 and not imp[0].get("without_collision")
    assert imp[1]["without_collision"] and imp[0]["t"] == imp[1]["t"] == 0.0
    m = sc.params["mass"]
    lost = 0.0
    for e in imp:
        (P_n,), ((P_ta, P_tb),) = e["normal_impulse"], e["tangential_impulse"]
        P = np.array([P_ta, P_tb, P_n])
        w0, v0 = e["x_minus"][7:10], e["x_minus"][10:13]
        w1, v1 = e["x_plus"][7:10], e["x_plus"][10:13]
        scale = np.abs(P).max()
        np.testing.assert_allclose(m * (v1 - v0), P, atol=1e-9 * scale)
        np.testing.assert_allclose(I_W @ (w1 - w0), np.cross(r, P), atol=1e-9 * scale)
        ke = lambda w, v: 0.5 * (m * v @ v + w @ I_W @ w)  # noqa: E731
        np.testing.assert_allclose(ke(w0, v0) - ke(w1, v1), e["energy_lost"], rtol=1e-8)
        lost += e["energy_lost"]
        np.testing.assert_allclose(e["impact_loss_plus"], lost, rtol=1e-9)
        assert len(e["pairs_plus"]) == 1
    np.testing.assert_array_equal(imp[1]["x_minus"], imp[0]["x_plus"])
    assert imp[0]["x_plus"][12] > VZ          # the LZB impact stopped the approach, not the slip
    w1, v1 = imp[1]["x_plus"][7:10], imp[1]["x_plus"][10:13]
    assert np.abs(v1 + np.cross(w1, r)).max() < 1e-12
    # The recorder after Initialize (as `simulate` calls it): no step end before the event,
    # the state after each impulse, then the state the event left.
    rec = _Recorder(types.SimpleNamespace(diagram=diagram, contact=sc.system))
    rec.sample(root)
    assert rec.record.kind == [POST_IMPACT, POST_IMPACT, STEP]
    for k, e in enumerate(imp):
        np.testing.assert_array_equal(rec.record.x[k], e["x_plus"][:13])
    np.testing.assert_array_equal(rec.record.x[2], imp[1]["x_plus"][:13])


@pytest.mark.parametrize("landing", [True, False])
def test_impacts_without_collision_count_against_max_impacts(landing, frictionless_lzb):
    """With max_impacts = 1 the landing rod's LZB impact is admitted and its impact without
    collision, the second impulse, raises `ZenoError`; with max_impacts = 0 the sliding rod's
    impact without collision alone does (its tip has no approach speed: no LZB impact)."""
    opts = ContactOptions(max_impacts=1 if landing else 0)
    if landing:
        with pytest.raises(ZenoError, match=r"max_impacts = 1 .*tip_plane"):
            initialized(opts)
    else:
        sc = painleve_rod(PAINLEVE_THETA, mu=3.0, options=opts)
        X, V = painleve_state(sc)
        with pytest.raises(ZenoError, match=r"max_impacts = 0 .*tip_plane") as err:
            make_simulator(sc.system, SimulatorConfig(integration_scheme="runge_kutta5",
                                                      accuracy=1e-10),
                           lambda root: sc.set_state(root, X, V),
                           witness_accuracy=WITNESS_ACCURACY_FLOOR).Initialize()
        assert math.isclose(err.value.time, 0.0, abs_tol=0.0)
