"""The LZB impact (`solve_lzb`, the compiled kernel `drake_dock.core.kernels.lzb`) on general
impacts, checked against laws its integration does not impose: the energy ledger (the kinetic
energy lost is the compression work not returned plus the friction loss, each integrated on
its own), Coulomb's cone for the impulses, no couple approaching at the end, and convergence in
rtol; sticking and locked couples on the stool and a sphere; its errors and determinism. The
closed forms and the continuous limit are in tests/core/test_impact.py."""
import json
from pathlib import Path

import numpy as np
import pytest

from drake_dock.core.kernels.lzb_records import KINDS
from drake_dock.core.lzb.solve import solve_lzb
from drake_dock.errors import NumericalError
from test_impact import _stool, chain, sphere_on_plane


def check_laws(res, Wn, Wt, v, mu_s, rtol):
    """The energy ledger to 1e-7 of the kinetic energy before, the tangential impulses in the
    static cones, every couple separating or at rest at the end (to 10 rtol of the largest
    relative speed before, v the velocity before)."""
    ke = res.kinetic_energy_minus
    ledger = (res.compression_work.sum() - res.restitution_work.sum()
              + res.friction_loss.sum())
    assert abs((res.kinetic_energy_minus - res.kinetic_energy_plus) - ledger) <= 1e-7 * ke
    assert np.all(res.compression_work >= -1e-12 * ke)
    assert np.all(res.friction_loss >= -1e-12 * ke)
    if Wt is not None:
        pt = np.linalg.norm(res.tangential_impulse, axis=1)
        assert np.all(pt <= np.asarray(mu_s) * res.normal_impulse * (1 + 1e-9)
                      + 1e-12 * res.normal_impulse.max())
    assert np.all(res.normal_impulse >= 0.0)
    W = Wn if Wt is None else np.column_stack([Wn, Wt])
    assert (Wn.T @ res.v_plus).min() >= -10 * rtol * np.abs(W.T @ v).max()


def random_impact(rng):
    """A random multibody impact: n = 6, 1-4 couples approaching or at rest, friction."""
    n, s = 6, int(rng.integers(1, 5))
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    Wn, Wt = rng.normal(size=(n, s)), rng.normal(size=(n, 2 * s))
    v = rng.normal(size=n)
    # Make every couple approach (u_n < 0) or rest.
    target = -rng.uniform(0.0, 1.0, size=s)
    v = v + np.linalg.lstsq(Wn.T, target - Wn.T @ v, rcond=None)[0]
    # Some couples at rest tangentially, so that they stick (as many as the n velocities
    # can hold with the normal ones).
    if rng.uniform() < 0.5:
        rest = rng.uniform(size=s) < 0.5
        rest[np.cumsum(rest) > (n - s) // 2] = False
        Wt_rest = Wt[:, np.repeat(rest, 2)]
        if Wt_rest.size:
            A = np.column_stack([Wn, Wt_rest])
            goal = np.concatenate([Wn.T @ v, np.zeros(Wt_rest.shape[1])])
            v = v + np.linalg.lstsq(A.T, goal - A.T @ v, rcond=None)[0]
    return M, Wn, Wt, v, s


SEEDS = range(64)


def random_case(seed):
    """(args, kwargs) of `solve_lzb` for a random impact (`random_impact`): restitutions with
    e = 0 among them, friction on every other seed (mu_s above mu on every fourth), the
    three laws in turn."""
    rng = np.random.default_rng(seed)
    M, Wn, Wt, v, s = random_impact(rng)
    K = rng.uniform(1e6, 1e8, size=s)
    e = rng.choice([0.0, 0.2, 0.7, 1.0], size=s)
    fric = seed % 2 == 1
    mu = rng.uniform(0.1, 0.8, size=s) if fric else 0.0
    mu_s = mu * rng.uniform(1.0, 1.5, size=s) if seed % 4 == 3 else None
    law = ("paper", "mono", "bi")[seed % 3]
    eta = rng.choice([1.0, 1.5])
    return (M, Wn, v, K, eta, e), dict(Wt=Wt if fric else None, mu=mu, mu_s=mu_s, law=law)


@pytest.mark.parametrize("seed", SEEDS)
def test_random_impacts_keep_the_laws_and_converge(seed):
    """Random impacts (`random_case`): `check_laws` at rtol 1e-10 and 1e-12, and v+ within
    1e-6 of its value at rtol 1e-12 (relative to the largest velocity)."""
    args, kw = random_case(seed)
    M, Wn, v = args[:3]
    r = solve_lzb(*args, rtol=1e-10, **kw)
    fine = solve_lzb(*args, rtol=1e-12, **kw)
    mu_s = kw["mu"] if kw["mu_s"] is None else kw["mu_s"]
    check_laws(r, Wn, kw["Wt"], v, mu_s, 1e-10)
    check_laws(fine, Wn, kw["Wt"], v, mu_s, 1e-12)
    scale = np.abs(v).max() + np.abs(fine.v_plus).max()
    assert np.abs(r.v_plus - fine.v_plus).max() <= 1e-6 * scale


def test_the_random_impacts_reach_every_phase():
    """The random impacts above go through every kind of phase event (so that those tests
    check the sticking and locked phases too), run here again."""
    seen = set()
    for seed in SEEDS:
        args, kw = random_case(seed)
        seen.update(ev.kind for ev in solve_lzb(*args, rtol=1e-10, **kw).events)
    assert seen == set(KINDS), set(KINDS) - seen


@pytest.mark.parametrize("e", [0.0, 0.5])
def test_sticking_stool_and_sphere(e):
    """The stool's three feet landing at rest tangentially stick (no tangential velocity
    after, the laws kept); a sphere hitting a plane with a small tangential speed and large
    friction sticks during compression and leaves rolling (zero slip at the contact)."""
    M, Wn, Wt = _stool()
    v = np.array([0, 0, 0, 0, 0, -0.14])
    r = solve_lzb(M, Wn, v, 1e9, 1.5, e, Wt=Wt, mu=0.3, rtol=1e-10)
    check_laws(r, Wn, Wt, v, 0.3, 1e-10)
    assert np.abs(Wt.T @ r.v_plus).max() <= 1e-8 * 0.14
    M, Wn, Wt, *_ = sphere_on_plane()
    v = np.array([0.3, 0.0, -1.0, 0.0, 0.0, 0.0])
    r = solve_lzb(M, Wn, v, 1e9, 1.5, e, Wt=Wt, mu=0.5, rtol=1e-10)
    check_laws(r, Wn, Wt, v, 0.5, 1e-10)
    assert "stick" in [ev.kind for ev in r.events]
    assert np.abs(Wt.T @ r.v_plus).max() <= 1e-8


def test_same_inputs_same_bits():
    M, Wn, Wt, v, s = random_impact(np.random.default_rng(3))
    a = solve_lzb(M, Wn, v, 1e7, 1.5, 0.5, Wt=Wt, mu=0.3)
    b = solve_lzb(M, Wn, v, 1e7, 1.5, 0.5, Wt=Wt, mu=0.3)
    assert a.v_plus.tobytes() == b.v_plus.tobytes()
    assert a.impulse_history.tobytes() == b.impulse_history.tobytes()


def test_step_budget_raises():
    M, Wn = chain(5)
    with pytest.raises(NumericalError, match="did not end within 20 steps"):
        solve_lzb(M, Wn, [1.0, 0, 0, 0, 0], 1e7, 1.5, 0.3, max_steps=20)


def _impact_of(path):
    """(the record, M, Wn, Wt, v_minus) of an impact recorded as JSON."""
    d = json.loads(path.read_text())
    M = np.zeros((d["n"], d["n"]))
    for i, j, m in d["M_nonzeros"]:
        M[i, j] = m
    return d, M, np.array(d["Wn"]), np.array(d["Wt"]), np.array(d["v_minus"])


REST_IMPACT = Path(__file__).with_name("lzb_rest_impact.json")


def test_a_couple_sliding_to_rest_while_turning_sticks():
    """An impact of the docking scene (conditions sweep, random 7): couple 0 slides to rest
    while its sliding direction turns by 90 deg. Its friction event (u_t along the last slip
    direction down to the speed of rest) fires and it sticks; the impact ends within the
    default step budget. Checked against the kinematics of v+ (the stuck couple's tangential
    velocity is within the speed of rest) and the laws."""
    d, M, Wn, Wt, v = _impact_of(REST_IMPACT)
    r = solve_lzb(M, Wn, v, d["stiffness"], d["eta"], d["restitution"], Wt=Wt, mu=d["mu"],
                  rtol=d["rtol"])
    assert [e.kind for e in r.events] == ["max_compression", "stick", "end"]
    assert [e.couple for e in r.events][:2] == [0, 0]
    v_s = np.abs(Wn.T @ v).max()
    assert np.linalg.norm(Wt[:, :2].T @ r.v_plus) <= 2 * d["rtol"] * v_s
    check_laws(r, Wn, Wt, v, d["mu"], d["rtol"])


def test_two_couples_starting_to_slide_together_end():
    """An impact of the docking scene (`lzb_start_sliding_together.json`, the two tips on the
    lips of tests/docking/test_box_failures.py): two couples start to slide from rest at once,
    one just outside its static cone, whose sliding speed grows slowly. Started along minus
    their sticking forces, or following the direction of a u_t of round-off size, the
    direction of u_t turned faster than any step could follow and the impact did not end
    within the step budget. It ends, keeps the laws and converges in rtol."""
    d, M, Wn, Wt, v = _impact_of(Path(__file__).with_name("lzb_start_sliding_together.json"))
    args = (M, Wn, v, d["stiffness"], d["eta"], d["restitution"])
    r = solve_lzb(*args, Wt=Wt, mu=d["mu"], rtol=d["rtol"])
    kinds = [ev.kind for ev in r.events]
    assert kinds[:3] == ["stick", "slip_reversal", "slip"]
    check_laws(r, Wn, Wt, v, d["mu"], d["rtol"])
    fine = solve_lzb(*args, Wt=Wt, mu=d["mu"], rtol=1e-11)
    assert np.abs(r.v_plus - fine.v_plus).max() <= 1e-5 * np.abs(fine.v_plus).max()


@pytest.mark.parametrize("seed", range(40))
def test_a_start_of_sliding_goes_along_its_acceleration(seed):
    """`lzb_friction._start_dir`: for a random effective tangential Delassus block G~ (SPD),
    acceleration c and m = mu lambda_n with the sticking force -G~^-1 c outside the cone m,
    the direction s makes c - m G~ s = alpha s with alpha > 0 (to 1e-9 of |c|); inside it,
    s is minus the sticking force's direction."""
    from drake_dock.core.kernels.lzb_friction import _start_dir
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(2, 2))
    G = A @ A.T + rng.uniform(0.01, 1.0) * np.eye(2)
    c = rng.normal(size=2)
    lt = -np.linalg.solve(G, c)
    m = np.linalg.norm(lt) * rng.uniform(0.05, 1.5)
    s = _start_dir(c[0], c[1], G[0, 0], G[0, 1], G[1, 1], m)
    assert abs(np.linalg.norm(s) - 1.0) <= 1e-12
    a = c - m * G @ s
    if np.linalg.norm(lt) > m:
        alpha = a @ s
        assert alpha > 0.0
        assert np.linalg.norm(a - alpha * s) <= 1e-9 * np.linalg.norm(c)
    else:
        np.testing.assert_allclose(s, -lt / np.linalg.norm(lt), atol=1e-12)


@pytest.mark.parametrize("seed", range(60))
def test_stick_slip_decisions_are_consistent(seed):
    """`lzb_friction.select_friction_modes` on random loaded couples at rest (2-4 couples, a
    random Delassus matrix, mu_s >= mu): every couple left stuck has its sticking force rate
    in its static cone, and every couple that starts to slide has its tangential acceleration
    (`lzb_forces.rhs`) along +s, its slip direction: u_t grows along s."""
    from drake_dock.core.kernels import lzb_forces, lzb_friction, lzb_records as LR
    rng = np.random.default_rng(seed)
    s = int(rng.integers(2, 5))
    n = 3 * s + 2
    A = rng.normal(size=(n, n))
    W = rng.normal(size=(n, 3 * s))
    G = W.T @ np.linalg.solve(A @ A.T + n * np.eye(n), W)
    mu = rng.uniform(0.05, 0.6, size=s)
    mu_s = mu * rng.uniform(1.0, 1.3, size=s) if seed % 2 else mu.copy()
    imp = LR.ImpactConstants(s, 3 * s, G, np.ones(s), np.full(s, 1.5), np.full(s, 0.5), mu,
                             mu_s, True, 0, 1e-10, 1e-10, 1e-12, 1000, 1.0)
    ph = LR.new_phases(s)
    y = np.zeros(10 * s)
    y[:s] = rng.uniform(0.1, 1.0, size=s)            # loaded
    y[s:2 * s] = -rng.uniform(0.0, 1.0, size=s)      # approaching, at rest tangentially
    lam = np.empty(3 * s)
    log = LR.EventLog(np.empty(16), np.empty(16, np.int64), np.empty(16, np.int64),
                      np.int64(0))
    lzb_friction.select_friction_modes(y, np.ones(s, np.bool_), 0.0, imp, ph, log, lam,
                             np.zeros(s, np.bool_))
    out = np.empty_like(y)
    lzb_forces.rhs(y, out, imp, ph, lam)
    for j in range(s):
        lt = lam[s + 2 * j: s + 2 * j + 2]
        if ph.stuck[j]:
            assert np.linalg.norm(lt) <= mu_s[j] * lam[j] * (1 + 1e-9)
        else:
            a, d = out[2 * s + 2 * j: 2 * s + 2 * j + 2], ph.slip_dir[j]
            assert a @ d > 0.0
            assert np.linalg.norm(a - (a @ d) * d) <= 1e-8 * np.linalg.norm(a)
