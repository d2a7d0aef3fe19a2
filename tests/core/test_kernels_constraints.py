"""The compiled constraint solve and mode selection (drake_dock.core.kernels.constraints) against
the equations and inequalities of the modes they return (Eq. 48-52, stated independently here),
on random seeded scenes of one or two free bodies with sticking, sliding and detached couples;
redundant sticking rows against the minimum-norm forces, inconsistent ones and non-finite ones
against their typed errors, and Painleve's rod on both sides of its critical friction (closed
form). tests/core/test_constraints.py and test_squeeze.py hold the closed-form scenes."""
import math

import numpy as np
import pytest

from drake_dock.core.constraints import (DETACH, SLIDE, STICK, TIE_RTOL, ContactRow,
                                         slip_angle, stabilised)
from drake_dock.core.kernels import constraints as KC
from drake_dock.errors import (NumericalError, PainleveError, PainleveInconsistency,
                               SingularContactError)
from test_constraints import G, OMEGA, choices_by_kkt, random_scene, rod


def check_equations(Minv, a0, rows, sol, omega, tol=1e-9):
    """The equations of the solution's modes, each within tol of its scale: M v' = M a0 +
    sum (Wn lam_n + Wt lam_t) (the generalized contact force), a couple in contact holding
    g'' + 2 omega g' + omega^2 g = 0 (Eq. 52, stabilised), a sticking one a_t = Wt^T v' + bt =
    0 (Eq. 51), a sliding one lam_t = -mu lam_n s along its unit direction s (Eq. 50), a
    detached one no force."""
    f = sum(r.Wn * ln + r.Wt @ lt for r, ln, lt in zip(rows, sol.lam_n, sol.lam_t))
    f_scale = 1.0 + np.abs(sol.lam_n).max(initial=0.0) + np.abs(sol.lam_t).max(initial=0.0)
    a_scale = 1.0 + np.abs(sol.vdot).max() + np.abs(a0).max()
    np.testing.assert_allclose(sol.generalized_force, f, rtol=0.0, atol=tol * f_scale)
    np.testing.assert_allclose(sol.vdot, a0 + Minv @ f, rtol=0.0,
                               atol=tol * (a_scale + np.abs(Minv).max() * f_scale))
    for i, (r, m) in enumerate(zip(rows, sol.modes)):
        gdd = stabilised(r.Wn @ sol.vdot + r.bn, r.vn, r.gap, omega)
        if m == DETACH:
            assert sol.lam_n[i] == 0.0 and not sol.lam_t[i].any()
            continue
        assert abs(gdd) <= tol * a_scale
        if m == STICK:
            np.testing.assert_allclose(r.Wt.T @ sol.vdot + r.bt, 0.0, atol=tol * a_scale)
        else:
            s = np.asarray(sol.dirs[i])
            assert np.hypot(*s) == pytest.approx(1.0, abs=1e-12)
            np.testing.assert_allclose(sol.lam_t[i], -r.mu * sol.lam_n[i] * s, rtol=0.0,
                                       atol=tol * f_scale)


def scales(a0, rows, sol):
    """The mode selection's force and acceleration scales (`drake_dock.core.constraints`):
    1 N + max |lambda_n| of the solution, and 1 m/s^2 + the largest free normal and tangential
    accelerations (every couple detached)."""
    gdd = [abs(r.Wn @ a0 + r.bn) for r in rows]
    at = [np.abs(r.Wt.T @ a0 + r.bt).max() for r in rows]
    return 1.0 + np.abs(sol.lam_n).max(initial=0.0), 1.0 + max(gdd) + max(at)


def consistent(a0, rows, sol, omega, rtol):
    """Whether the solution's modes hold their inequalities within rtol of the `scales`:
    lam_n >= 0 in contact (Eq. 50-51), the stabilised normal row >= 0 detached (Eq. 52), a
    sticking force in the static cone |lam_t| <= mu_s lam_n (Eq. 51)."""
    f_scale, a_scale = scales(a0, rows, sol)
    for i, (r, m) in enumerate(zip(rows, sol.modes)):
        gdd = stabilised(r.Wn @ sol.vdot + r.bn, r.vn, r.gap, omega)
        if m == DETACH:
            if gdd < -rtol * a_scale:
                return False
        elif sol.lam_n[i] < -rtol * f_scale or (
                m == STICK and np.hypot(*sol.lam_t[i]) > r.mu_s * sol.lam_n[i] + rtol * f_scale):
            return False
    return True


def check_starts(rows, sol, v_slip=1e-6):
    """A couple moving faster than v_slip does not stick and slides against its velocity;
    one starting to slide from rest has a tangential acceleration along its direction (a
    positive component along it, the slip angle within 1e-6 rad: Eq. 50, friction opposes the
    slip it starts), or one below 1e-6 of the acceleration scale (at its stick-slip
    transition)."""
    for i, (r, m) in enumerate(zip(rows, sol.modes)):
        moving = np.hypot(*r.vt) > v_slip
        if m == STICK:
            assert not moving
        elif m == SLIDE and moving:
            np.testing.assert_allclose(sol.dirs[i], r.vt / np.hypot(*r.vt), atol=1e-12)
        elif m == SLIDE:
            at = r.Wt.T @ sol.vdot + r.bt
            if np.hypot(*at) <= 1e-6 * (1.0 + np.abs(sol.vdot).max()):
                continue
            assert at @ sol.dirs[i] > 0 and abs(slip_angle(sol.dirs[i], at)) < 1e-6


def key(sol, rows, avoid) -> tuple:
    """The selection's preference among consistent choices, smaller first: fewer couples in a
    mode they are leaving (``avoid``), then more sticking, then more in contact."""
    avoid = avoid or [()] * len(rows)
    return (sum(m in a for m, a in zip(sol.modes, avoid)), -sol.modes.count(STICK),
            sol.modes.count(DETACH))


def general_scene(rng, *, slow=0.5):
    """One or two free bodies (a random symmetric positive definite M) with 1-4 couples in
    random directions, each drifted by up to 1e-8 m; a couple slides (|vt| = 0.05 m/s) or, with
    probability ``slow``, is at rest (it may stick or start to slide)."""
    nv = 6 * int(rng.integers(1, 3))
    B = rng.normal(size=(nv, nv))
    M = B @ B.T + nv * np.diag(rng.uniform(1.0, 100.0, nv))
    rows = []
    for j in range(int(rng.integers(1, 5))):
        W = rng.normal(size=(nv, 3))
        mu = rng.uniform(0.05, 0.5)
        vt = np.zeros(2) if rng.random() < slow else rng.normal(size=2) * 0.05
        rows.append(ContactRow(f"c{j}", W[:, 0], W[:, 1:], rng.normal(), rng.normal(size=2),
                                   rng.uniform(-1e-8, 1e-8), rng.uniform(-1e-9, 1e-9), vt, mu,
                                   mu * rng.uniform(1.0, 1.3)))
    a0 = rng.normal(size=nv)
    return M, a0, rows


def outcome(solve, *args, **kw):
    """The solution, or the typed error's class, its message up to any number and its
    couples."""
    try:
        return solve(*args, **kw)
    except NumericalError as err:
        return type(err), str(err).split("(")[0], err.couples


def test_solve_given_modes_holds_the_equations_of_the_modes():
    """Every choice of stick, slide (random unit direction) and detach on random scenes: the
    modes' equations hold, or the constraint matrix D^T M^-1 C is singular (numpy's SVD of it,
    built here) and the solve raises `SingularContactError` naming the couples in contact."""
    rng = np.random.default_rng(19)
    singular = 0
    for _ in range(200):
        M, a0, rows = general_scene(rng)
        Minv = np.linalg.inv(M)
        modes = [(STICK, SLIDE, DETACH)[rng.integers(3)] for _ in rows]
        dirs = []
        for m in modes:
            s = rng.normal(size=2)
            dirs.append(s / np.linalg.norm(s) if m == SLIDE else None)
        C, D = [], []
        for r, m, s in zip(rows, modes, dirs):
            if m == STICK:
                C += [r.Wn, r.Wt[:, 0], r.Wt[:, 1]]
                D += [r.Wn, r.Wt[:, 0], r.Wt[:, 1]]
            elif m == SLIDE:
                C.append(r.Wn - r.mu * r.Wt @ s)
                D.append(r.Wn)
        try:
            sol = KC.solve_given_modes(Minv, a0, rows, modes, dirs, omega=OMEGA, time=0.25)
        except SingularContactError as err:
            A = np.array(D) @ Minv @ np.array(C).T
            sv = np.linalg.svd(A, compute_uv=False)
            assert sv[-1] <= 1e-8 * sv[0]
            assert err.time == 0.25
            assert set(err.couples) == {r.name for r, m in zip(rows, modes) if m != DETACH}
            singular += 1
            continue
        if C:
            sv = np.linalg.svd(np.array(D) @ Minv @ np.array(C).T, compute_uv=False)
            assert sv[-1] > 1e-12 * sv[0]
        check_equations(Minv, a0, rows, sol, OMEGA)
        assert sol.modes == tuple(modes)
    assert 0 < singular < 20         # more rows than velocities: singular and inconsistent


def test_redundant_sticking_rows_take_the_minimum_norm_forces():
    """A second couple with the first one's row (a statically indeterminate support): the
    consistent equations take the minimum-norm forces (the pseudo-inverse's, numpy's, shared
    equally by the two couples); with a different velocity-product term they are
    inconsistent, and the solve raises `SingularContactError` naming the couples."""
    rng = np.random.default_rng(7)
    B = rng.normal(size=(6, 6))
    M, a0, W = B @ B.T + 6 * np.eye(6), rng.normal(size=6), rng.normal(size=(6, 3))
    r = ContactRow("a", W[:, 0], W[:, 1:], 0.3, np.array([0.1, -0.2]), 0.0, 0.0,
                   np.zeros(2), 0.2, 0.2)
    twin = ContactRow("b", r.Wn, r.Wt, r.bn, r.bt, r.gap, r.vn, r.vt, r.mu, r.mu_s)
    Minv = np.linalg.inv(M)
    sol = KC.solve_given_modes(Minv, a0, [r, twin], [STICK] * 2, [None] * 2, omega=OMEGA)
    check_equations(Minv, a0, [r, twin], sol, OMEGA)
    C = np.column_stack([W, W])                 # n, ta, tb of each couple
    b = -(np.array([r.bn, *r.bt] * 2) + C.T @ a0)
    lam = np.linalg.pinv(C.T @ Minv @ C) @ b
    np.testing.assert_allclose(sol.lam_n, lam[[0, 3]], rtol=1e-9)
    np.testing.assert_allclose(sol.lam_t, lam[[1, 2, 4, 5]].reshape(2, 2), rtol=1e-9)
    np.testing.assert_allclose(sol.lam_n[0], sol.lam_n[1], rtol=1e-12)   # minimum norm: shared
    off = ContactRow("b", r.Wn, r.Wt, r.bn + 1.0, r.bt, r.gap, r.vn, r.vt, r.mu, r.mu_s)
    with pytest.raises(SingularContactError, match="inconsistent") as err:
        KC.solve_given_modes(Minv, a0, [r, off], [STICK] * 2, [None] * 2, omega=OMEGA,
                             time=0.5)
    assert err.value.couples == ("a", "b") and err.value.time == 0.5


def test_non_finite_equations_raise_a_typed_error():
    """A nan in a row is reported as a `NumericalError` with the time and the couple, not as a
    LAPACK error."""
    rng = np.random.default_rng(3)
    M, a0, rows = general_scene(rng, slow=1.0)
    rows[0].Wn[0] = np.nan
    with pytest.raises(NumericalError, match="not finite") as err:
        KC.solve_given_modes(np.linalg.inv(M), a0, rows, [STICK] * len(rows),
                             [None] * len(rows), omega=OMEGA, time=0.125)
    assert err.value.time == 0.125 and "c0" in err.value.couples


@pytest.mark.parametrize("scene", ["plane", "general", "at rest"])
def test_select_contact_modes_returns_a_consistent_choice(scene):
    """The choice of mode selection on random scenes: contacts on a plane in the lift-off
    window (test_constraints.random_scene), general scenes with couples at rest, and general
    scenes with every couple at rest (among them choices with three or more couples starting to
    slide at once), with and without modes to avoid. Each choice holds its modes' equations and
    inequalities, and no choice without a start of sliding that is consistent to 1e-10 of the
    scales (tighter than the selection's 1e-9), solved by its KKT system
    (`test_constraints.choices_by_kkt`), is preferred to it; where the selection finds
    none consistent (`PainleveInconsistency`, with the time), none of those is."""
    rng = np.random.default_rng(20)
    kinds = set()
    for n in range(150):
        M, a0, rows = (random_scene(rng) if scene == "plane" else
                       general_scene(rng, slow=1.0 if scene == "at rest" else 0.5))
        Minv = np.linalg.inv(M)
        avoid = None
        if n % 2:
            avoid = [tuple(m for m in (STICK, SLIDE, DETACH) if rng.random() < 0.3)
                     for _ in rows]
        others = [o for o in choices_by_kkt(M, a0, rows, OMEGA)
                  if consistent(a0, rows, o, OMEGA, 1e-10)]
        try:
            sol = KC.select_contact_modes(Minv, a0, rows, omega=OMEGA, time=0.5, avoid=avoid)
        except PainleveInconsistency as err:
            assert err.time == 0.5 and not others
            kinds.add("PainleveInconsistency")
            continue
        except PainleveError as err:
            assert err.time == 0.5
            kinds.add("PainleveError")
            continue
        check_equations(Minv, a0, rows, sol, OMEGA, tol=1e-8)
        assert consistent(a0, rows, sol, OMEGA, TIE_RTOL)
        check_starts(rows, sol)
        starts = sum(m == SLIDE and not np.hypot(*r.vt) > 1e-6 for r, m in zip(rows, sol.modes))
        kinds.add(f"{min(starts, 3)} starting")
        assert all(key(sol, rows, avoid) <= key(o, rows, avoid) for o in others)
        kinds.update(sol.modes)
    # The scenes reach every mode (and, on general scenes, the Painleve paradox).
    assert {SLIDE, DETACH} <= kinds
    if scene != "plane":
        assert {STICK, "PainleveInconsistency", "1 starting", "2 starting"} <= kinds
    if scene == "at rest":
        assert "3 starting" in kinds            # three or more couples starting at once


def rod_critical_mu(theta):
    """Painleve's rod with its tip sliding towards -x: the tip's normal inverse mass
    (1 + 3 c (c - mu sn)) / m vanishes at mu_c = (1 + 3 c^2) / (3 c sn)."""
    c, sn = math.cos(theta), math.sin(theta)
    return (1.0 + 3.0 * c * c) / (3.0 * c * sn)


@pytest.mark.parametrize("factor", [0.98, 1.02])
def test_painleve_rod_on_both_sides_of_the_critical_friction(factor):
    """Below mu_c the tip slides with lambda_n = m g / (1 + 3 c (c - mu sn)) (gravity on the
    plane); above it no mode is consistent and the selection raises `PainleveInconsistency`."""
    theta, l, mass = math.radians(30.0), 1.0, 1000.0
    mu = factor * rod_critical_mu(theta)
    M, row = rod(theta, l, mass, mu, gap=0.0, vn=0.0, vt=[-1.0, 0.0])
    a0 = np.array([0.0, 0.0, -G, 0.0, 0.0, 0.0])
    a = outcome(KC.select_contact_modes, np.linalg.inv(M), a0, [row], omega=OMEGA, time=0.5)
    if factor > 1:
        assert a[0] is PainleveInconsistency and "no consistent" in a[1]
    else:
        assert a.modes == (SLIDE,)
        c, sn = math.cos(theta), math.sin(theta)
        np.testing.assert_allclose(a.lam_n[0], mass * G / (1.0 + 3.0 * c * (c - mu * sn)),
                                   rtol=1e-12)
