"""Two couples sticking between two rigid bodies leave one internal squeeze undetermined
(`drake_dock.core.squeeze`): a ball resting in a V-groove, whose minimum-norm forces are
vertical and so outside a small friction cone, sticks with forces inside it (statics: they
carry the weight), and a block standing on two points of an incline steeper than its friction
angle slides with the closed-form acceleration; starts of sliding found where the tangential
acceleration lies along the direction (dense samplings, scipy's least squares). The compiled
solve and mode selection (drake_dock.core.kernels.constraints); runs without Drake."""
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from drake_dock.core.constraints import (SLIDE, SLIDE_START_ITER, STICK,
                                         ContactRow, slip_angle)
from drake_dock.core.kernels import constraints as compiled
from drake_dock.core.squeeze import SHRINK, cone_interval, sorted_values

G, OMEGA = 9.81, 20.0


@pytest.fixture
def select_contact_modes():
    return compiled.select_contact_modes


def test_sorted_values_is_a_stable_ascending_sort():
    """The squeeze's sort of its cut points, called as Python and compiled, against Python's
    sorted() (stable): up to five values drawn from few, with infinities and both zeros, whose
    order sorted() keeps as given (their sign bits compared, not only their values)."""
    from numba import njit
    compiled_sort = njit(lambda x: sorted_values(x))
    pool = np.array([-np.inf, np.inf, 0.0, -0.0, 1.5, -2.0, 1.5])
    rng = np.random.default_rng(5)
    for _ in range(300):
        x = rng.choice(pool, size=rng.integers(0, 6))
        want = np.array(sorted(x.tolist()), dtype=float)
        for got in (sorted_values(x), compiled_sort(x)):
            assert got.tolist() == want.tolist()
            assert np.signbit(got).tolist() == np.signbit(want).tolist()


def point_row(name, r, n, mu):
    """A body point at r from the mass centre on a fixed plane of unit normal n, at rest (v =
    (v_com, w), world frame): W = [e; r x e] for e = n, t1, t2 (Eq. 11)."""
    t1 = np.cross(n, [0.0, 1.0, 0.0] if abs(n[1]) < 0.9 else [1.0, 0.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    W = [np.concatenate([e, np.cross(r, e)]) for e in (n, t1, t2)]
    return ContactRow(name, W[0], np.column_stack(W[1:]), 0.0, np.zeros(2), 0.0, 0.0,
                      np.zeros(2), mu, mu)


def test_cone_interval_equals_a_dense_sampling():
    """The closed form against the cone tested on 200001 points of s in [-50, 50]."""
    rng = np.random.default_rng(4)
    s = np.linspace(-50.0, 50.0, 200001)
    for _ in range(300):
        a, b, c0, c1, d0, d1 = rng.normal(size=6) * [5, 1, 2, 2, 1, 1]
        mu = rng.uniform(0.05, 1.0)
        lo, hi = cone_interval(a, b, c0, c1, d0, d1, mu)
        ok = (a + b * s >= 0) & (np.hypot(c0 + d0 * s, c1 + d1 * s) <= mu * (a + b * s))
        if not ok.any():
            assert lo > hi or min(hi, 50) - max(lo, -50) < 1e-3
            continue
        assert np.all(ok[(s > lo + 1e-3) & (s < hi - 1e-3)])         # one interval
        assert s[ok].min() == pytest.approx(max(lo, -50.0), abs=1e-3)
        assert s[ok].max() == pytest.approx(min(hi, 50.0), abs=1e-3)


def test_a_couple_the_squeeze_does_not_move_is_inside_for_every_s_or_none():
    """b = 0 and d = 0: the couple's force does not change with s."""
    assert cone_interval(2.0, 0.0, 0.1, 0.0, 0.0, 0.0, 0.1) == (-np.inf, np.inf)
    lo, hi = cone_interval(2.0, 0.0, 0.3, 0.0, 0.0, 0.0, 0.1)
    assert lo > hi


@pytest.mark.parametrize("theta_deg", [20.0, 35.0, 50.0])
@pytest.mark.parametrize("mu", [0.05, 0.1, 0.3, 0.5])
def test_a_ball_in_a_v_groove_sticks_with_forces_in_the_cone(select_contact_modes, theta_deg, mu):
    """A ball of radius R at rest in a groove whose faces' normals lean theta from the vertical.
    The minimum-norm forces are vertical (mg/2 each: tangential/normal = tan theta, outside the
    cone for mu < tan theta); forces along the normals (mg / (2 cos theta)) hold it. Sticking is
    consistent: the ball stays at rest, the forces carry the weight and lie in the cones."""
    m, R, th = 2.0, 0.1, math.radians(theta_deg)
    I = 0.4 * m * R * R
    M = np.diag([m, m, m, I, I, I])
    nA, nB = np.array([math.sin(th), 0.0, math.cos(th)]), np.array([-math.sin(th), 0.0,
                                                                     math.cos(th)])
    rows = [point_row("A", -R * nA, nA, mu), point_row("B", -R * nB, nB, mu)]
    a0 = np.array([0.0, 0.0, -G, 0.0, 0.0, 0.0])
    sol = select_contact_modes(np.linalg.inv(M), a0, rows, omega=OMEGA)
    assert sol.modes == (STICK, STICK)
    assert np.abs(sol.vdot).max() < 1e-9
    force = sum(r.Wn * ln + r.Wt @ lt for r, ln, lt in zip(rows, sol.lam_n, sol.lam_t))
    assert force == pytest.approx([0.0, 0.0, m * G, 0.0, 0.0, 0.0], abs=1e-9)
    for ln, lt in zip(sol.lam_n, sol.lam_t):
        assert math.hypot(*lt) <= SHRINK * mu * ln * (1 + 1e-12)
    if mu >= math.tan(th):                      # the minimum-norm forces already hold
        assert sol.lam_n == pytest.approx([0.5 * m * G * math.cos(th)] * 2, rel=1e-9)


def test_a_block_on_two_points_of_a_steep_incline_slides_at_the_closed_form_rate(
        select_contact_modes):
    """A body on two points of an incline of angle alpha > atan(mu), its mass centre on the
    line through them (no moment about it): no squeeze makes sticking consistent, and it
    slides down at g (sin alpha - mu cos alpha) without turning."""
    m, alpha, mu = 3.0, math.radians(25.0), 0.2
    M = np.diag([m, m, m, 0.1, 0.2, 0.15])
    n = np.array([-math.sin(alpha), 0.0, math.cos(alpha)])
    down = np.array([-math.cos(alpha), 0.0, -math.sin(alpha)])
    rows = [point_row(k, y * np.array([0.0, 1.0, 0.0]), n, mu)
            for k, y in (("A", -0.1), ("B", 0.1))]
    a0 = np.array([0.0, 0.0, -G, 0.0, 0.0, 0.0])
    sol = select_contact_modes(np.linalg.inv(M), a0, rows, omega=OMEGA)
    assert sol.modes == (SLIDE, SLIDE)
    a = sol.vdot[:3]
    assert a == pytest.approx(G * (math.sin(alpha) - mu * math.cos(alpha)) * down, abs=1e-9)
    assert np.abs(sol.vdot[3:]).max() < 1e-9


def _docking_selection(name="slide_start_docking.json"):
    d = json.loads((Path(__file__).parent / name).read_text())
    rows = [ContactRow(r["name"], np.array(r["Wn"]), np.array(r["Wt"]), r["bn"],
                       np.array(r["bt"]), r["gap"], r["vn"], np.array(r["vt"]), r["mu"],
                       r["mu_s"]) for r in d["rows"]]
    return np.array(d["Minv"]), np.array(d["a0"]), rows, d


def _slip_angles(Minv, a0, rows, v1, omega, th):
    """Couple 0 sliding along each angle of th, couple 1 along v1: the angles from couple 0's
    direction to its tangential acceleration, and whether that acceleration has a positive
    component along it."""
    angle, along = [], []
    for t in th:
        e = np.array([math.cos(t), math.sin(t)])
        at = compiled.solve_given_modes(Minv, a0, rows, (SLIDE, SLIDE), [e, v1],
                                           omega=omega).at[0]
        angle.append(slip_angle(e, at))
        along.append(at @ e > 0)
    return np.array(angle), np.array(along)


def _fixed_point(Minv, a0, rows, j, other, omega):
    """Couple j of two starting to slide, the other sliding along ``other``: the fixed point
    s <- a_t/|a_t| from the direction opposite its sticking force (where the selection
    starts), iterated as often as the selection does; (s, a_t) at its end."""
    def modes(m):
        return (m, SLIDE) if j == 0 else (SLIDE, m)

    def dirs(e):
        return [e, other] if j == 0 else [other, e]
    stick = compiled.solve_given_modes(Minv, a0, rows, modes(STICK), dirs(None), omega=omega)
    e = -stick.lam_t[j] / np.hypot(*stick.lam_t[j])
    for _ in range(SLIDE_START_ITER):
        at = compiled.solve_given_modes(Minv, a0, rows, modes(SLIDE), dirs(e), omega=omega).at[j]
        e = at / np.hypot(*at)
    return e, compiled.solve_given_modes(Minv, a0, rows, modes(SLIDE), dirs(e),
                                         omega=omega).at[j]


def test_a_start_of_sliding_the_fixed_point_misses_is_found(select_contact_modes):
    """A docking selection (tests/core/slide_start_docking.json): couple 0 at rest, couple 1
    sliding. Couple 0 sticking needs more than its cone; the fixed point s = a_t/|a_t| for its
    start of sliding does not converge. A dense sampling of its direction (3600 angles, no
    bisection) finds where a_t lies along s; the selection slides along that direction."""
    Minv, a0, rows, d = _docking_selection()
    sol = select_contact_modes(Minv, a0, rows, v_slip=d["v_slip"], omega=d["omega"],
                       avoid=[tuple(a) for a in d["avoid"]])
    assert sol.modes == (SLIDE, SLIDE)
    s = sol.dirs[0]
    assert abs(slip_angle(s, sol.at[0])) < 1e-9 and sol.at[0] @ s > 0
    assert (sol.lam_n > 0).all()
    v1 = rows[1].vt / np.hypot(*rows[1].vt)
    th = np.linspace(-math.pi, math.pi, 3601)
    res = np.abs(_slip_angles(Minv, a0, rows, v1, d["omega"], th)[0])
    t_best = th[int(np.argmin(res))]
    assert min(res) < 2 * math.pi / 3600
    assert math.atan2(s[1], s[0]) == pytest.approx(t_best, abs=2 * math.pi / 3600)
    # The fixed point alone misses it: s <- a_t/|a_t| from the sticking force's direction
    # (where the selection starts), iterated as often as the selection does, ends with a_t
    # not along s.
    e, at = _fixed_point(Minv, a0, rows, 0, v1, d["omega"])
    assert not at @ e > 0


def test_a_start_of_sliding_whose_fixed_point_does_not_converge_lies_along_a_t(
        select_contact_modes):
    """A docking selection (tests/core/slide_start_fixed_point.json): couple 0 sliding, couple
    1 at rest and leaving stick. The fixed point s = a_t/|a_t| for couple 1 does not converge:
    from the sticking force's direction, as many iterations as the selection makes leave a_t
    off s, though with a positive component along it. The selection slides along a direction
    where a_t lies along s (Eq. 50), the one a dense sampling (3600 angles) finds."""
    Minv, a0, rows, d = _docking_selection("slide_start_fixed_point.json")
    v0 = rows[0].vt / np.hypot(*rows[0].vt)
    e, at = _fixed_point(Minv, a0, rows, 1, v0, d["omega"])
    assert at @ e > 0 and abs(slip_angle(e, at)) > 1e-3
    sol = select_contact_modes(Minv, a0, rows, v_slip=d["v_slip"], omega=d["omega"],
                               avoid=[tuple(a) for a in d["avoid"]])
    assert sol.modes == (SLIDE, SLIDE) and (sol.lam_n > 0).all()
    s, at = sol.dirs[1], rows[1].Wt.T @ sol.vdot + rows[1].bt
    assert abs(slip_angle(s, at)) < 1e-9 and at @ s > 0
    th = np.linspace(-math.pi, math.pi, 3601)
    res = []
    for t in th:
        u = np.array([math.cos(t), math.sin(t)])
        a = compiled.solve_given_modes(Minv, a0, rows, (SLIDE, SLIDE), [v0, u],
                                       omega=d["omega"]).at[1]
        res.append(abs(slip_angle(u, a)) if a @ u > 0 else math.pi)
    k = int(np.argmin(res))
    assert res[k] < 5 * 2 * math.pi / 3600      # a_t turns faster than s there
    assert math.atan2(s[1], s[0]) == pytest.approx(th[k], abs=2 * math.pi / 3600)


def test_two_couples_starting_to_slide_are_found(select_contact_modes):
    """A docking selection (tests/core/slide_start_two.json): both couples at rest and leaving
    stick. Least squares from each point of a 36 x 36 grid of their two directions (scipy, an
    independent solver) finds where both tangential accelerations lie along their directions;
    the selection slides along those directions."""
    from scipy.optimize import least_squares
    d = json.loads((Path(__file__).parent / "slide_start_two.json").read_text())
    rows = [ContactRow(r["name"], np.array(r["Wn"]), np.array(r["Wt"]), r["bn"],
                       np.array(r["bt"]), r["gap"], r["vn"], np.array(r["vt"]), r["mu"],
                       r["mu_s"]) for r in d["rows"]]
    Minv, a0 = np.array(d["Minv"]), np.array(d["a0"])
    sol = select_contact_modes(Minv, a0, rows, v_slip=d["v_slip"], omega=d["omega"],
                       avoid=[tuple(a) for a in d["avoid"]])
    assert sol.modes == (SLIDE, SLIDE) and (sol.lam_n > 0).all()

    def residual(th):
        dirs = [np.array([math.cos(t), math.sin(t)]) for t in th]
        at = compiled.solve_given_modes(Minv, a0, rows, (SLIDE, SLIDE), dirs,
                                           omega=d["omega"]).at
        return [slip_angle(e, a) for e, a in zip(dirs, at)]

    g = np.linspace(-math.pi, math.pi, 36, endpoint=False)
    start = min(((a, b) for a in g for b in g), key=lambda t: np.abs(residual(t)).sum())
    root = least_squares(residual, start, xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    assert np.abs(residual(root)).max() < 1e-8
    for s, t in zip(sol.dirs, root):
        assert s == pytest.approx([math.cos(t), math.sin(t)], abs=1e-6)


def test_two_couples_at_the_stick_slip_transition_start_to_slide(select_contact_modes):
    """A docking selection (tests/core/slide_start_transition.json): both couples at rest and
    leaving stick at once. No squeeze puts the sticking forces in both cones (the intervals of
    `cone_interval`, checked on a dense sampling of the squeeze), and the sliding directions
    where both tangential accelerations vanish to 1e-6 of the acceleration scale are taken:
    the forces on the cones' edges, in equilibrium with no tangential acceleration."""
    d = json.loads((Path(__file__).parent / "slide_start_transition.json").read_text())
    rows = [ContactRow(r["name"], np.array(r["Wn"]), np.array(r["Wt"]), r["bn"],
                       np.array(r["bt"]), r["gap"], r["vn"], np.array(r["vt"]), r["mu"],
                       r["mu_s"]) for r in d["rows"]]
    Minv, a0 = np.array(d["Minv"]), np.array(d["a0"])
    stick = compiled.solve_given_modes(Minv, a0, rows, (STICK, STICK), [None, None],
                                          omega=d["omega"])
    C = np.column_stack([c for r in rows for c in (r.Wn, r.Wt[:, 0], r.Wt[:, 1])])
    z = np.linalg.svd(C.T @ Minv @ C)[2][-1]
    lam = np.concatenate([[stick.lam_n[i], *stick.lam_t[i]] for i in range(2)])
    s = np.linspace(-1e3, 1e3, 400001)
    L = lam + s[:, None] * z
    inside = ((np.hypot(L[:, 1], L[:, 2]) <= 0.1 * L[:, 0])
              & (np.hypot(L[:, 4], L[:, 5]) <= 0.1 * L[:, 3]))
    assert not inside.any()
    sol = select_contact_modes(Minv, a0, rows, v_slip=d["v_slip"], omega=d["omega"],
                       avoid=[tuple(a) for a in d["avoid"]])
    assert sol.modes == (SLIDE, SLIDE) and (sol.lam_n > 0).all()
    assert np.abs(sol.at).max() <= 1e-6 * (1.0 + np.abs(sol.vdot).max())


def test_a_start_of_sliding_next_to_the_stick_slip_transition_is_found(select_contact_modes):
    """A docking selection (tests/core/slide_start_steep.json): couple 0 at rest and leaving
    stick, its sticking force 2 % outside its cone; couple 1 sliding. Sliding, couple 0's
    tangential acceleration is small and turns fast with its direction: on the scan's grid
    the angle between them crosses zero between neighbours more than 90 deg apart. A dense
    sampling (20,000 angles) finds where a_t lies along s; the selection slides along it."""
    Minv, a0, rows, d = _docking_selection("slide_start_steep.json")
    v1 = rows[1].vt / np.hypot(*rows[1].vt)
    stick = compiled.solve_given_modes(Minv, a0, rows, (STICK, SLIDE), [None, v1],
                                          omega=d["omega"])
    ratio = np.hypot(*stick.lam_t[0]) / (rows[0].mu_s * stick.lam_n[0])
    assert 1.0 < ratio < 1.05
    sol = select_contact_modes(Minv, a0, rows, v_slip=d["v_slip"], omega=d["omega"],
                       avoid=[tuple(a) for a in d["avoid"]])
    assert sol.modes == (SLIDE, SLIDE) and (sol.lam_n > 0).all()
    s = sol.dirs[0]
    assert abs(slip_angle(s, sol.at[0])) < 1e-6 and sol.at[0] @ s > 0
    th = np.linspace(-math.pi, math.pi, 20001)
    angle, along = _slip_angles(Minv, a0, rows, v1, d["omega"], th)
    res = np.where(along, angle, math.pi)
    k = int(np.argmin(np.abs(res)))
    assert abs(res[k]) < 1e-3
    assert math.atan2(s[1], s[0]) == pytest.approx(th[k], abs=2 * math.pi / 20000)


def _bracket_order(ths, rs, th0):
    """The brackets the compiled scan bisects, in order (`slide_start._nearest_bracket`: the
    first kind, then the second where it is another)."""
    from drake_dock.core.kernels.slide_start import _nearest_bracket
    ths, rs = np.asarray(ths, float), np.asarray(rs, float)
    first = _nearest_bracket(ths, rs, th0, True)
    second = _nearest_bracket(ths, rs, th0, False)
    return [k for i, k in enumerate((first, second)) if k >= 0 and not (i and k == first)]


def test_the_scan_brackets_cross_zero_not_the_half_turn():
    """The slide-start scan's brackets on hand-made scans of the slip angle: a sign change
    through +-180 deg (a_t opposite s) next to th0 is never a bracket; a steep crossing of zero
    (15 deg to -103 deg) is, after any crossing with both ends within 90 deg."""
    ths = np.linspace(-math.pi, math.pi, 9)
    rs = np.array([1.0, 1.0, 3.1, -3.1, 0.27, -1.8, -1.0, -1.0, -1.0])   # th0 = 0: k = 3 wraps
    assert _bracket_order(ths, rs, 0.0) == [4]
    rs2 = rs.copy()
    rs2[7:] = [-0.3, 0.4]                                                  # a gentle crossing
    assert _bracket_order(ths, rs2, 0.0) == [7, 4]


SCAN_WITH_MADE_UP_ACCELERATION = """
import math, sys
import numpy as np
import numba
from drake_dock.core.kernels import slide_start as S
assert numba.config.DISABLE_JIT
from drake_dock.core.constraints import SLIDE_START_SCAN as n
th = [2.0 * math.pi * (k / n - 0.5) for k in range(n + 1)]
b_lo, b_hi, a_lo, a_hi = th[37], th[38], th[40], th[41]

def phi(t):
    if t <= b_lo:
        return -1.8
    if t <= b_hi:
        return -1.8 + 2.1 * (t - b_lo) / (b_hi - b_lo)
    if t <= a_lo:
        return 0.3
    if t <= a_hi:
        return 0.3 + (2.0 * math.pi - 0.6) * (t - a_lo) / (a_hi - a_lo)
    return 2.0 * math.pi - 0.3

tried = []

def made_up(P, modes, dirs, i, t, omega, out):
    tried.append(t)
    dirs[i, 0], dirs[i, 1] = math.cos(t), math.sin(t)
    out.at[i, 0], out.at[i, 1] = math.cos(t + phi(t)), math.sin(t + phi(t))
    return S.OK, S._slip_angle(dirs, out.at, i)


rs = [made_up(None, None, np.zeros((1, 2)), 0, t, 0.0,
               S.Outputs(None, np.zeros(1), np.zeros((1, 2))))[1] for t in th]
first = S._nearest_bracket(np.array(th), np.array(rs), 0.0, True)
second = S._nearest_bracket(np.array(th), np.array(rs), 0.0, False)
print(first, second)
S._slip_residual = made_up
del tried[:]
dirs = np.array([[1.0, 0.0]])
out = S.Outputs(None, np.zeros(1), np.zeros((1, 2)))
st, found = S._slide_start_scan(None, None, dirs, 0, 0.0, out)
inside = [t for t in tried if b_lo < t < b_hi or a_lo < t < a_hi]
print(st == S.OK, found, *out.at[0], b_lo + (b_hi - b_lo) * 1.8 / 2.1,
      a_lo < inside[0] < a_hi, any(b_lo < t < b_hi for t in inside))
"""


def test_a_bracket_whose_bisection_ends_on_the_half_turn_gives_way_to_the_next():
    """The scan (`slide_start._slide_start_scan`, run as Python by the debugging path,
    ``NUMBA_DISABLE_JIT=1``, its residual replaced) on a made-up tangential acceleration
    a_t(s(theta)) whose angle from s is phi(theta) (theta0 = 0): -1.8 rad, then crossing zero
    steeply to 0.3 rad over the step from the 37th scanned direction (the nearest crossing,
    but its ends are not both within 90 deg), 0.3 rad, then turning through +180 deg to -0.3
    rad over the step from the 40th (a sign change within 90 deg at both ends), and -0.3 rad
    after. Its brackets are the 40th step, then the 37th; it bisects the 40th first, finds
    a_t against s there, and slides along the 37th step's root, where phi = 0 (closed
    form)."""
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", SCAN_WITH_MADE_UP_ACCELERATION], env=env,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    first, second, ok, found, a0, a1, t_root, fortieth_first, then_37th = out.stdout.split()
    assert (first, second) == ("40", "37")
    assert fortieth_first == then_37th == "True"      # bisected in that order
    assert ok == "True" and found == "True"
    assert [float(a0), float(a1)] == pytest.approx([math.cos(float(t_root)),
                                                    math.sin(float(t_root))], abs=1e-9)

