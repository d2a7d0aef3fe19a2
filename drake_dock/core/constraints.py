"""Acceleration-level contact constraints with Coulomb friction (Eq. 48-52): the law, the
contact set's records (`ContactRow`, `ContactSolution`) and their constants. The solve for given
modes and the mode selection are the compiled `drake_dock.core.kernels.constraints`
(`solve_given_modes`, `select_contact_modes`); this module states what they compute.

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

The mode selection enumerates the modes of the contact set (3^k choices, k <= 8) and keeps the
consistent ones, within ``rtol`` of the force and acceleration scales (each with a floor of
1 N and 1 m/s^2). At a transition round-off can leave every mode just outside ``rtol``: then the
modes consistent within ``TIE_RTOL`` (1e-6) of those scales are taken, with the same
preferences. None consistent even so, or several with different accelerations that differ in
their normal modes, is the Painleve paradox of a rigid model: it raises `PainleveError` with the
time and the couples. Several consistent choices that differ only in stick against
start-of-sliding (possible when mu_s > mu) are resolved by preferring stick: a couple at rest
stays at rest.

A start of sliding takes the direction along which the couple's tangential acceleration lies:
a fixed point s = a_t/|a_t| (``SLIDE_START_ITER`` iterations at most), accepted where each
starting couple's a_t lies along its s; where it does not, a scan of one couple's direction
(accepting a bisected root with a_t . s > 0) or a grid and Newton's method for two (accepting
a root with a_t along s, or a_t below 1e-6 of the acceleration scale); three or more couples
whose fixed point leaves an a_t off its s have no start of sliding
(`drake_dock.core.kernels.slide_start`).

Two couples sticking between the same two bodies are fixed up to a squeeze, chosen to keep
them in their cones (`drake_dock.core.squeeze`).
"""
from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

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


def slip_angle(s, a):
    """The angle from the unit direction s to the vector a (0 where a lies along s)."""
    return math.atan2(s[0] * a[1] - s[1] * a[0], s[0] * a[0] + s[1] * a[1])


def stabilised_gddot(sol, rows, omega) -> np.ndarray:
    """(k,) g'' + 2 omega g' + omega^2 g: the normal row the contact modes hold at zero
    (Eq. 52, stabilised)."""
    return np.array([stabilised(g, r.vn, r.gap, omega) for g, r in zip(sol.gddot, rows)])
