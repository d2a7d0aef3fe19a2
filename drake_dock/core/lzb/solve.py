"""LZB multiple impacts with Coulomb friction and energetic restitution (Sect. 6, Eq. 26-36,
53-54), for any multibody system at a fixed configuration, without Drake: the problem checked
and scaled here, integrated by the compiled kernel `drake_dock.core.kernels.lzb`.

The model
---------
During an impact the configuration is frozen; couple j carries the normal force law of Eq. (28),
lambda_j = K_j delta_j^eta_j, so that its stored energy is E_j = K_j delta_j^(eta_j+1)/(eta_j+1)
and the distributing law (29) dP_j / dP_i = lambda_j / lambda_i holds at every instant. The
impulse-domain equations (35),

    M dv = sum_j (W^3_j dP^3_j + W^1_j dP^1_j + W^2_j dP^2_j),    dE_j = -v^3_j dP^3_j  (30-31)

are integrated here with a time-like parameter tau, dP*/dtau = lambda* > 0, instead of P*
itself: the trajectory is the same, but tau has no singularity at zero stored energy (which
Eq. 33-34 resolve for P*: the solver reproduces their limit, see the tests) nor between
sub-impacts when no couple is loaded. Everything is written in contact space: with
W = [Wn, Wt] and the Delassus matrix G = W^T M^-1 W, the relative velocities u = W^T v obey
du/dtau = G lambda, and v+ = v- + M^-1 W P at the end.

Phases
------
Each couple has an effective indentation x_j >= 0 and a phase. The configuration is frozen,
so there is no gap: a couple whose indentation is zero is unloaded, and it loads again as soon
as it approaches again (u_n < 0). This is the continuous-time limit of LZB that Siconos's
`MultipleImpact` also converges to; `drake_dock.core.lzb.limit` integrates it on ball chains in
physical time, as the tests' reference.

- Compression: dx/dtau = -u_n (x does not fall below zero while unloaded).
- Maximal compression (u_n = 0 while loaded): the work of this compression,
  W = E - E_start (E_start: the stored energy when it began), enters W_c (Eq. 36) and the law
  turns the couple to expansion.
- Expansion, then either the end (x reaches x_end: the couple is unloaded, its remaining
  energy lost), or a re-compression when u_n turns negative again before the end: compression
  resumes on the loading curve from the energy stored then (E_start = E).
- A couple at u_n = 0 within round-off after an event takes the phase its motion starts with.

The laws, at each maximal compression (`drake_dock.core.kernels.lzb_records.unloading`):

- ``"paper"``, Eq. (54): E' = E - (1 - e^2) W, so x jumps to the loading curve at E' and
  unloads on it to x_end = 0; over a contact's compressions the work returned is e^2 times
  the work received (Eq. 36).
- ``"mono"``: the stored energy is released on the loading curve; the contact ends when
  (1 - e^2) W_c is left, W_c being the compression work since the contact began, at
  x_end = ((eta+1)(1 - e^2) W_c / K)^(1/(eta+1)); that energy is dropped.
- ``"bi"``: during expansion dE = -(1/e^2) delta dP, i.e. dx/dtau = -u_n/e^2 (a stiffer
  unloading branch), to x_end = 0; a re-compression takes dx/dtau = -u_n again.

Repeated impacts
----------------
- e = 0: at its maximal compression a couple loses its stored energy and is locked: a
  constraint force rate lambda_n >= 0 keeps u_n = 0 (the limit e -> 0 of every law, which
  would otherwise re-impact without end). It is released, and separates, when lambda_n
  reaches zero, or at once where an event of another couple leaves it pulling. A plastic
  chain thus ends with the balls moving together.
- Small e: the couples can re-compress many times with ever smaller amplitudes. The impact
  ends when no couple approaches faster, nor could the stored energy move one faster, than
  ``rtol`` times the largest initial approach speed (the bodies have settled).

With one couple the three laws give the same post-impact velocity; with several they differ.

Friction, Eq. (27) and (53): a loaded couple slides with dP^t = -mu dP^3 u_t/|u_t|, or sticks
(u_t = 0 held by the tangential impulse rate that keeps it zero) while that rate stays inside
the static cone mu_s dP^3. Slip-to-stick, stick-to-slip and slip reversal are located events.
The couples at rest when they load (at the impact's start, a re-impact, a sliding couple come
to rest) take stick or slip jointly: all stick if the tangential forces that keep them at rest
lie in their static cones, otherwise the one furthest outside slips and the rest are tested
again.

Numerics: the compiled kernel `drake_dock.core.kernels.lzb`, one call per impact: the
Dormand-Prince 5(4) pair with error control by ``rtol`` (atol 1e-2 of it), every phase change
located on its dense output and the integration restarted there. The normal event functions
are also sampled inside each step, so that u_n crossing zero twice within one step (a brief
separation between two compressions) is not missed. The problem is nondimensionalised
(velocity scale: the largest initial relative velocity; mass scale: the smallest effective mass
of a couple; stiffness scale: the largest K), so all thresholds are relative to the impact's
scale and scaling every K by the same factor leaves the result unchanged.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from drake_dock.core.kernels import lzb as kernel
from drake_dock.core.kernels.lzb_records import KINDS, LAW_NAMES, ImpactConstants, new_phases
from drake_dock.core.lzb.inputs import check_inputs, per_couple
from drake_dock.core.lzb.state import ImpactEvent, StateLayout
from drake_dock.errors import NumericalError

__all__ = ["LAWS", "ImpactResult", "solve_lzb", "check_inputs", "per_couple"]

LAWS = LAW_NAMES                    # the restitution laws ("paper", "mono", "bi")

SEPARATING_RTOL = 1e-6              # normal velocities up to this fraction of the largest are
                                    # a couple at rest (`drake_dock.core.hybrid.CLOSED_RTOL`)


@dataclasses.dataclass
class ImpactResult:
    """Outcome of `solve_lzb`. Impulses in N s, works and energies in J."""

    v_plus: np.ndarray             # post-impact generalized velocity (n,)
    normal_impulse: np.ndarray     # P^3 per couple (s,)
    tangential_impulse: np.ndarray  # (P^1, P^2) per couple (s, 2)
    compression_work: np.ndarray   # W_c per couple, summed over its contact episodes (s,)
    restitution_work: np.ndarray   # W_r per couple (s,)
    friction_loss: np.ndarray      # energy dissipated by friction per couple (s,)
    steps: int                     # accepted integration steps
    events: list                   # ImpactEvent log
    kinetic_energy_minus: float
    kinetic_energy_plus: float
    impulse_history: np.ndarray = None  # normal impulses P^3 (N s) after each accepted step


def solve_lzb(M, Wn, v_minus, stiffness, eta, restitution, *, Wt=None, mu=0.0, mu_s=None,
              law="paper", initial_energy=None, rtol=1e-10,
              max_steps=200_000) -> ImpactResult:
    """Solves a (multiple) impact by the LZB method at a fixed configuration.

    Parameters
    ----------
    M : (n, n) generalized mass matrix, symmetric positive definite.
    Wn : (n, s) normal directions W^3 of the s couples (Eq. 11): Wn.T @ v is the normal relative
        velocity, negative when approaching.
    v_minus : (n,) pre-impact generalized velocity.
    stiffness, eta, restitution : per couple (scalars broadcast): K_j and eta_j of Eq. (28) and
        the energetic coefficient of restitution e_j of Eq. (36), 0 <= e <= 1.
    Wt : (n, 2s) tangential directions W^1, W^2 of each couple (columns 2j, 2j+1), or None for
        frictionless couples.
    mu, mu_s : sliding and static friction coefficients per couple (mu_s defaults to mu).
    law : "paper" (Eq. 54), "mono" or "bi"; see the module docstring.
    initial_energy : stored energy E_j(t^-) per couple (default zero).
    rtol : relative accuracy of the impulse-domain integration.
    max_steps : the integration's step budget.

    Returns an `ImpactResult`. Raises ValueError naming the argument for degenerate input (M not
    SPD, wrong shapes, non-finite values, a couple already separating) and NumericalError when
    the impact does not end within ``max_steps``.
    """
    M, L, Wn, v, Wt, n, s = check_inputs(M, Wn, v_minus, Wt)
    if law not in LAWS:
        raise ValueError(f"law: expected one of {LAWS}, got {law!r}")
    if not 1e-14 <= rtol <= 1e-2:
        raise ValueError(f"rtol: expected 1e-14 <= rtol <= 1e-2, got {rtol}")
    K = per_couple("stiffness", stiffness, s, positive=True)
    eta_ = per_couple("eta", eta, s, positive=True)
    e = per_couple("restitution", restitution, s, lo=0.0, hi=1.0)
    mu_ = per_couple("mu", mu, s, lo=0.0)
    mu_s_ = mu_ if mu_s is None else per_couple("mu_s", mu_s, s, lo=0.0)
    E0 = np.zeros(s) if initial_energy is None else \
        per_couple("initial_energy", initial_energy, s, lo=0.0)
    friction = Wt is not None and np.any(mu_ > 0)
    W = Wn if Wt is None else np.concatenate([Wn, Wt], axis=1)
    # M^-1 W by the Cholesky factor; Delassus matrix G = W^T M^-1 W.
    MinvW = np.linalg.solve(L.T, np.linalg.solve(L, W))
    G = W.T @ MinvW
    u_minus = W.T @ v
    if Wt is None:   # contact space with zero tangential directions keeps one code path
        G = np.pad(G, ((0, 2 * s), (0, 2 * s)))
        u_minus = np.concatenate([u_minus, np.zeros(2 * s)])
        MinvW = np.pad(MinvW, ((0, 0), (0, 2 * s)))
    KE_minus = 0.5 * v @ M @ v
    # Scales: velocity v_s, mass m_s (smallest effective mass of a couple), stiffness K_ref.
    m_s = 1.0 / np.max(np.diag(G)[:s])
    k_ref = int(np.argmax(K))
    v_s = max(np.abs(u_minus).max(), np.sqrt(2.0 * E0.max() / m_s) if E0.max() > 0 else 0.0)
    empty = ImpactResult(v.copy(), np.zeros(s), np.zeros((s, 2)), np.zeros(s), np.zeros(s),
                         np.zeros(s), 0, [], KE_minus, KE_minus)
    if v_s == 0.0:
        return empty
    un0 = u_minus[:s]
    # A couple in contact may separate at round-off speed when another one is hit: up to
    # SEPARATING_RTOL of the velocity scale it takes part, with zero indentation, and loads
    # again only if the impact makes it approach (the caller's impact-set rule).
    if np.any(un0 > SEPARATING_RTOL * v_s):
        j = np.flatnonzero(un0 > SEPARATING_RTOL * v_s)
        raise ValueError(f"v_minus: couple(s) {j.tolist()} already separating (normal relative "
                         f"velocity {un0[j]} > {SEPARATING_RTOL:g} of the largest); pass only "
                         f"couples in contact or approaching")
    if np.all(un0 >= 0) and E0.max() == 0:
        return empty
    d_s = (m_s * v_s**2 / K[k_ref]) ** (1.0 / (eta_[k_ref] + 1.0))   # length scale
    t_s = d_s / v_s
    kappa = K * d_s**eta_ * t_s / (m_s * v_s)   # nondimensional stiffness (Eq. 28)
    x0 = ((eta_ + 1.0) * (E0 / (m_s * v_s**2)) / kappa) ** (1.0 / (eta_ + 1.0))
    nu = 3 * s if friction else s
    lay = StateLayout(s, nu)
    y = np.zeros(lay.size)
    y[lay.x] = x0
    y[lay.u] = (u_minus / v_s)[:nu]
    imp = ImpactConstants(s, nu, np.ascontiguousarray((G * m_s)[:nu, :nu]), kappa, eta_, e,
                          mu_, mu_s_, bool(friction), LAW_NAMES.index(law), rtol, rtol,
                          rtol * 1e-2, max_steps, m_s * v_s)
    ph = new_phases(s)
    decide = (x0 > 0) | (un0 < 0)
    status, tau, y, _, steps, log, hist, nh = kernel.lzb_impact(y, decide, imp, ph)
    events = [ImpactEvent(float(log.impulse[i]), KINDS[log.kind[i]], int(log.couple[i]))
              for i in range(log.n)]
    _raise_for(status, tau, max_steps, events)
    P = y[lay.P] * m_s * v_s
    if not friction:
        P = np.concatenate([P, np.zeros(2 * s)])
    v_plus = v + MinvW @ P
    E_scale = m_s * v_s**2
    return ImpactResult(
        v_plus=v_plus, normal_impulse=P[:s], tangential_impulse=P[s:].reshape(s, 2),
        compression_work=ph.wc * E_scale, restitution_work=-y[lay.w_exp] * E_scale,
        friction_loss=y[lay.w_fric] * E_scale, steps=steps, events=events,
        kinetic_energy_minus=KE_minus, kinetic_energy_plus=0.5 * v_plus @ M @ v_plus,
        impulse_history=hist[:nh].copy())


def _raise_for(status, tau, max_steps, events):
    """The kernel's status as a typed error (none for `kernel.DONE`)."""
    if status == kernel.BUDGET:
        raise NumericalError(f"LZB impact did not end within {max_steps} steps "
                             f"(events so far: {len(events)})",
                             couples=sorted({ev.couple for ev in events[-10:]}))
    if status == kernel.STEP_FAILED:
        raise NumericalError(f"LZB integration failed: step size below the smallest at "
                             f"tau = {tau:.6g}")
    if status == kernel.NONFINITE:
        raise NumericalError(f"LZB integration failed: non-finite state at tau = {tau:.6g}")
