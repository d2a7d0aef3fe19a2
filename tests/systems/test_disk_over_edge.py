"""The hand-over in the contact system (`drake_dock.systems.transitions`): a disk sliding
frictionless off a plane's end onto the edge there (`disk_on_incline` with ``edge``) pivots
over the edge like a particle on a cylinder of radius r and leaves it at the closed-form angle
cos(theta_c) = (2 + v0^2 / (g r)) / 3; the run between and after is checked against that closed
form and energy conservation."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from drake_dock.core.hybrid import Mode
from drake_dock.studies.small_scenes import G, disk_on_incline
from test_contact_system import couple, energy, start

V0, END = 1.0, 0.5


@pytest.fixture(scope="module")
def run():
    sc = disk_on_incline(0.0, mu=0.0, plane_end=END, edge=True)
    r = sc.params["radius"]
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r])), (np.zeros(3), np.array([V0, 0, 0]))))
    return sc, sim, ctx, r


def test_disk_hands_over_to_the_edge_and_leaves_it_at_the_closed_form_angle(run):
    """Plane until t_h = END / v0, then the edge pair in contact (the plane pair far); the
    contact force passes through the centre, so the disk does not turn and its centre moves on
    the circle of radius r about the edge (theta' ^ 2 = (v0 / r)^2 + 2 g (1 - cos theta) / r)
    until lambda_n = 0 at theta_c, then flies: at t_c + 0.05 s its position and velocity equal
    the closed form to 1e-6 (its spin stays 0 to 1e-7 rad/s), and the energy is conserved to 1e-8 of the kinetic energy."""
    sc, sim, ctx, r = run
    t_h = END / V0
    sim.AdvanceTo(t_h - 1e-3)
    assert couple(sc.system, ctx, "rim_plane")["status"] == Mode.SLIDING
    assert couple(sc.system, ctx, "rim_edge")["status"] == Mode.FAR
    e0 = energy(sc.system, ctx)
    sim.AdvanceTo(t_h + 1e-3)
    assert couple(sc.system, ctx, "rim_edge")["status"] == Mode.SLIDING
    assert couple(sc.system, ctx, "rim_plane")["status"] == Mode.FAR
    assert abs(couple(sc.system, ctx, "rim_edge")["gap"]) < 1e-8
    c_th = (2.0 + V0 ** 2 / (G * r)) / 3.0
    th_c = math.acos(c_th)
    rate = lambda th: math.sqrt((V0 / r) ** 2 + 2 * G * (1 - math.cos(th)) / r)   # theta'
    t_c = t_h + quad(lambda th: 1.0 / rate(th), 0.0, th_c, epsabs=1e-14, epsrel=1e-13)[0]
    sim.AdvanceTo(t_c - 1e-3)
    assert couple(sc.system, ctx, "rim_edge")["status"] == Mode.SLIDING
    sim.AdvanceTo(t_c + 1e-3)
    assert couple(sc.system, ctx, "rim_edge")["status"] == Mode.TRACKED
    T = t_c + 0.05
    sim.AdvanceTo(T)
    x = ctx.get_continuous_state_vector().CopyToVector()
    q, v = x[:sc.system.nq], x[sc.system.nq:sc.system.nq + sc.system.nv]
    speed = math.sqrt(G * r * c_th)
    vx, vz = speed * c_th, -speed * math.sin(th_c) - G * (T - t_c)
    px = END + r * math.sin(th_c) + vx * (T - t_c)
    pz = r * c_th - speed * math.sin(th_c) * (T - t_c) - 0.5 * G * (T - t_c) ** 2
    np.testing.assert_allclose(q[4:7], [px, 0.0, pz], atol=1e-6)
    np.testing.assert_allclose(v[3:6], [vx, 0.0, vz], atol=1e-6)
    np.testing.assert_allclose(v[:3], 0.0, atol=1e-7)
    e1 = energy(sc.system, ctx)
    ke = 0.5 * sc.params["mass"] * V0 ** 2
    assert abs((e1[0] + e1[1]) - (e0[0] + e0[1])) < 1e-8 * ke
    assert sc.system.get_modes(ctx).impacts == []



def _through_the_handover(edge_first):
    """The frictionless disk of `run` with the pairs in the given order, past the hand-over
    from the plane to the edge: its state, the couples (by name) and the seeks per pair."""
    sc = disk_on_incline(0.0, mu=0.0, plane_end=END, edge=True, edge_first=edge_first)
    r = sc.params["radius"]
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r])), (np.zeros(3), np.array([V0, 0, 0]))))
    sim.AdvanceTo(END / V0 + 0.02)
    x = ctx.get_continuous_state_vector().CopyToVector()
    couples = {n: couple(sc.system, ctx, n) for n in ("rim_plane", "rim_edge")}
    return (x[:sc.system.nq + sc.system.nv], couples,
            sc.system.timing.shares(1.0)["seeks_per_pair"])


def _handover_event(edge_first):
    """One event (`Transitions.resolve`) of the disk of `run`, pairs in the given order, moved
    3 mm on from 2 mm before the plane's end, so that the plane pair's couple has passed the
    edge, with the edge pair (far) due to be sought too (its clearance set to 0): per pair its
    mode, sigma, distance and couple, the body state after and the seeks per pair."""
    sc = disk_on_incline(0.0, mu=0.0, plane_end=END, edge=True, edge_first=edge_first)
    system, r = sc.system, sc.params["radius"]
    sim, root, ctx = start(system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r])), (np.zeros(3), np.array([V0, 0, 0]))))
    sim.AdvanceTo(END / V0 - 2e-3)
    x = ctx.get_continuous_state_vector().CopyToVector()
    x[4] += 3e-3                                    # the disk's centre (q = [quaternion, p])
    ctx.get_mutable_continuous_state_vector().SetFromVector(x)
    modes = system.get_modes(ctx).working_copy()
    names = [p.name for p in system.pairs]
    modes.pairs[names.index("rim_edge")].clearance = 0.0
    system.timing.reset()
    x_new, after = system.transitions.resolve(ctx.get_time(), x, modes, system.input_force(ctx),
                                              lambda: system._cache.Eval(ctx))
    u = x_new[system.nq + system.nv:]
    pairs = {n: (st.mode, st.sigma, st.distance, u[system.couple_slice(k)])
             for k, (n, st) in enumerate(zip(names, after.pairs))}
    return pairs, x_new[:system.nq + system.nv], dict(system.timing.seeks)


def test_an_event_hands_over_alike_whichever_pair_comes_first():
    """At one event the plane pair's couple passes the edge and goes to the edge pair, declared
    after it and before it (``edge_first``): the target is not sought in either order, and the
    modes, sigmas, distances, couples and body state are the same."""
    after, x_after, seeks_after = _handover_event(edge_first=False)
    before, x_before, seeks_before = _handover_event(edge_first=True)
    assert after["rim_edge"][0] == Mode.SLIDING and after["rim_plane"][0] == Mode.FAR
    assert seeks_before == seeks_after and "rim_edge" not in seeks_after
    for name in after:
        assert before[name][:2] == after[name][:2], name
        np.testing.assert_allclose(before[name][2], after[name][2], rtol=0, atol=1e-12)
        np.testing.assert_allclose(before[name][3], after[name][3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(x_before, x_after, rtol=0, atol=1e-12)


def test_the_handover_does_not_depend_on_the_pairs_order():
    """The plane pair hands its couple to the edge pair declared after it (the `run` order) and
    before it (``edge_first``): the same modes, couples, body state and seeks per pair over the
    run (the edge pair far and carried by the plane pair before, whichever pair is sought
    first at the initial event)."""
    x_after, c_after, seeks_after = _through_the_handover(edge_first=False)
    x_before, c_before, seeks_before = _through_the_handover(edge_first=True)
    assert c_after["rim_edge"]["status"] == Mode.SLIDING
    assert c_after["rim_plane"]["status"] == Mode.FAR
    assert seeks_before == seeks_after
    for name in c_after:
        for k in ("status", "gap", "u", "lambda_n"):
            np.testing.assert_allclose(c_before[name][k], c_after[name][k], rtol=0,
                                       atol=1e-12, err_msg=f"{name} {k}")
    np.testing.assert_allclose(x_before, x_after, rtol=0, atol=1e-12)


def test_the_handovers_applied_do_not_depend_on_the_pairs_labels():
    """`applied` on random hand-overs due among 6 pairs (single ones, chains, exchanges, two
    couples due to one pair): relabelling the pairs relabels the hand-overs made, and each made
    one is a pair taking the only couple due to it while not handing its own on."""
    from drake_dock.systems.handover_links import applied
    rng = np.random.default_rng(5)
    made_some = waited = 0
    for _ in range(200):
        n = 6
        due = {int(i): (int(j), None) for i, j in zip(rng.permutation(n)[:rng.integers(0, 5)],
                                                      rng.integers(0, n, size=5)) if i != j}
        made = applied(due)
        made_some += bool(made)
        waited += len(made) < len(due)
        for j, i in made.items():
            assert due[i][0] == j and j not in due
            assert [k for k, (t, _) in due.items() if t == j] == [i]
        perm = rng.permutation(n)
        relabelled = {int(perm[i]): (int(perm[j]), None) for i, (j, _) in due.items()}
        assert applied(relabelled) == {int(perm[j]): int(perm[i]) for j, i in made.items()}
    assert made_some > 50 and waited > 50
