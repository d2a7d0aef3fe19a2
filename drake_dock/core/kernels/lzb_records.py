"""The records and the law of a compiled LZB impact (`drake_dock.core.kernels.lzb`): the
impact's constants, the couples' phase arrays and the event log as typed records (NamedTuples
that numba passes as structures of arrays and scalars); the nonsmooth law of a couple, apart
from the integration (as Siconos keeps its `MultipleImpactNSL` apart from the integrator): the
loading curve of Eq. (28) and the restitution laws. The rules are stated in
`drake_dock.core.lzb.solve`'s docstring.

The functions take the records whole and read the fields they use at their top: a record still
in use further down holds a reference to each of its arrays, taken and released on every
call."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from drake_dock.core.kernels.copies import copy1

# Phases of a couple (LOCKED: e = 0, held) and event rows.
COMPRESSION, EXPANSION, LOCKED = 0, 1, 2
NORMAL, FRICTION, APPROACH = 0, 1, 2
# Event kinds logged, as codes into KINDS (`drake_dock.core.lzb.state.ImpactEvent`).
KINDS = ("max_compression", "recompression", "end", "re_impact", "lock", "release", "stick",
         "slip", "slip_reversal")
MAXC, RECOMP, END, REIMPACT, LOCK, RELEASE, STICK, SLIP, REVERSAL = range(9)
# Restitution laws, as codes into LAW_NAMES.
LAW_NAMES = ("paper", "mono", "bi")


# The records -------------------------------------------------------------------------------
class ImpactConstants(NamedTuple):
    """The constants of one impact (nondimensional, `drake_dock.core.lzb.solve`): s couples
    and nu force components (s, or 3 s with friction); the Delassus matrix G (nu, nu) in
    contact space; per couple the stiffness kappa and exponent eta of Eq. (28), the energetic
    restitution e of Eq. (36), the sliding and static friction mu and mu_s of Eq. (27);
    ``friction``; ``law``, a code into LAW_NAMES; ``settle``, the relative velocity below
    which the impact has ended and the sliding speed at which a couple has come to rest; the
    integration's rtol, atol and step budget; ``imp_scale`` (m_s v_s), the impulses' unit."""
    s: int
    nu: int
    G: np.ndarray
    kappa: np.ndarray
    eta: np.ndarray
    e: np.ndarray
    mu: np.ndarray
    mu_s: np.ndarray
    friction: bool
    law: int
    settle: float
    rtol: float
    atol: float
    max_steps: int
    imp_scale: float


class Phases(NamedTuple):
    """The couples' phase arrays, changed in place by the events: the phase, ``sep``
    (unloaded and separating), ``rate`` (dx/dtau = -rate u_n), ``x_end`` (the indentation at
    which expansion ends), ``stuck``, ``slip_dir`` (s, 2), the compression work ``wc`` summed
    over episodes, ``e_start`` (the stored energy when the current compression began) and
    ``wc_open`` (the compression work since the contact began)."""
    phase: np.ndarray
    sep: np.ndarray
    rate: np.ndarray
    x_end: np.ndarray
    stuck: np.ndarray
    slip_dir: np.ndarray
    wc: np.ndarray
    e_start: np.ndarray
    wc_open: np.ndarray


class EventLog(NamedTuple):
    """The events applied, as `ImpactEvent`: the first n entries of the total normal impulse,
    the kind (a code into KINDS) and the couple; n an int64."""
    impulse: np.ndarray
    kind: np.ndarray
    couple: np.ndarray
    n: int


def new_phases(s: int) -> Phases:
    """The phase arrays at an impact's start: every couple in compression, sliding."""
    return Phases(np.zeros(s, np.int64), np.zeros(s, np.bool_), np.ones(s), np.zeros(s),
                  np.zeros(s, np.bool_), np.zeros((s, 2)), np.zeros(s), np.zeros(s),
                  np.zeros(s))


# The law ------------------------------------------------------------------------------------
@njit(cache=True)
def stored_energy(kappa, eta, x):
    """The energy stored at indentation x on the loading curve: Eq. (28) integrated,
    E = kappa x^(eta+1) / (eta+1)."""
    return kappa * max(x, 0.0) ** (eta + 1.0) / (eta + 1.0)


@njit(cache=True)
def indentation(kappa, eta, E):
    """The indentation at which the loading curve stores the energy E (inverse of
    `stored_energy`)."""
    return ((eta + 1.0) * max(E, 0.0) / kappa) ** (1.0 / (eta + 1.0))


@njit(cache=True)
def unloading(law, kappa, eta, e, E, work, wc_open):
    """How a couple expands after a maximal compression at stored energy E, W = ``work`` the
    work of this compression and W_c = ``wc_open`` that since its contact began, under the
    restitution law ``law`` (a code into LAW_NAMES): (x_start, x_end, rate), from indentation
    x_start (NaN: where it is) at dx/dtau = -rate u_n until x reaches x_end.
    - paper, Eq. (54): E' = E - (1 - e^2) W; x jumps to the loading curve at E' and unloads on
      it to zero;
    - mono: unloads on the loading curve; ends when (1 - e^2) W_c is left (W_r = e^2 W_c,
      Eq. 36);
    - bi: a stiffer unloading branch, dE = -(1/e^2) delta dP: rate 1/e^2, to zero."""
    if law == 0:
        return indentation(kappa, eta, E - (1.0 - e * e) * work), 0.0, 1.0
    if law == 1:
        return np.nan, indentation(kappa, eta, (1.0 - e * e) * wc_open), 1.0
    return np.nan, 0.0, 1.0 / (e * e)


@njit(cache=True)
def any_held(ph):
    """Whether a couple is stuck or locked."""
    for j in range(len(ph.phase)):
        if ph.stuck[j] or ph.phase[j] == LOCKED:
            return True
    return False


@njit(cache=True)
def any_locked(ph):
    for j in range(len(ph.phase)):
        if ph.phase[j] == LOCKED:
            return True
    return False


@njit(cache=True)
def set_phase(ph, j, phase, rate):
    ph.phase[j] = phase
    ph.rate[j] = 0.0 if phase == LOCKED else rate



@njit(cache=True)
def log_event(log, impulse, kind, j):
    """``log`` with the event (impulse, kind, j) appended, its arrays doubled when full."""
    ev_imp, ev_kind, ev_couple, n = log
    if n >= len(ev_kind):
        m = 2 * len(ev_kind)
        a, b, c = np.empty(m), np.empty(m, np.int64), np.empty(m, np.int64)
        copy1(a[:n], ev_imp[:n])
        copy1(b[:n], ev_kind[:n])
        copy1(c[:n], ev_couple[:n])
        ev_imp, ev_kind, ev_couple = a, b, c
    ev_imp[n], ev_kind[n], ev_couple[n] = impulse, kind, j
    return EventLog(ev_imp, ev_kind, ev_couple, n + 1)


