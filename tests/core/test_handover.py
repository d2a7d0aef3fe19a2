"""The hand-over between an edge pair and a surface pair (`drake_dock.core.handover`) in closed
form: a ring's circle rolling over the straight edge of a plane face and back (tests/
edge_scenes.py, `ring_over_plate_edge`), and over an APDS petal's tip arc from its guide surface
and back (`ring_over_petal_tip`). Each couple is tracked by Eq. (47) until its guard; the reset
gives the other pair's couple, which equals the closed form to 1e-8, continues the same contact
point with gap 0 and the same normal, and is tracked on to the next hand-over."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from drake_dock.core import handover
from drake_dock.core.couple import evaluate_couple
from edge_scenes import ring_over_petal_tip, ring_over_plate_edge

SCENES = {"plate_edge": ring_over_plate_edge, "petal_tip": ring_over_petal_tip}


def _wrap(du, per):
    return np.array([(d + math.pi) % (2 * math.pi) - math.pi if p else d
                     for d, p in zip(du, per)])


def _evaluate(scene, t, u, sigma, project=True):
    X1, V1, X2, V2 = scene.poses(t)
    return evaluate_couple(scene.kind, scene.patch1, X1, V1, scene.patch2, X2, V2, u, sigma,
                           project=project)


def _track(scene, t_span, u0, event):
    """u* by Eq. (47) from u0 until ``event`` (decreasing through zero)."""
    event.terminal, event.direction = True, -1
    sol = solve_ivp(lambda t, u: _evaluate(scene, t, u, 1.0, project=False).udot, t_span, u0,
                    method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True, events=event)
    assert sol.success
    return sol


def _check_tracked(scene, sol, sigma, t0, t1):
    """The tracked couple equals the closed form at 9 times in (t0, t1), with gap 0."""
    per = list(scene.patch1.periodic) + list(scene.patch2.periodic)
    for t in np.linspace(t0, t1, 11)[1:-1]:
        u, gap, p1, p2, n = scene.exact(t)
        np.testing.assert_allclose(_wrap(sol.sol(t) - u, per), 0.0, atol=1e-8)
        ev = _evaluate(scene, t, sol.sol(t), sigma)
        assert gap == 0.0 and abs(ev.gap) < 1e-10
        np.testing.assert_allclose(ev.n, n, atol=1e-10)
        np.testing.assert_allclose(ev.p1, p1, atol=1e-10)


@pytest.mark.parametrize("name", SCENES)
def test_handover_surface_edge_surface(name):
    """The surface couple reaches the edge at the closed-form time t_on (its guard, the domain
    end); reset to the edge pair (`handover.to_edge`, sigma by `carried_sigma`): the same
    points, normal and gap 0. The edge couple's guard n . b is positive while the ring lies
    beyond the edge and reaches zero at the closed-form t_off, where the reset back to the
    surface (`handover.to_surface`) again continues the contact; tracked to the end."""
    surf, edge_scene, edge, (t_on, t_off) = SCENES[name]()
    S, E = surf.patch2, edge_scene.patch2
    k = 1 + edge.fixed

    def at_edge(t, u):
        return (S.upper[edge.fixed] - u[k]) if edge.upper else (u[k] - S.lower[edge.fixed])

    sol = _track(surf, (0.0, 1.0), surf.exact(0.0)[0], at_edge)
    assert sol.t_events[0][0] == pytest.approx(t_on, abs=1e-8)
    _check_tracked(surf, sol, 1.0, 0.0, t_on)
    u_s = sol.y_events[0][0]
    before = _evaluate(surf, t_on, u_s, 1.0, project=False)
    u_e = np.array(handover.to_edge(edge, 1, u_s))
    np.testing.assert_allclose(_wrap(u_e - edge_scene.exact(t_on)[0], [True, False]), 0.0,
                               atol=1e-8)
    sigma = handover.carried_sigma(before.n, _evaluate(edge_scene, t_on, u_e, 1.0,
                                                       project=False).n)
    after = _evaluate(edge_scene, t_on, u_e, sigma, project=False)
    for f in ("p1", "p2", "n"):
        np.testing.assert_allclose(getattr(after, f), getattr(before, f), atol=1e-8)
    assert abs(after.gap) < 1e-8 and abs(before.gap) < 1e-8

    def guard(t, u):
        ev = _evaluate(edge_scene, t, u, sigma, project=False)
        X2 = edge_scene.poses(t)[2]
        a = handover.surface_params(edge, S.lower, S.upper, u[1])
        return handover.edge_guard(edge, ev.n, [X2[0] @ np.asarray(v) for v in S.jet(a)[1]])

    assert guard(t_on + 1e-3, edge_scene.exact(t_on + 1e-3)[0]) > 0.0
    sol = _track(edge_scene, (t_on, 1.0), u_e, guard)
    assert sol.t_events[0][0] == pytest.approx(t_off, abs=1e-8)
    _check_tracked(edge_scene, sol, sigma, t_on, t_off)
    u_e = sol.y_events[0][0]
    before = _evaluate(edge_scene, t_off, u_e, sigma, project=False)
    u_s = np.array(handover.to_surface(edge, 1, u_e, S.lower, S.upper))
    np.testing.assert_allclose(_wrap(u_s - surf.exact(t_off)[0], [True, False, False]), 0.0,
                               atol=1e-8)
    assert handover.carried_sigma(before.n, _evaluate(surf, t_off, u_s, 1.0,
                                                      project=False).n) == 1.0
    after = _evaluate(surf, t_off, u_s, 1.0, project=False)
    for f in ("p1", "p2", "n"):
        np.testing.assert_allclose(getattr(after, f), getattr(before, f), atol=1e-8)
    sol = _track(surf, (t_off, 1.0), u_s, at_edge)
    assert sol.t_events[0].size == 0
    _check_tracked(surf, sol, 1.0, t_off, 1.0)


def test_edge_maps_invert_each_other():
    """`to_edge` after `to_surface` is the identity on the edge pair's couple, and the surface
    point of `surface_params` is the edge's point (both scenes' edges)."""
    for make in SCENES.values():
        surf, edge_scene, edge, _ = make()
        S, E = surf.patch2, edge_scene.patch2
        for e in np.linspace(E.lower[0], E.upper[0], 7):
            u = [0.3, e]
            back = handover.to_edge(edge, 1, handover.to_surface(edge, 1, u, S.lower, S.upper))
            assert back == pytest.approx(u, abs=1e-14)
            a = handover.surface_params(edge, S.lower, S.upper, e)
            np.testing.assert_allclose(S.position(np.array(a)), E.position(np.array([e])),
                                       atol=1e-14)
