"""Mode selection of the contact set on rigid bodies resting on the plane z = 0: a rod whose
sliding tip unloads and lifts off with the gap drift of a docking run, Painleve's rod, and random
sliding contacts against a brute-force enumeration of the modes, by the compiled solve and mode
selection (drake_dock.core.kernels.constraints). Runs without Drake."""
import itertools
import math

import numpy as np
import pytest

from drake_dock.core.constraints import (DETACH, SLIDE, STICK, TIE_RTOL, ContactRow,
                                         ContactSolution, stabilised_gddot)
from drake_dock.core.kernels import constraints as compiled
from drake_dock.errors import PainleveError

G = 9.81
OMEGA = 20.0          # the contact system's Baumgarte omega (rad/s)


@pytest.fixture
def select_contact_modes():
    """The mode selection (`drake_dock.core.kernels.constraints.select_contact_modes`)."""
    return compiled.select_contact_modes


def body_mass(m, inertia):
    """M of a rigid body in v = (v_com, w), world frame."""
    return np.diag([m, m, m, *inertia])


def plane_row(name, r, *, gap, vn, vt, mu, bn=0.0):
    """The row of a body point at r from the mass centre against the plane z = 0 (n = z,
    t = x, y): W = [e; r x e] (Eq. 11), no velocity-product terms but ``bn``."""
    e = np.eye(3)
    W = [np.concatenate([e[k], np.cross(r, e[k])]) for k in (2, 0, 1)]
    return ContactRow(name, W[0], np.column_stack(W[1:]), bn, np.zeros(2), gap, vn,
                      np.asarray(vt, float), mu, mu)


def rod(theta, l, mass, mu, **row):
    """A uniform rod of half-length l at theta above the horizontal, its lower tip on the plane
    (I = m l^2 / 3 about its transverse axes): (M, the tip's row)."""
    r = -l * np.array([math.cos(theta), 0.0, math.sin(theta)])
    I = mass * l * l / 3.0
    return body_mass(mass, [I, I, 1e-3 * I]), plane_row("tip_plane", r, mu=mu, **row)


def tip_A(theta, l, mass, mu, s):
    """The tip's normal inverse mass while sliding along s x (planar form, I = m l^2 / 3):
    a_z = A lambda_n + b with friction -mu s lambda_n along x."""
    c, sn = math.cos(theta), math.sin(theta)
    return (1.0 + 3.0 * c * (c + mu * s * sn)) / mass


def choices_by_kkt(M, a0, rows, omega, v_slip=1e-6):
    """Every choice of modes without a start of sliding (stick or detach for a couple at rest,
    slide against its velocity or detach for a moving one), each solved from the Newton-Euler
    equations and the constraint rows together (a KKT system in M, not the mode selection's
    Schur complement): a `ContactSolution` per choice whose system is regular."""
    nv, out = len(a0), []
    moving = [np.linalg.norm(r.vt) > v_slip for r in rows]
    for modes in itertools.product(*[(SLIDE, DETACH) if mv else (STICK, DETACH)
                                     for mv in moving]):
        dirs = [r.vt / np.linalg.norm(r.vt) if m == SLIDE else None
                for r, m in zip(rows, modes)]
        C, D, rhs = [], [], []
        for r, m, s in zip(rows, modes, dirs):
            stab = -(r.bn + 2 * omega * r.vn + omega ** 2 * r.gap)
            if m == SLIDE:
                C.append(r.Wn - r.mu * r.Wt @ s)
                D.append(r.Wn)
                rhs.append(stab)
            elif m == STICK:
                C += [r.Wn, r.Wt[:, 0], r.Wt[:, 1]]
                D += [r.Wn, r.Wt[:, 0], r.Wt[:, 1]]
                rhs += [stab, -r.bt[0], -r.bt[1]]
        C, D = np.array(C).reshape(-1, nv), np.array(D).reshape(-1, nv)
        k = len(rhs)
        K = np.block([[M, -C.T], [D, np.zeros((k, k))]])
        try:
            x = np.linalg.solve(K, np.concatenate([M @ a0, rhs]))
        except np.linalg.LinAlgError:
            continue
        vdot, lam = x[:nv], iter(x[nv:])
        lam_n, lam_t = np.zeros(len(rows)), np.zeros((len(rows), 2))
        for i, (r, m, s) in enumerate(zip(rows, modes, dirs)):
            if m == SLIDE:
                lam_n[i] = next(lam)
                lam_t[i] = -r.mu * lam_n[i] * s
            elif m == STICK:
                lam_n[i], lam_t[i] = next(lam), [next(lam), next(lam)]
        out.append(ContactSolution(modes, dirs, vdot, lam_n, lam_t, C.T @ x[nv:], list(rows)))
    return out


def modes_by_enumeration(M, a0, rows, omega, rtol=1e-9):
    """Every consistent choice of {slide, detach} for couples that all slide (`choices_by_kkt`):
    [(modes, vdot, lam_n)]."""
    out = []
    for sol in choices_by_kkt(M, a0, rows, omega):
        modes, vdot, lam_n = sol.modes, sol.vdot, sol.lam_n
        stab = np.array([r.Wn @ vdot + r.bn + 2 * omega * r.vn + omega ** 2 * r.gap
                         for r in rows])
        f_tol = rtol * (1.0 + np.abs(lam_n).max())
        a_tol = rtol * (1.0 + np.abs(a0).max())
        if all(lam_n[i] >= -f_tol if m == SLIDE else stab[i] >= -a_tol
               for i, m in enumerate(modes)):
            out.append((modes, vdot, lam_n))
    return out


def check_solution(M, a0, rows, sol, omega):
    """The chosen modes' forces and accelerations: M v' = M a0 + sum (Wn lam_n + Wt lam_t),
    the contact rows held at g'' + 2 omega g' + omega^2 g = 0 (Eq. 52) with lambda_n >= 0 and
    lambda_t = -mu lambda_n s (Eq. 50), the detached rows not closing."""
    f = sum(r.Wn * ln + r.Wt @ lt for r, ln, lt in zip(rows, sol.lam_n, sol.lam_t))
    np.testing.assert_allclose(M @ sol.vdot, M @ a0 + f, rtol=1e-12, atol=1e-12)
    stab = stabilised_gddot(sol, rows, omega)
    f_tol = TIE_RTOL * (1.0 + np.abs(sol.lam_n).max())
    for i, (r, m) in enumerate(zip(rows, sol.modes)):
        if m == DETACH:
            assert sol.lam_n[i] == 0.0 and stab[i] >= 0.0
        else:
            assert abs(stab[i]) <= 1e-12 * (1.0 + np.abs(a0).max())
            assert sol.lam_n[i] >= -f_tol
            s = r.vt / np.linalg.norm(r.vt)
            np.testing.assert_allclose(sol.lam_t[i], -r.mu * sol.lam_n[i] * s, atol=1e-15)


# The lift-off of a sliding couple as the IDSS campaign's sample 139 met it: the tip slides at
# 8 cm/s and its normal force falls to zero; at the witness's zero the contact has drifted
# 8.3e-9 m open and closes at 1.9e-10 m/s, and the free normal acceleration is -3.3e-6 m/s^2,
# less than the stabilisation's omega^2 g + 2 omega g' = 3.3e-6 m/s^2 pulling the gap shut.
LIFT_OFF = dict(gap=8.273e-9, vn=-1.875e-10, vt=[-0.0803, 0.0])
GDDOT_FREE = -3.2909e-6


def test_a_sliding_couple_lifting_off_with_an_open_drift_detaches(select_contact_modes):
    """The free motion's stabilised normal acceleration is +1.1e-8 m/s^2: sliding would need
    lambda_n = -1.1e-8 / A < 0 (a pull), detaching leaves the stabilised row >= 0, so
    detaching is the one consistent mode (Eq. 50-52). The unstabilised g'' < 0 of the free
    motion is the drift closing, which the gap witness of the detached couple watches."""
    theta, l, mass, mu = math.radians(30.0), 1.0, 1000.0, 0.1
    M, row = rod(theta, l, mass, mu, **LIFT_OFF)
    a0 = np.zeros(6)
    a0[2] = GDDOT_FREE                       # free g'' = a_z of the tip (no rotation)
    stab_free = GDDOT_FREE + 2 * OMEGA * row.vn + OMEGA ** 2 * row.gap
    # Sliding pulls and the unstabilised g'' of detaching is negative, both beyond TIE_RTOL
    # of the force (1 N) and acceleration (1 m/s^2) floors:
    lam_slide = -stab_free / tip_A(theta, l, mass, mu, -1.0)
    assert stab_free > 0 and GDDOT_FREE < -TIE_RTOL * 1.01 and lam_slide < -TIE_RTOL
    sol = select_contact_modes(np.linalg.inv(M), a0, [row], omega=OMEGA, time=1.96525946,
                       avoid=[("stick", "slide")])
    assert sol.modes == (DETACH,)
    np.testing.assert_array_equal(sol.vdot, a0)
    check_solution(M, a0, [row], sol, OMEGA)
    (modes, vdot, lam_n), = modes_by_enumeration(M, a0, [row], OMEGA)
    assert modes == (DETACH,)
    # Without the avoid hint the choice is the same: it is the only consistent one.
    assert select_contact_modes(np.linalg.inv(M), a0, [row], omega=OMEGA).modes == (DETACH,)


def test_a_loaded_sliding_couple_with_the_same_drift_keeps_sliding(select_contact_modes):
    """Gravity on the same rod: lambda_n = -(b + 2 omega g' + omega^2 g) / A, the sliding
    tip's closed form (Eq. 50, 52)."""
    theta, l, mass, mu = math.radians(30.0), 1.0, 1000.0, 0.1
    M, row = rod(theta, l, mass, mu, gap=LIFT_OFF["gap"], vn=LIFT_OFF["vn"], vt=[-0.08, 0.0])
    a0 = np.array([0.0, 0.0, -G, 0.0, 0.0, 0.0])
    sol = select_contact_modes(np.linalg.inv(M), a0, [row], omega=OMEGA)
    assert sol.modes == (SLIDE,)
    b = -G + 2 * OMEGA * row.vn + OMEGA ** 2 * row.gap
    np.testing.assert_allclose(sol.lam_n[0], -b / tip_A(theta, l, mass, mu, -1.0), rtol=1e-12)
    check_solution(M, a0, [row], sol, OMEGA)


@pytest.mark.parametrize("drift", [dict(gap=0.0, vn=0.0), LIFT_OFF])
def test_painleve_rod_above_the_critical_friction_is_inconsistent(drift, select_contact_modes):
    """mu = 3 at 30 deg: A = (1 + 3 c (c + mu s sn)) / m < 0 for the tip sliding towards -x, and
    gravity presses it on the plane: sliding needs lambda_n = G / A < 0 and detaching has
    g'' = -G. No consistent mode: PainleveError."""
    theta, l, mass, mu = math.radians(30.0), 1.0, 1000.0, 3.0
    assert tip_A(theta, l, mass, mu, -1.0) < 0
    M, row = rod(theta, l, mass, mu, vt=[-1.0, 0.0], **{k: drift[k] for k in ("gap", "vn")})
    a0 = np.array([0.0, 0.0, -G, 0.0, 0.0, 0.0])
    assert modes_by_enumeration(M, a0, [row], OMEGA) == []
    with pytest.raises(PainleveError, match="no consistent contact mode") as err:
        select_contact_modes(np.linalg.inv(M), a0, [row], omega=OMEGA, time=0.5)
    assert err.value.time == 0.5 and list(err.value.couples) == ["tip_plane"]


def random_scene(rng):
    """A rigid body with 1-3 sliding contact points on the plane at mu = 0.1, each drifted
    open or shut by up to 1e-8 m at up to 1e-9 m/s, and a free acceleration whose normal parts
    are of the size of the stabilisation (the window between lift-off and contact)."""
    mass = rng.uniform(50.0, 5000.0)
    inertia = mass * rng.uniform(0.2, 2.0, 3)
    k = int(rng.integers(1, 4))
    angles = rng.permutation(np.linspace(0.0, 2 * np.pi, 3, endpoint=False))[:k]
    rows = []
    for j, a in enumerate(angles):
        r = np.array([math.cos(a), math.sin(a), -rng.uniform(0.3, 1.0)])
        rows.append(plane_row(f"c{j}", r, gap=rng.uniform(-1e-8, 1e-8),
                              vn=rng.uniform(-1e-9, 1e-9), vt=rng.normal(size=2) * 0.05,
                              mu=0.1))
    a0 = np.concatenate([rng.normal(size=3) * 1e-3, rng.normal(size=3) * 1e-9])
    a0[2] = rng.uniform(-1.0, 1.0) * OMEGA ** 2 * 1e-8
    return body_mass(mass, inertia), a0, rows


def test_random_sliding_contacts_match_the_enumeration(select_contact_modes):
    """Random scenes in the lift-off window: mode selection always succeeds at mu = 0.1, and
    its choice is a consistent mode of the brute-force enumeration with the same
    accelerations."""
    rng = np.random.default_rng(18)
    detached = 0
    for _ in range(300):
        M, a0, rows = random_scene(rng)
        sol = select_contact_modes(np.linalg.inv(M), a0, rows, omega=OMEGA)
        check_solution(M, a0, rows, sol, OMEGA)
        found = modes_by_enumeration(M, a0, rows, OMEGA, rtol=TIE_RTOL)
        assert found
        assert any(np.allclose(vdot, sol.vdot, rtol=0.0, atol=1e-12) for _, vdot, _ in found)
        detached += DETACH in sol.modes
    assert 0 < detached < 300


def test_two_sticking_points_carry_the_load_within_the_baumgarte_terms():
    """A box resting on two sticking points of the plane is statically indeterminate: their
    six rows have rank 5 (the two points' distance is held twice). When the two couples' gaps
    drift apart by round-off, the stabilised rows (Eq. 52) ask the two normal accelerations for
    different corrections, and the equations are inconsistent by as much: the least-squares
    forces are taken. Closed form: the plane carries the weight m g, shared equally by the
    symmetric points, no tangential force, and the residual is within the Baumgarte terms."""
    m = 2.0
    M = body_mass(m, [0.1, 0.2, 0.15])
    a0 = np.array([0.0, 0.0, -G, 0.0, 0.0, 0.0])
    r = np.array([0.3, 0.0, -0.1])
    rows = [plane_row("left", r * [-1, 1, 1], gap=0.0, vn=0.0, vt=[0, 0], mu=0.5),
            plane_row("right", r, gap=0.0, vn=3e-7, vt=[0, 0], mu=0.5)]
    sol = compiled.solve_given_modes(np.linalg.inv(M), a0, rows, ("stick", "stick"),
                                     [None, None], omega=OMEGA)
    soft = 2 * OMEGA * 3e-7
    assert sol.lam_n.sum() == pytest.approx(m * G, abs=10 * m * soft)
    assert sol.lam_n[0] == pytest.approx(sol.lam_n[1], abs=10 * m * soft)
    assert np.abs(sol.lam_t).max() < 10 * m * soft
    gdd = [r_.Wn @ sol.vdot + r_.bn + 2 * OMEGA * r_.vn for r_ in rows]
    assert max(abs(x) for x in gdd) <= soft


def test_inconsistent_redundant_sticking_beyond_the_baumgarte_terms_is_singular():
    """The same box with the two points at one place but asked for different normal
    accelerations by their velocity-product terms (1e-3 m/s^2 apart, far beyond round-off and
    with no Baumgarte term to account for it): no forces hold both rows, a
    `SingularContactError`."""
    from drake_dock.errors import SingularContactError
    M = body_mass(2.0, [0.1, 0.2, 0.15])
    a0 = np.array([0.0, 0.0, -G, 0.0, 0.0, 0.0])
    r = np.array([0.3, 0.0, -0.1])
    rows = [plane_row("a", r, gap=0.0, vn=0.0, vt=[0, 0], mu=0.5),
            plane_row("b", r, gap=0.0, vn=0.0, vt=[0, 0], mu=0.5, bn=1e-3)]
    with pytest.raises(SingularContactError):
        compiled.solve_given_modes(np.linalg.inv(M), a0, rows, ("stick", "stick"),
                                   [None, None], omega=OMEGA)
