"""Acceleration-level contact constraints with Coulomb friction (Eq. 48-52), plain numpy.

For the couples of the contact set, with generalized mass M, free acceleration a0 = M^-1 tau
(everything but the contact forces) and, per couple, the directions Wn = W^3, Wt = [W^1, W^2]
of Eq. (11) and the velocity-product terms b (so that g'' = Wn.v' + bn and the tangential
relative acceleration is Wt^T v' + bt), each couple takes one mode:

- ``stick``:  g'' = 0 and Wt^T v' + bt = 0, force (lam_n, lam_t) inside the static cone
  |lam_t| <= mu_s lam_n (Eq. 51);
- ``slide``:  g'' = 0, lam_t = -mu lam_n s with s the unit sliding direction (Eq. 50), lam_n >= 0;
- ``detach``: no force, g'' + 2 omega g' + omega^2 g >= 0.

M v' = tau + sum (Wn lam_n + Wt lam_t). The normal constraint is stabilised (Baumgarte):
g'' + 2 omega g' + omega^2 g = 0, so that the gap's drift decays instead of growing (omega = 0
gives Eq. 52 as printed). The sticking condition a_t = 0 is not stabilised: its drift is a
velocity (of the order of the integration error) and is removed at every mode change by the
contact system's velocity projection, while a feedback term would bias the friction force.

The normal complementarity is stated on that stabilised row on both sides: lam_n >= 0 holding
it at zero, or no force with it >= 0. One couple of normal inverse mass A > 0 then always has
exactly one consistent normal mode (lam_n = -(its free value) / A). A detached couple tested on
g'' alone would leave a window, 0 < g'' + 2 omega g' + omega^2 g < 2 omega g' + omega^2 g, where
both modes fail: a couple whose gap has drifted open by g as it unloads (at omega = 20 rad/s a
drift of 1e-8 m opens 4e-6 m/s^2, past ``TIE_RTOL`` of the 1 m/s^2 floor). Once detached, its
drift is watched by its gap witness.

`select_contact_modes` enumerates the modes of the contact set (3^k choices, k <= 8) and keeps the
consistent ones, within ``rtol`` of the force and acceleration scales (each with a floor of
1 N and 1 m/s^2). At a transition round-off can leave every mode just outside ``rtol``: then the
modes consistent within ``TIE_RTOL`` (1e-6) of those scales are taken, with the same
preferences. None consistent even so, or several with different accelerations that differ in
their normal modes, is the Painleve paradox of a rigid model: it raises `PainleveError` with the
time and the couples. Several consistent choices that differ only in stick against
start-of-sliding (possible when mu_s > mu) are resolved by preferring stick: a couple at rest
stays at rest.

A start of sliding takes the direction along which the couple's tangential acceleration lies:
a fixed point, then, where it does not converge, a scan of one couple's direction or a grid
and Newton's method for two (`_slide_start`). Two couples sticking between the same two bodies
are fixed up to a squeeze, chosen to keep them in their cones (`drake_dock.core.squeeze`).
"""
from __future__ import annotations

import dataclasses
import functools
import itertools
import math

import numpy as np

from drake_dock.core.squeeze import squeezed
from drake_dock.errors import (NumericalError, PainleveError, PainleveInconsistency,
                               SingularContactError)

STICK, SLIDE, DETACH = "stick", "slide", "detach"
MAX_ENUMERATED = 8
TIE_RTOL = 1e-6     # consistency accepted at a transition when none holds at rtol
SLIDE_START_ITER = 200   # fixed-point iterations for the direction of a start of sliding
SLIDE_START_SCAN = 72    # directions scanned when the fixed point fails for one couple
SLIDE_START_GRID = 24    # per couple, when it fails for two: a grid, then Newton


@dataclasses.dataclass
class ContactRow:
    """One couple of the contact set, in the generalized coordinates."""

    name: str
    Wn: np.ndarray        # (nv,)
    Wt: np.ndarray        # (nv, 2)
    bn: float
    bt: np.ndarray        # (2,)
    gap: float
    vn: float
    vt: np.ndarray        # (2,)
    mu: float
    mu_s: float


@dataclasses.dataclass
class ContactSolution:
    modes: tuple
    dirs: list            # unit sliding direction (2,) per couple, or None
    vdot: np.ndarray
    lam_n: np.ndarray     # (k,)
    lam_t: np.ndarray     # (k, 2)
    generalized_force: np.ndarray  # sum Wn lam_n + Wt lam_t
    rows: list

    @functools.cached_property
    def gddot(self) -> np.ndarray:
        """(k,) g'' (without the stabilisation terms); computed when asked (the mode selection
        needs it, a derivative evaluation does not)."""
        return np.array([r.Wn @ self.vdot + r.bn for r in self.rows])

    @functools.cached_property
    def at(self) -> np.ndarray:
        """(k, 2) tangential relative accelerations."""
        return np.array([r.Wt.T @ self.vdot + r.bt for r in self.rows]).reshape(-1, 2)

    def power_lost_to_friction(self, rows):
        """sum -lam_t . v_t over the couples (>= 0 for sliding, 0 for sticking)."""
        return friction_power(self.lam_t, [r.vt for r in rows])


def friction_power(lam_t, vt) -> float:
    """sum -lam_t . v_t over the couples, their tangential forces and velocities (k, 2)."""
    return float(sum(-(lt @ v) for lt, v in zip(lam_t, vt)))


def stabilised(x, vn, gap, omega):
    """x + 2 omega g' + omega^2 g: the Baumgarte-stabilised normal row (Eq. 52), with x = g''
    or its velocity-product term bn."""
    return x + 2 * omega * vn + omega ** 2 * gap


def solve_given_modes(Minv, a0, rows, modes, dirs, *, omega=0.0, time=None) -> ContactSolution:
    """Contact forces and accelerations for the given modes (``dirs[i]`` the sliding direction
    of a sliding couple). Raises `SingularContactError` if the constraint matrix is singular."""
    cols, cons, rhs = [], [], []
    for r, m, s in zip(rows, modes, dirs):
        if m == STICK:
            cols += [r.Wn, r.Wt[:, 0], r.Wt[:, 1]]
            cons += [r.Wn, r.Wt[:, 0], r.Wt[:, 1]]
            rhs += [stabilised(r.bn, r.vn, r.gap, omega), r.bt[0], r.bt[1]]
        elif m == SLIDE:
            cols.append(r.Wn - r.mu * (r.Wt @ s))
            cons.append(r.Wn)
            rhs.append(stabilised(r.bn, r.vn, r.gap, omega))
    vdot = a0
    lam = np.zeros(0)
    Cf = None
    if cols:
        C = np.array(cols).T
        D = np.array(cons).T
        MinvC = Minv @ C
        A = D.T @ MinvC
        b = -(np.asarray(rhs) + D.T @ a0)
        # Singular (redundant or degenerate rows) when the Hadamard ratio |det A| / prod of
        # its row norms, a scale-free measure in [0, 1] that vanishes with the smallest
        # singular value of the row-scaled matrix, is below 1e-12 (an SVD per evaluation
        # cost more than the rest of the solve).
        rn = np.sqrt(np.einsum("ij,ij->i", A, A))
        ratio = abs(np.linalg.det(A)) / np.prod(rn) if np.all(rn > 0) else 0.0
        if np.isfinite(ratio) and ratio > 1e-12:
            lam = np.linalg.solve(A, b)
        else:
            finite = bool(np.all(np.isfinite(A)))
            cond = np.linalg.cond(A) if finite else np.nan
            # Redundant constraints (a body resting on several sticking couples is statically
            # indeterminate): the minimum-norm forces, if the equations are consistent. The
            # Baumgarte terms pull each couple's own drift to zero, so redundant rows disagree
            # by as much as those terms: a residual within them is consistent.
            lam = np.linalg.lstsq(A, b, rcond=1e-10)[0] if finite else None
            soft = math.sqrt(sum((2 * omega * r.vn + omega ** 2 * r.gap) ** 2
                                 for r, m in zip(rows, modes) if m != DETACH))
            if lam is None or np.linalg.norm(A @ lam - b) > (1e-8 * (1.0 + np.linalg.norm(b))
                                                             + soft):
                raise SingularContactError(
                    f"contact constraint equations singular and inconsistent (cond = "
                    f"{cond:.3e}) for modes {modes}", time=time,
                    couples=[r.name for r, m in zip(rows, modes) if m != DETACH])
            # Two couples sticking between two bodies: the squeeze that keeps them in their
            # cones (Eq. 51; `drake_dock.core.squeeze`).
            offsets, mus, j = [], [], 0
            for r, m in zip(rows, modes):
                if m == STICK:
                    offsets.append(j)
                    mus.append(r.mu_s)
                j += 3 if m == STICK else (1 if m == SLIDE else 0)
            lam = squeezed(lam, A, C, np.array(offsets, dtype=np.int64), np.array(mus))
        vdot = a0 + MinvC @ lam
        Cf = C @ lam
    k = len(rows)
    lam_n, lam_t = np.zeros(k), np.zeros((k, 2))
    j = 0
    for i, (r, m, s) in enumerate(zip(rows, modes, dirs)):
        if m == STICK:
            lam_n[i], lam_t[i] = lam[j], lam[j + 1:j + 3]
            j += 3
        elif m == SLIDE:
            lam_n[i] = lam[j]
            lam_t[i] = -r.mu * lam[j] * np.asarray(s)
            j += 1
    return ContactSolution(tuple(modes), list(dirs), vdot, lam_n, lam_t,
                           Cf if Cf is not None else np.zeros_like(a0), list(rows))


def _slide_start(Minv, a0, rows, modes, dirs, i_start, omega, time,
                 max_iter=SLIDE_START_ITER):
    """Sliding directions of couples that start to slide from rest: friction opposes the
    tangential relative acceleration it produces (fixed point s = a_t/|a_t|)."""
    dirs = list(dirs)
    sol = None
    for _ in range(max_iter):
        sol = solve_given_modes(Minv, a0, rows, modes, dirs, omega=omega, time=time)
        change = 0.0
        for i in i_start:
            a = sol.at[i]
            na = math.hypot(a[0], a[1])
            if na == 0.0:
                return sol, False
            new = a / na
            change = max(change, float(np.abs(new - dirs[i]).max()))
            dirs[i] = new
        if change < 1e-13:
            break
    sol = solve_given_modes(Minv, a0, rows, modes, dirs, omega=omega, time=time)
    ok = all(sol.at[i] @ dirs[i] > 0 for i in i_start)
    if not ok and len(i_start) == 1:
        return _slide_start_scan(Minv, a0, rows, modes, dirs, i_start[0], omega, time)
    if not ok and len(i_start) == 2:
        return _slide_start_grid(Minv, a0, rows, modes, dirs, i_start, omega, time)
    return sol, ok


def slip_angle(s, a):
    """The angle from the unit direction s to the vector a (0 where a lies along s)."""
    return math.atan2(s[0] * a[1] - s[1] * a[0], s[0] * a[0] + s[1] * a[1])


def _slide_start_scan(Minv, a0, rows, modes, dirs, i, omega, time):
    """The direction of couple i starting to slide where the fixed point does not converge:
    a direction s(theta) along which its tangential acceleration lies, bracketed on
    `SLIDE_START_SCAN` angles around the fixed point's last direction theta0 and bisected
    (the bracket nearest theta0 whose ends lie within 90 deg of s; failing that, the nearest
    where the angle crosses zero rather than +-180 deg, `scan_brackets`: next to the stick-slip
    transition a_t is small and turns fast with theta); (sol, True), or (sol, False) if there
    is none."""
    dirs = list(dirs)
    th0 = math.atan2(dirs[i][1], dirs[i][0])

    def residual(th):
        dirs[i] = np.array([math.cos(th), math.sin(th)])
        sol = solve_given_modes(Minv, a0, rows, modes, dirs, omega=omega, time=time)
        return slip_angle(dirs[i], sol.at[i]), sol

    n = SLIDE_START_SCAN
    ths = [th0 + 2.0 * math.pi * (k / n - 0.5) for k in range(n + 1)]
    rs = [residual(t)[0] for t in ths]
    sol = None
    for k in scan_brackets(ths, rs, th0):
        lo, hi, flo = ths[k], ths[k + 1], rs[k]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            fm = residual(mid)[0]
            if fm * flo > 0:
                lo, flo = mid, fm
            else:
                hi = mid
        sol = residual(0.5 * (lo + hi))[1]
        if sol.at[i] @ dirs[i] > 0:
            return sol, True
    return (residual(th0)[1] if sol is None else sol), False


def scan_brackets(ths, rs, th0) -> list:
    """The brackets k (ths[k], ths[k + 1]) of the slide-start scan to bisect, in order: the
    one nearest th0 where the angle changes sign with both ends within 90 deg, then the one
    nearest th0 where it changes sign by less than 180 deg (crossing zero, not +-180 deg)."""
    out = []
    for near in (lambda a, b: max(abs(a), abs(b)) < 0.5 * math.pi,
                 lambda a, b: abs(a - b) < math.pi):
        ks = [k for k in range(len(rs) - 1) if rs[k] * rs[k + 1] <= 0 and near(rs[k], rs[k + 1])]
        if ks:
            k = min(ks, key=lambda k: abs(0.5 * (ths[k] + ths[k + 1]) - th0))
            if k not in out:
                out.append(k)
    return out


def _slide_start_grid(Minv, a0, rows, modes, dirs, i_start, omega, time):
    """The directions of two couples starting to slide where the fixed point does not converge:
    where each couple's tangential acceleration lies along its direction. The point of a
    `SLIDE_START_GRID`^2 grid of the two angles around the fixed point's last directions with
    the least angles between directions and accelerations starts Newton's method on s x a_t
    (smooth where a_t vanishes, unlike the angle; forward-difference Jacobian, steps halved
    while it does not fall). (sol, True) at a root with a_t along s, or with a_t below 1e-6 of
    the acceleration scale (both couples at the stick-slip transition: forces on the cones'
    edges), else (sol, False)."""
    dirs = list(dirs)
    th0 = np.array([math.atan2(dirs[i][1], dirs[i][0]) for i in i_start])

    def solve(th):
        for i, t in zip(i_start, th):
            dirs[i] = np.array([math.cos(t), math.sin(t)])
        return solve_given_modes(Minv, a0, rows, modes, dirs, omega=omega, time=time)

    def cross(th):
        sol = solve(th)
        return np.array([dirs[i][0] * sol.at[i][1] - dirs[i][1] * sol.at[i][0]
                         for i in i_start]), sol

    n = SLIDE_START_GRID
    steps = 2.0 * math.pi * (np.arange(n) / n - 0.5)
    best, th = np.inf, th0
    for d0 in steps:
        for d1 in steps:
            t = th0 + np.array([d0, d1])
            sol = solve(t)
            r = sum(abs(slip_angle(dirs[i], sol.at[i])) for i in i_start)
            if r < best:
                best, th = r, t
    r, sol = cross(th)
    for _ in range(40):
        J = np.empty((2, 2))
        for c in range(2):
            e = np.zeros(2)
            e[c] = 1e-7
            J[:, c] = (cross(th + e)[0] - r) / 1e-7
        det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
        if not (math.isfinite(det) and det != 0.0):
            break
        step = np.array([J[0, 1] * r[1] - J[1, 1] * r[0], J[1, 0] * r[0] - J[0, 0] * r[1]]) / det
        for _ in range(30):
            r_new, sol_new = cross(th + step)
            if np.abs(r_new).sum() < np.abs(r).sum():
                th, r, sol = th + step, r_new, sol_new
                break
            step = 0.5 * step
        else:
            break
    r, sol = cross(th)
    small = 1e-6 * (1.0 + float(np.abs(sol.vdot).max()))
    ok = all(math.hypot(*sol.at[i]) <= small
             or (abs(ri) <= 1e-9 * math.hypot(*sol.at[i]) and sol.at[i] @ dirs[i] > 0)
             for i, ri in zip(i_start, r))
    return sol, bool(ok)


def stabilised_gddot(sol, rows, omega) -> np.ndarray:
    """(k,) g'' + 2 omega g' + omega^2 g: the normal row the contact modes hold at zero
    (Eq. 52, stabilised)."""
    return np.array([stabilised(g, r.vn, r.gap, omega) for g, r in zip(sol.gddot, rows)])


def _consistent(sol, rows, omega, tol_f, tol_a):
    """Complementarity on the stabilised normal row (lambda_n >= 0 in contact, Eq. 50-51;
    g'' + 2 omega g' + omega^2 g >= 0 detached, Eq. 52) and the static cone (Eq. 51), within
    ``tol_f`` (N) and ``tol_a`` (m/s^2)."""
    stab = stabilised_gddot(sol, rows, omega)
    for i, (r, m) in enumerate(zip(rows, sol.modes)):
        if m == DETACH:
            if stab[i] < -tol_a:
                return False
        else:
            if sol.lam_n[i] < -tol_f:
                return False
            if m == STICK and math.hypot(*sol.lam_t[i]) > r.mu_s * sol.lam_n[i] + tol_f:
                return False
    return True


def select_contact_modes(Minv, a0, rows, *, v_slip=1e-6, omega=0.0, time=None, rtol=1e-9,
                         avoid=None):
    """One consistent choice of modes for the contact set (see the module docstring).

    A couple whose sliding speed exceeds ``v_slip`` slides in its direction of motion (or
    detaches); one at rest may stick, start to slide or detach. ``avoid[i]`` lists modes that
    couple i is leaving (its witness has just crossed zero): at a tie, where a mode it leaves
    is still consistent within round-off, another consistent mode is taken."""
    k = len(rows)
    names = [r.name for r in rows]
    if k == 0:
        return solve_given_modes(Minv, a0, rows, (), [], omega=omega, time=time)
    if k > MAX_ENUMERATED:
        raise NumericalError(f"{k} couples in contact at once; mode enumeration is limited to "
                             f"{MAX_ENUMERATED}", time=time, couples=names)
    options, moving_dir = [], []
    for r in rows:
        speed = math.hypot(r.vt[0], r.vt[1])
        if speed > v_slip:
            options.append((SLIDE, DETACH))
            moving_dir.append(np.asarray(r.vt) / speed)
        else:
            options.append((STICK, SLIDE, DETACH))
            moving_dir.append(None)
    # Force and acceleration scales for the consistency tolerances.
    free = solve_given_modes(Minv, a0, rows, (DETACH,) * k, [None] * k, omega=omega, time=time)
    a_scale = 1.0 + float(np.abs(free.gddot).max()) + float(np.abs(free.at).max())
    found, near = [], []
    for modes in itertools.product(*options):
        dirs = [moving_dir[i] if m == SLIDE and moving_dir[i] is not None else None
                for i, m in enumerate(modes)]
        starting = [i for i, m in enumerate(modes) if m == SLIDE and moving_dir[i] is None]
        try:
            if starting:
                # Start from the direction opposite to the sticking force (or the free
                # tangential acceleration).
                guess = solve_given_modes(
                    Minv, a0, rows, [STICK if i in starting else m for i, m in enumerate(modes)],
                    [d if d is not None else np.zeros(2) for d in dirs], omega=omega, time=time)
                for i in starting:
                    g = -guess.lam_t[i]
                    if math.hypot(*g) == 0.0:
                        g = free.at[i]
                    ng = math.hypot(*g)
                    dirs[i] = g / ng if ng > 0 else np.array([1.0, 0.0])
                sol, ok = _slide_start(Minv, a0, rows, modes, dirs, starting, omega, time)
                if not ok:
                    continue
            else:
                sol = solve_given_modes(Minv, a0, rows, modes, dirs, omega=omega, time=time)
        except SingularContactError:
            continue
        f_scale = 1.0 + float(np.abs(sol.lam_n).max())
        if _consistent(sol, rows, omega, rtol * f_scale, rtol * a_scale):
            found.append(sol)
        elif _consistent(sol, rows, omega, TIE_RTOL * f_scale, TIE_RTOL * a_scale):
            near.append(sol)
    found = found or near
    if not found:
        raise PainleveInconsistency(
            "no consistent contact mode (Painleve inconsistency: the rigid model with this "
            "friction has no solution)", time=time, couples=names)
    # Preference among consistent choices: more sticking couples, then more couples in contact.
    avoid = avoid or [()] * k
    found.sort(key=lambda s: (sum(m in a for m, a in zip(s.modes, avoid)),
                              -s.modes.count(STICK), s.modes.count(DETACH)))
    best = found[0]
    v_scale = 1.0 + float(np.abs(best.vdot).max())
    for other in found[1:]:
        if np.abs(other.vdot - best.vdot).max() <= 1e-6 * v_scale:
            continue
        normal = [m == DETACH for m in best.modes] != [m == DETACH for m in other.modes]
        if normal:
            raise PainleveError(
                f"several consistent contact modes with different accelerations "
                f"({best.modes} and {other.modes}): Painleve indeterminacy", time=time,
                couples=names)
    return best
