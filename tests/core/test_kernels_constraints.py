"""The compiled constraint solve and mode selection (drake_dock.core.kernels.constraints) against
the pure-Python reference (drake_dock.core.constraints) to 1e-10 (the compiled solve factors its
systems by its own LU, `small_linalg`, the reference by LAPACK's: they agree to the round-off
the systems' conditioning allows): random seeded scenes of one
or two free bodies with sticking, sliding and detached couples, redundant and inconsistent
sticking rows, and Painleve's rod on both sides of its critical friction (closed form).
tests/core/test_constraints.py runs its scenes through both implementations too."""
import math

import numpy as np
import pytest

from drake_dock.core import constraints as ref
from drake_dock.core.kernels import constraints as KC
from drake_dock.errors import (NumericalError, PainleveInconsistency,
                               SingularContactError)
from test_constraints import G, OMEGA, random_scene, rod

FIELDS = ("vdot", "lam_n", "lam_t", "generalized_force")


def assert_same(a, b, tol=1e-10):
    """Two `ContactSolution`s: the same modes and sliding directions, and every force and
    acceleration within tol of its scale."""
    assert a.modes == b.modes
    for sa, sb in zip(a.dirs, b.dirs):
        assert (sa is None) == (sb is None)
        if sa is not None:
            np.testing.assert_allclose(sb, sa, rtol=0.0, atol=tol)
    for f in FIELDS:
        x, y = getattr(a, f), getattr(b, f)
        assert x.shape == y.shape
        np.testing.assert_allclose(y, x, rtol=0.0, atol=tol * (1.0 + np.abs(x).max(initial=0.0)))


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
        rows.append(ref.ContactRow(f"c{j}", W[:, 0], W[:, 1:], rng.normal(), rng.normal(size=2),
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


def assert_same_outcome(a, b):
    if isinstance(a, tuple):
        assert b == a
    else:
        assert_same(a, b)


def test_solve_given_modes_equals_the_reference():
    """Every choice of stick, slide (random unit direction) and detach on random scenes."""
    rng = np.random.default_rng(19)
    singular = 0
    for _ in range(200):
        M, a0, rows = general_scene(rng)
        Minv = np.linalg.inv(M)
        modes = [(ref.STICK, ref.SLIDE, ref.DETACH)[rng.integers(3)] for _ in rows]
        dirs = []
        for m in modes:
            s = rng.normal(size=2)
            dirs.append(s / np.linalg.norm(s) if m == ref.SLIDE else None)
        args = (Minv, a0, rows, modes, dirs)
        a = outcome(ref.solve_given_modes, *args, omega=OMEGA, time=0.25)
        assert_same_outcome(a, outcome(KC.solve_given_modes, *args, omega=OMEGA, time=0.25))
        singular += isinstance(a, tuple)
    assert 0 < singular < 20         # more rows than velocities: singular and inconsistent


def test_redundant_sticking_rows_take_the_reference_least_squares_forces():
    """A second couple with the first one's row (a statically indeterminate support): the
    consistent equations take the minimum-norm forces; with a different velocity-product
    term they are inconsistent, and both raise `SingularContactError` naming the couples."""
    rng = np.random.default_rng(7)
    B = rng.normal(size=(6, 6))
    M, a0, W = B @ B.T + 6 * np.eye(6), rng.normal(size=6), rng.normal(size=(6, 3))
    r = ref.ContactRow("a", W[:, 0], W[:, 1:], 0.3, np.array([0.1, -0.2]), 0.0, 0.0,
                       np.zeros(2), 0.2, 0.2)
    twin = ref.ContactRow("b", r.Wn, r.Wt, r.bn, r.bt, r.gap, r.vn, r.vt, r.mu, r.mu_s)
    Minv = np.linalg.inv(M)
    args = (Minv, a0, [r, twin], [ref.STICK] * 2, [None] * 2)
    a = ref.solve_given_modes(*args, omega=OMEGA)
    assert_same(a, KC.solve_given_modes(*args, omega=OMEGA))
    np.testing.assert_allclose(a.lam_n[0], a.lam_n[1], rtol=1e-12)   # minimum norm: shared
    off = ref.ContactRow("b", r.Wn, r.Wt, r.bn + 1.0, r.bt, r.gap, r.vn, r.vt, r.mu, r.mu_s)
    for solve in (ref.solve_given_modes, KC.solve_given_modes):
        with pytest.raises(SingularContactError, match="inconsistent") as err:
            solve(Minv, a0, [r, off], [ref.STICK] * 2, [None] * 2, omega=OMEGA, time=0.5)
        assert err.value.couples == ("a", "b") and err.value.time == 0.5


def test_non_finite_equations_raise_a_typed_error():
    """A nan in a row is reported as a `NumericalError` with the time and the couple, not as a
    LAPACK error."""
    rng = np.random.default_rng(3)
    M, a0, rows = general_scene(rng, slow=1.0)
    rows[0].Wn[0] = np.nan
    with pytest.raises(NumericalError, match="not finite") as err:
        KC.solve_given_modes(np.linalg.inv(M), a0, rows, [ref.STICK] * len(rows),
                             [None] * len(rows), omega=OMEGA, time=0.125)
    assert err.value.time == 0.125 and "c0" in err.value.couples


@pytest.mark.parametrize("scene", ["plane", "general"])
def test_select_contact_modes_equals_the_reference(scene):
    """The choice (modes, directions of sliding, forces, accelerations) or the error of mode
    selection on random scenes: contacts on a plane in the lift-off window
    (test_constraints.random_scene), and general scenes with couples at rest, with and
    without modes to avoid."""
    rng = np.random.default_rng(20)
    kinds = set()
    for n in range(150):
        M, a0, rows = random_scene(rng) if scene == "plane" else general_scene(rng)
        Minv = np.linalg.inv(M)
        avoid = None
        if n % 2:
            avoid = [tuple(m for m in (ref.STICK, ref.SLIDE, ref.DETACH) if rng.random() < 0.3)
                     for _ in rows]
        a = outcome(ref.select_contact_modes, Minv, a0, rows, omega=OMEGA, time=0.5, avoid=avoid)
        b = outcome(KC.select_contact_modes, Minv, a0, rows, omega=OMEGA, time=0.5, avoid=avoid)
        assert_same_outcome(a, b)
        kinds.update([a[0].__name__] if isinstance(a, tuple) else a.modes)
    # The scenes reach every mode (and, on general scenes, the Painleve paradox).
    assert {ref.SLIDE, ref.DETACH} <= kinds
    if scene == "general":
        assert {ref.STICK, "PainleveInconsistency"} <= kinds


def rod_critical_mu(theta):
    """Painleve's rod with its tip sliding towards -x: the tip's normal inverse mass
    (1 + 3 c (c - mu sn)) / m vanishes at mu_c = (1 + 3 c^2) / (3 c sn)."""
    c, sn = math.cos(theta), math.sin(theta)
    return (1.0 + 3.0 * c * c) / (3.0 * c * sn)


@pytest.mark.parametrize("factor", [0.98, 1.02])
def test_painleve_rod_on_both_sides_of_the_critical_friction(factor):
    """Below mu_c the tip slides with lambda_n = m g / (1 + 3 c (c - mu sn)) (gravity on the
    plane); above it no mode is consistent and both implementations raise `PainleveError`."""
    theta, l, mass = math.radians(30.0), 1.0, 1000.0
    mu = factor * rod_critical_mu(theta)
    M, row = rod(theta, l, mass, mu, gap=0.0, vn=0.0, vt=[-1.0, 0.0])
    a0 = np.array([0.0, 0.0, -G, 0.0, 0.0, 0.0])
    results = [outcome(s, np.linalg.inv(M), a0, [row], omega=OMEGA, time=0.5)
               for s in (ref.select_contact_modes, KC.select_contact_modes)]
    a, b = results
    assert_same_outcome(a, b)
    if factor > 1:
        assert a[0] is PainleveInconsistency and "no consistent" in a[1]
    else:
        assert a.modes == (ref.SLIDE,)
        c, sn = math.cos(theta), math.sin(theta)
        np.testing.assert_allclose(b.lam_n[0], mass * G / (1.0 + 3.0 * c * (c - mu * sn)),
                                   rtol=1e-12)
