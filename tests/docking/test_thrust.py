"""Post-contact thrust: the schedule's windows, the scenario's checks, and a coaxial run whose
momentum change, work and switching times the thrust's definition gives in closed form."""
import math

import numpy as np
import pytest
import yaml

from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.model.thrust import ThrustSchedule
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.results import summary, timeseries
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.docking.scenario.schema import ThrustParams
from drake_dock.errors import InputError


def test_schedule_of_delay_and_duration():
    s = ThrustSchedule.of(ThrustParams(force=300.0, delay=0.5, duration=2.0))
    assert s.windows == ((0.5, 2.5),)
    assert [s.on(x) for x in (0.49, 0.5, 2.49, 2.5)] == [False, True, True, False]
    assert s.still_to_act(-1.0) and s.still_to_act(2.4) and not s.still_to_act(2.5)
    assert s.switches() == (0.5, 2.5)
    assert ThrustSchedule.of(None) is None


def test_schedule_open_and_pulsed():
    s = ThrustSchedule.of(ThrustParams(force=10.0))
    assert s.windows == ((0.0, math.inf),) and s.on(1e9) and s.switches() == ()
    p = ThrustSchedule.of(ThrustParams(force=10.0, pulses=[[0.0, 1.0], [2.0, 3.0]]))
    assert [p.on(x) for x in (0.0, 0.99, 1.5, 2.0, 3.0)] == [True, True, False, True, False]
    assert p.switches() == (1.0, 2.0, 3.0)
    assert not ThrustSchedule.of(ThrustParams(force=0.0)).still_to_act(0.0)


def _scenario(thrust: dict, **initial):
    data = yaml.safe_load(PAPER_EXAMPLE.read_text())
    data["thrust"] = thrust
    data["initial"].update(initial)
    return load_scenario(data=yaml.safe_dump(data))


@pytest.mark.parametrize("thrust, field", [
    ({"force": -1.0}, "thrust.force"),
    ({"force": float("nan")}, "thrust.force"),
    ({"force": 100.0, "delay": -0.1}, "thrust.delay"),
    ({"force": 100.0, "duration": 0.0}, "thrust.duration"),
    ({"force": 100.0, "duration": 1.0, "pulses": [[0.0, 1.0]]}, "thrust.pulses"),
    ({"force": 100.0, "pulses": [[1.0, 0.5]]}, "thrust.pulses[0]"),
    ({"force": 100.0, "pulses": [[0.0, 2.0], [1.0, 3.0]]}, "thrust.pulses[1]"),
    ({"force": 100.0, "pulses": [[0.0]]}, "thrust.pulses[0]"),
    ({"force": 100.0, "until": 3.0}, "thrust.until"),
])
def test_bad_thrust_is_named(thrust, field):
    with pytest.raises(InputError) as e:
        _scenario(thrust)
    assert e.value.field == field


@pytest.fixture(scope="module")
def coaxial_run():
    """The paper's APDS closing coaxially at 0.1 m/s with 300 N from 0.05 s to 0.15 s after the
    first contact: the contact forces are three-fold symmetric about the axis, so the chaser
    does not turn its axis and the thrust's direction stays e3."""
    s = _scenario({"force": 300.0, "delay": 0.05, "duration": 0.1}, chaser_speed=0.1)
    s.simulation.duration = 0.35
    r = simulate(s, place(s))
    ts = timeseries(r)
    return s, r, ts, summary(r, ts)


def test_thrust_impulse_and_work_in_closed_form(coaxial_run):
    """Momentum: the system's linear momentum changes by exactly F T e3 (T = 0.1 s), the only
    external force; work: the ledger's input work is the integral of F e3 . v_chaser over the
    window (the trapezoid rule on the 2 ms samples: second order, so to 1e-4 here), and the
    ledger closes."""
    s, r, ts, summ = coaxial_run
    tc = r.impacts[0].t
    assert r.end_time > tc + 0.15
    masses = [getattr(s.bodies, n).mass for n in ts["body_names"]]
    P = np.einsum("b,nbx->nx", np.asarray(masses), ts["v_WB"])
    j = ts["body_names"].tolist().index("chaser")
    e3 = ts["R_WB"][0, j][:, 2]
    np.testing.assert_allclose(P[-1] - P[0], 300.0 * 0.1 * e3, atol=1e-9 * 7600 * 0.1)
    assert np.allclose(ts["R_WB"][:, j][:, :, 2], e3, atol=1e-12)
    F = ts["thrust_force_W"]
    on = (ts["t"] >= tc + 0.05) & (ts["t"] < tc + 0.15)
    assert np.allclose(np.linalg.norm(F[on], axis=1), 300.0) and not F[~on].any()
    power = np.einsum("nx,nx->n", F, ts["v_WB"][:, j])
    E = dict(zip(ts["energy_names"].tolist(), ts["energy"].T))
    t = ts["t"]
    inside = (t >= tc + 0.05 - 1e-6) & (t <= tc + 0.15 + 1e-6)
    tt, pp = t[inside], np.einsum("x,nx->n", 300.0 * e3, ts["v_WB"][inside, j])
    work = float(np.sum(0.5 * (pp[1:] + pp[:-1]) * np.diff(tt)))
    assert power.max() > 0
    assert E["input_work"][-1] == pytest.approx(work, rel=1e-4)
    assert summ["energy_ledger"]["input_work_J"] == E["input_work"][-1]
    assert summ["energy_ledger"]["closure_error_relative"] < 1e-7
    assert summ["momentum_drift_relative"]["linear"] < 1e-9


def test_thrust_switches_end_steps(coaxial_run):
    """A witness at each switch ends a step there (to the isolation window): the samples hold
    the switching times."""
    s, r, ts, summ = coaxial_run
    tc = r.impacts[0].t
    for switch in (tc + 0.05, tc + 0.15):
        assert np.min(np.abs(ts["t"] - switch)) < 1e-6
    assert summ["thrust"]["first_contact_time_s"] == tc
    assert summ["thrust"]["impulse_Ns"] == pytest.approx(30.0, rel=1e-9)
