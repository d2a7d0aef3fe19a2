"""The compiled LZB impact (`drake_dock.core.kernels.lzb` driven by
`drake_dock.core.lzb.compiled`) against the reference (scipy's DOP853, `solve_lzb`'s default),
a second implementation of the same equations with another integrator: at rtol 1e-12 the
post-impact velocities and impulses agree to 1e-9 relative and the phase events are the same
in the same order; the errors are raised alike. Against the continuous limit of the chains as
the reference is (`drake_dock.core.lzb.limit`)."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from drake_dock.core.lzb.limit import continuous_limit_chain
from drake_dock.core.lzb.solve import solve_lzb
from drake_dock.errors import NumericalError
from test_impact import CHAINS, _stool, chain, planar_rod_tip, sphere_on_plane, weighted_chain


def both(*args, **kw):
    """(reference, compiled, reference at 1.1 rtol) results of the same impact at rtol 1e-12."""
    kw.setdefault("rtol", 1e-12)
    return (solve_lzb(*args, **kw), solve_lzb(*args, compiled=True, **kw),
            solve_lzb(*args, **dict(kw, rtol=1.1 * kw["rtol"])))


def phases(res, upto=np.inf):
    """The phase sequence: per instant (events at the same total impulse, to 1e-12 of it) the
    set of (kind, couple), for the events at impulses below ``upto``. A set, since a couple
    released at once after its maximal compression (e = 0, nothing presses it) may touch again
    at the same instant by round-off and log the pair of events twice."""
    out, last = [], None
    for ev in res.events:
        if ev.impulse >= upto:
            break
        if last is None or abs(ev.impulse - last) > 1e-12 * max(abs(last), 1e-300):
            out.append(set())
        out[-1].add((ev.kind, int(ev.couple)))
        last = ev.impulse
    return out


def assert_same(ref, got, ref2):
    """Velocities and impulses to 1e-9 relative (of the largest), the same phase sequence.
    Where the reference's own sequence changes with a 10 % change of rtol (``ref2``: low
    restitution, whose re-impacts of vanishing amplitude end at the settling threshold in a
    number set by round-off), the sequences are compared up to the last 1e-7 of the impulse."""
    for a, b in ((ref.v_plus, got.v_plus), (ref.normal_impulse, got.normal_impulse),
                 (ref.tangential_impulse, got.tangential_impulse)):
        scale = max(np.abs(a).max(), np.abs(ref.normal_impulse).max())
        assert np.abs(a - b).max() <= 1e-9 * scale, (a, b)
    upto = np.inf
    if phases(ref2) != phases(ref):
        upto = (1 - 1e-7) * ref.normal_impulse.sum()
        assert phases(ref2, upto) == phases(ref, upto)
    assert phases(got, upto) == phases(ref, upto)
    np.testing.assert_allclose(got.compression_work, ref.compression_work, rtol=1e-8,
                               atol=1e-12 * ref.kinetic_energy_minus)


@pytest.mark.parametrize("law", ["paper", "mono", "bi"])
@pytest.mark.parametrize("k", range(len(CHAINS)))
def test_chains_as_the_reference(k, law):
    masses, K = CHAINS[k]
    M, Wn = weighted_chain(masses)
    v0 = np.zeros(len(masses))
    v0[0] = 1.0
    for e in (0.0, 0.1, 0.5, 1.0):
        assert_same(*both(M, Wn, v0, K, 1.5, e, law=law))


@pytest.mark.parametrize("law", ["paper", "mono", "bi"])
def test_chains_follow_the_continuous_limit(law):
    """As the reference does (tests/core/test_impact.py): to 1e-8 at rtol 1e-10."""
    for k in range(3):
        masses, K = CHAINS[k]
        M, Wn = weighted_chain(masses)
        v0 = np.zeros(len(masses))
        v0[0] = 1.0
        for e in (0.1, 0.5, 1.0):
            ref = continuous_limit_chain(masses, v0, K, 1.0, e, law, max_step=1e-2)
            r = solve_lzb(M, Wn, v0, K, 1.0, e, law=law, rtol=1e-10, compiled=True)
            assert np.abs(r.v_plus - ref).max() < 1e-8, (e, r.v_plus, ref)
            assert abs(masses @ r.v_plus - masses[0]) < 1e-12            # momentum


@pytest.mark.parametrize("case", ["sliding", "sticking", "reversal"])
def test_rod_as_the_reference(case):
    M, Wn, Wt = planar_rod_tip(math.radians(35.0))
    v0 = np.array({"sliding": [1.5, -1.0, 0.0], "sticking": [0.2, -1.0, 0.0],
                   "reversal": [0.1, -1.0, 0.0]}[case])
    mu = {"sliding": 0.2, "sticking": 0.9, "reversal": 0.3}[case]
    assert_same(*both(M, Wn, v0, 1e8, 1.5, 0.5, Wt=Wt, mu=mu))


def test_rod_two_ends_as_the_reference():
    M = np.diag([1.0, 1.0, 1.0 / 12])
    Wn = np.array([[0.0, 1.0, -0.5], [0.0, 1.0, 0.5]]).T
    for e in (0.0, 0.4, 1.0):
        assert_same(*both(M, Wn, np.array([0.2, -1.0, 0.8]), [1e7, 2.5e7], 1.5, e))


@pytest.mark.parametrize("e", [0.0, 0.5])
def test_sticking_as_the_reference(e):
    """Sticking couples (the stool's three feet, a sphere that starts to roll): their phases
    go through the reference's decisions and integration."""
    M, Wn, Wt = _stool()
    assert_same(*both(M, Wn, np.array([0, 0, 0, 0, 0, -0.14]), 1e9, 1.5, e, Wt=Wt, mu=0.3))
    M, Wn, Wt, *_ = sphere_on_plane()
    ref, got, ref2 = both(M, Wn, np.array([0.3, 0.0, -1.0, 0.0, 0.0, 0.0]), 1e9, 1.5, e,
                          Wt=Wt, mu=0.5)
    assert_same(ref, got, ref2)
    assert "stick" in [ev.kind for ev in got.events]


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
    return M, Wn, Wt, v, s


@pytest.mark.parametrize("seed", range(12))
def test_random_impacts_as_the_reference(seed):
    rng = np.random.default_rng(seed)
    M, Wn, Wt, v, s = random_impact(rng)
    K = rng.uniform(1e6, 1e8, size=s)
    e = rng.choice([0.0, 0.2, 0.7, 1.0], size=s)
    mu = rng.uniform(0.0, 0.8, size=s) if seed % 2 else 0.0
    law = ("paper", "mono", "bi")[seed % 3]
    assert_same(*both(M, Wn, v, K, rng.choice([1.0, 1.5]), e, Wt=Wt if seed % 2 else None,
                      mu=mu, law=law))


def test_same_inputs_same_bits():
    M, Wn, Wt, v, s = random_impact(np.random.default_rng(3))
    a = solve_lzb(M, Wn, v, 1e7, 1.5, 0.5, Wt=Wt, mu=0.3, compiled=True)
    b = solve_lzb(M, Wn, v, 1e7, 1.5, 0.5, Wt=Wt, mu=0.3, compiled=True)
    assert a.v_plus.tobytes() == b.v_plus.tobytes()
    assert a.impulse_history.tobytes() == b.impulse_history.tobytes()


@pytest.mark.parametrize("compiled", [False, True])
def test_step_budget_raises_alike(compiled):
    M, Wn = chain(5)
    with pytest.raises(NumericalError, match="did not end within 20 steps"):
        solve_lzb(M, Wn, [1.0, 0, 0, 0, 0], 1e7, 1.5, 0.3, max_steps=20, compiled=compiled)


REST_IMPACT = Path(__file__).with_name("lzb_rest_impact.json")


@pytest.mark.parametrize("compiled", [False, True], ids=["reference", "compiled"])
def test_a_couple_sliding_to_rest_while_turning_sticks(compiled):
    """An impact of the docking scene (conditions sweep, random 7): couple 0 slides to rest
    while its sliding direction turns by 90 deg. Its friction event (u_t along the last slip
    direction down to the speed of rest) fires and it sticks; the impact ends within the
    default step budget. Checked against the kinematics of v+ (the stuck couple's tangential
    velocity is within the speed of rest) and between the two integrators."""
    d = json.loads(REST_IMPACT.read_text())
    M = np.zeros((d["n"], d["n"]))
    for i, j, m in d["M_nonzeros"]:
        M[i, j] = m
    Wn, Wt, v = np.array(d["Wn"]), np.array(d["Wt"]), np.array(d["v_minus"])
    args = (M, Wn, v, d["stiffness"], d["eta"], d["restitution"])
    kw = dict(Wt=Wt, mu=d["mu"], rtol=d["rtol"])
    r = solve_lzb(*args, **kw, compiled=compiled)
    assert [e.kind for e in r.events] == ["max_compression", "stick", "end"]
    assert [e.couple for e in r.events][:2] == [0, 0]
    v_s = np.abs(Wn.T @ v).max()
    assert np.linalg.norm(Wt[:, :2].T @ r.v_plus) <= 2 * d["rtol"] * v_s
    if compiled:
        ref = solve_lzb(*args, **kw)
        assert np.abs(r.v_plus - ref.v_plus).max() <= 1e-7 * np.abs(ref.v_plus).max()
