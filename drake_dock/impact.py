"""LZB multiple impacts with Coulomb friction and energetic restitution (Sect. 6, Eq. 26-36,
53-54), for any multibody system at a fixed configuration. Plain numpy and scipy, no Drake.

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

Each couple has an effective indentation x_j (dx_j/dtau = -v^3_j while it exists; x_j < 0 is a
gap opened during the impact, so that a couple that separated re-impacts when x_j returns to 0)
and a phase: compression or expansion. The restitution laws act at the couple's maximal
compression (v^3_j = 0, energy W_c = K x_max^(eta+1)/(eta+1), initial energy included as in
Eq. 36) and end its expansion:

- ``"paper"``, Eq. (54): in expansion the force derives from E' = E - (1 - e^2) W_c, that is
  x jumps to e^(2/(eta+1)) x_max and unloads on the loading curve; the couple ends at E' = 0,
  having returned W_r = e^2 W_c (Eq. 36).
- ``"mono"``: the stored energy is released on the loading curve until (1 - e^2) W_c is left,
  at x = (1 - e^2)^(1/(eta+1)) x_max, which is then dropped.
- ``"bi"``: during expansion dE = -(1/e^2) delta dP, i.e. dx/dtau = -v^3/e^2 (a stiffer
  unloading branch); E reaches zero when e^2 W_c has been returned.

With one couple the three laws give the same post-impact velocity; with several they differ.

Friction, Eq. (27) and (53): a loaded couple slides with dP^t = -mu dP^3 u_t/|u_t|, or sticks
(u_t = 0 held by the tangential impulse rate that keeps it zero) while that rate stays inside
the static cone mu_s dP^3. Slip-to-stick, stick-to-slip and slip reversal are located events.

Numerics: scipy's DOP853 (8th order, error controlled by ``rtol``), every phase change located
on its dense output and the integration restarted there. The problem is nondimensionalised
(velocity scale: the largest initial relative velocity; mass scale: the smallest effective mass
of a couple; stiffness scale: the largest K), so all thresholds are relative to the impact's
scale and scaling every K by the same factor leaves the result unchanged.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from drake_dock.errors import NumericalError

LAWS = ("paper", "mono", "bi")
_COMP, _EXP = 0, 1


@dataclasses.dataclass
class ImpactEvent:
    """A phase event: ``kind`` is one of 'max_compression', 'end', 're_impact', 'stick',
    'slip', 'slip_reversal', 'reload'; ``impulse`` is the total normal impulse (N s) so far."""

    impulse: float
    kind: str
    couple: int


@dataclasses.dataclass
class ImpactResult:
    """Outcome of `solve_lzb`. Impulses in N s, works and energies in J."""

    v_plus: np.ndarray             # post-impact generalized velocity (n,)
    normal_impulse: np.ndarray     # P^3 per couple (s,)
    tangential_impulse: np.ndarray  # (P^1, P^2) per couple (s, 2)
    compression_work: np.ndarray   # W_c per couple, summed over its contact episodes (s,)
    restitution_work: np.ndarray   # W_r per couple (s,)
    friction_loss: np.ndarray      # energy dissipated by friction per couple (s,)
    primary_sequence: list         # couples of largest stored energy, in order (Eq. 32)
    steps: int                     # accepted integration steps
    events: list                   # ImpactEvent log
    kinetic_energy_minus: float
    kinetic_energy_plus: float
    impulse_history: np.ndarray = None  # normal impulses P^3 (N s) after each accepted step

    @property
    def energy_lost(self):
        """Per couple: compression work not restituted plus friction loss."""
        return self.compression_work - self.restitution_work + self.friction_loss


def _per_couple(name, value, s, *, positive=False, lo=None, hi=None):
    a = np.broadcast_to(np.asarray(value, dtype=float), (s,)).copy() if np.ndim(value) == 0 \
        else np.asarray(value, dtype=float)
    if a.shape != (s,):
        raise ValueError(f"{name}: expected a scalar or {s} values (one per couple), got shape "
                         f"{np.shape(value)}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: values must be finite, got {a}")
    if positive and np.any(a <= 0):
        raise ValueError(f"{name}: values must be > 0, got {a}")
    if lo is not None and np.any(a < lo):
        raise ValueError(f"{name}: values must be >= {lo}, got {a}")
    if hi is not None and np.any(a > hi):
        raise ValueError(f"{name}: values must be <= {hi}, got {a}")
    return a


def _check_inputs(M, Wn, v_minus, Wt):
    M = np.asarray(M, dtype=float)
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise ValueError(f"M: expected a square matrix, got shape {M.shape}")
    n = M.shape[0]
    if not np.all(np.isfinite(M)):
        raise ValueError("M: contains non-finite values")
    if not np.allclose(M, M.T, rtol=1e-12, atol=1e-12 * np.abs(M).max()):
        raise ValueError("M: not symmetric")
    try:
        L = np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise ValueError("M: not positive definite (Cholesky failed)") from None
    Wn = np.asarray(Wn, dtype=float)
    if Wn.ndim == 1:
        Wn = Wn[:, None]
    if Wn.ndim != 2 or Wn.shape[0] != n or Wn.shape[1] < 1:
        raise ValueError(f"Wn: expected shape ({n}, s) with s >= 1, got {Wn.shape}")
    if not np.all(np.isfinite(Wn)):
        raise ValueError("Wn: contains non-finite values")
    s = Wn.shape[1]
    if np.any(np.linalg.norm(Wn, axis=0) == 0):
        raise ValueError(f"Wn: column(s) {np.flatnonzero(np.linalg.norm(Wn, axis=0) == 0)} "
                         "are zero")
    v = np.asarray(v_minus, dtype=float)
    if v.shape != (n,):
        raise ValueError(f"v_minus: expected shape ({n},), got {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError("v_minus: contains non-finite values")
    if Wt is not None:
        Wt = np.asarray(Wt, dtype=float)
        if Wt.shape != (n, 2 * s):
            raise ValueError(f"Wt: expected shape ({n}, {2 * s}) (two tangent directions per "
                             f"couple), got {Wt.shape}")
        if not np.all(np.isfinite(Wt)):
            raise ValueError("Wt: contains non-finite values")
    return M, L, Wn, v, Wt, n, s


class _Problem:
    """Nondimensional contact-space impact problem and its state machine."""

    def __init__(self, G, u0, kappa, eta, e, mu, mu_s, law, x0, friction):
        self.s = s = len(kappa)
        self.kappa, self.eta, self.e, self.mu, self.mu_s = kappa, eta, e, mu, mu_s
        self.law = law
        self.friction = friction
        self.phase = np.full(s, _COMP)
        self.comp_f = np.ones(s)          # 1.0 in compression, 0.0 in expansion
        # A scalar exponent when all couples share eta (faster power).
        self.eta_pow = float(eta[0]) if np.all(eta == eta[0]) else eta
        self.rate = np.ones(s)           # dx/dtau = -rate * u_n
        self.x_end = np.zeros(s)         # expansion ends at x = x_end
        self.stuck = np.zeros(s, dtype=bool)
        self.v_tiny = 1e-12              # |u_t| (scaled velocity) below which a couple is at rest
        self._stick_cache = {}
        self.slip_dir = np.zeros((s, 2))
        self.wc = np.zeros(s)            # compression work, summed over episodes
        # State: x (s), u (nu: normal then tangential pairs), P (nu), W_comp (s), W_exp (s),
        # friction dissipation (s); nu = 3s with friction, s without.
        nu = 3 * s if friction else s
        if not friction:
            G, u0 = G[:s, :s], u0[:s]
        self.G = G
        self.ix = slice(0, s)
        self.iu = slice(s, s + nu)
        self.iun = slice(s, 2 * s)
        self.iP = slice(s + nu, s + 2 * nu)
        self.iwc = slice(s + 2 * nu, 2 * s + 2 * nu)
        self.iwe = slice(2 * s + 2 * nu, 3 * s + 2 * nu)
        self.iwf = slice(3 * s + 2 * nu, 4 * s + 2 * nu)
        y = np.zeros(4 * s + 2 * nu)
        y[self.ix] = x0
        y[self.iu] = u0
        self.y0 = y

    # Forces ---------------------------------------------------------------------------------
    def forces(self, y):
        s = self.s
        x = y[self.ix]
        u = y[self.iu]
        lam_n = self.kappa * np.maximum(x, 0.0) ** self.eta_pow     # 0 where x <= 0
        if self.friction and not self.stuck.any():
            # Fast path (every couple slips or is unloaded): unloaded couples get zero.
            ut = u[s:].reshape(s, 2)
            nt = np.sqrt(ut[:, 0] ** 2 + ut[:, 1] ** 2)
            big = nt > self.v_tiny
            d = np.where(big[:, None], ut / np.where(big, nt, 1.0)[:, None], self.slip_dir)
            return lam_n, (-self.mu * lam_n)[:, None] * d
        lam_t = np.zeros((s, 2))
        if self.friction:
            ut = u[s:].reshape(s, 2)
            loaded = lam_n > 0
            slip = loaded & ~self.stuck
            if slip.any():
                nt = np.linalg.norm(ut[slip], axis=1)
                # Near |u_t| = 0 (slip just started from rest) the slip direction is the one
                # set by the stick-to-slip transition: the direction of a round-off-sized u_t
                # is noise, and following it makes the force chatter.
                big = nt > self.v_tiny
                d = np.where(big[:, None], ut[slip] / np.where(big, nt, 1.0)[:, None],
                             self.slip_dir[slip])
                lam_t[slip] = -self.mu[slip, None] * lam_n[slip, None] * d
            stick = loaded & self.stuck
            if stick.any():
                lam_t[stick] = self._stick_forces(lam_n, lam_t, stick)
        return lam_n, lam_t

    def _stick_forces(self, lam_n, lam_t, stick):
        """Tangential force rates that keep u_t = 0 on the sticking couples (Eq. 27, second
        line): G_SS lam_S = -(G_Sn lam_n + G_S,slip lam_slip)."""
        s = self.s
        key = stick.tobytes()
        hit = self._stick_cache.get(key)
        if hit is None:
            # Per set of sticking couples: the rows and the pseudo-inverse of G_SS (the
            # least-squares solution, as lstsq with rcond 1e-12), factored once.
            idx = np.concatenate([[s + 2 * j, s + 2 * j + 1] for j in np.flatnonzero(stick)])
            GS = self.G[idx].copy()
            GS[:, idx] = 0.0
            hit = self._stick_cache[key] = (-np.linalg.pinv(self.G[np.ix_(idx, idx)],
                                                           rcond=1e-12) @ GS)
        return (hit @ np.concatenate([lam_n, lam_t.ravel()])).reshape(-1, 2)

    def rhs(self, t, y):
        s = self.s
        x = y[self.ix]
        un = y[self.iun]
        if not self.friction:
            # Fast path (most impacts): a handful of numpy operations.
            return self._assemble(y, self.kappa * np.maximum(x, 0.0) ** self.eta_pow, un, 0.0)
        if not self.stuck.any():
            return self._rhs_sliding(y)
        lam_n, lam_t = self.forces(y)
        lam = np.concatenate([lam_n, lam_t.ravel()])
        du = self.G @ lam
        if self.stuck.any():
            for j in np.flatnonzero(self.stuck & (lam_n > 0)):
                du[s + 2 * j: s + 2 * j + 2] = 0.0
        power = lam_n * (-un)
        dy = np.empty_like(y)
        dy[self.ix] = -self.rate * un
        dy[self.iu] = du
        dy[self.iP] = lam
        dy[self.iwc] = power * self.comp_f
        dy[self.iwe] = power * (1.0 - self.comp_f)
        ut = y[self.iu][s:].reshape(s, 2)
        dy[self.iwf] = -(lam_t * ut).sum(axis=1)
        return dy

    def _rhs_sliding(self, y):
        """`rhs` with friction when no couple sticks (most frictional impacts): the loaded
        couples slide, lambda_t = -mu lambda_n u_t/|u_t|, and their friction power is
        mu lambda_n |u_t|; the same equations in fewer numpy operations."""
        s = self.s
        x, un = y[:s], y[s:2 * s]
        lam = np.empty(3 * s)
        lam_n = lam[:s]
        np.power(np.maximum(x, 0.0), self.eta_pow, out=lam_n)
        lam_n *= self.kappa
        ut = y[2 * s:4 * s].reshape(s, 2)
        nt = np.sqrt(np.einsum("ij,ij->i", ut, ut))
        big = nt > self.v_tiny
        if big.all():
            d = ut / nt[:, None]
        else:
            d = np.where(big[:, None], ut / np.where(big, nt, 1.0)[:, None], self.slip_dir)
        lam_t = lam[s:].reshape(s, 2)
        mu_lam = self.mu * lam_n
        np.multiply(d, -mu_lam[:, None], out=lam_t)
        return self._assemble(y, lam, un, mu_lam * np.einsum("ij,ij->i", d, ut))

    def _assemble(self, y, lam, un, friction_power):
        """dy/dtau from the force rates lam (normal, then tangential pairs if any): x, u, P,
        compression and expansion works, friction dissipation (Eq. 30-31, 35)."""
        s, nu = self.s, len(lam)
        dy = np.empty_like(y)
        dy[:s] = -self.rate * un
        dy[s:s + nu] = self.G @ lam
        dy[s + nu:s + 2 * nu] = lam
        power = lam[:s] * un
        dy[s + 2 * nu:2 * s + 2 * nu] = -power * self.comp_f
        dy[2 * s + 2 * nu:3 * s + 2 * nu] = power * (self.comp_f - 1.0)
        dy[3 * s + 2 * nu:] = friction_power
        return dy

    # Events ---------------------------------------------------------------------------------
    def event_values(self, y):
        """Per couple, functions whose crossing from > 0 to <= 0 is a phase event:
        [max compression or end of expansion or re-impact, friction]."""
        s = self.s
        x = y[self.ix]
        g = np.empty((2, s))
        un = y[self.iun]
        # Compression with x > 0: -u_n crosses zero (maximal compression). Compression with
        # x <= 0 (a gap): x crosses zero upwards (re-impact), written as -x.
        g[0] = np.where(self.phase == _COMP, np.where(x > 0, -un, -x), x - self.x_end)
        g[1] = np.inf
        if self.friction and not self.stuck.any():
            # No couple sticks: the loaded ones (x > 0) slide.
            ut = y[2 * s:4 * s].reshape(s, 2)
            loaded = x > 0
            g[1][loaded] = np.einsum("ij,ij->i", ut, self.slip_dir)[loaded]
        elif self.friction:
            lam_n, lam_t = self.forces(y)
            ut = y[self.iu][s:].reshape(s, 2)
            loaded = lam_n > 0
            slip = loaded & ~self.stuck
            g[1][slip] = np.einsum("ij,ij->i", ut[slip], self.slip_dir[slip])
            st = loaded & self.stuck
            g[1][st] = self.mu_s[st] * lam_n[st] - np.linalg.norm(lam_t[st], axis=1)
        return g

    def _probe_loads(self, y):
        """Normal forces for the friction-mode test: the current ones, or, when no couple is
        loaded yet (the instant of loading), their ratio as loading starts: couples closing at
        rates -u_n load as lambda = kappa (-u_n tau)^eta (Eq. 28)."""
        s = self.s
        x, un = y[self.ix], y[self.iun]
        lam_n = np.where(x > 0, self.kappa * np.maximum(x, 0.0) ** self.eta, 0.0)
        if not (lam_n > 0).any():
            loading = (x >= 0) & (un < 0) & (self.phase == _COMP)
            lam_n = np.where(loading, self.kappa * np.maximum(-un, 0.0) ** self.eta, 0.0)
        return lam_n

    def select_friction_modes(self, y, js, events, impulse):
        """Stick or slip for the couples ``js`` (loaded or loading, Eq. 27), decided jointly
        with the couples that stick now, since their sticking forces depend on each other: a
        couple that moves tangentially slips along its motion; the couples at rest all stick
        if the tangential forces that keep them at rest lie in their static cones; otherwise
        the one furthest outside its cone slips, along minus its sticking force, and the rest
        are tested again (at most s rounds). Testing one couple at a time, with the others'
        loads not yet counted, made three feet landing together slip and stick in turn without
        end."""
        s = self.s
        ut = y[self.iu][s:].reshape(s, 2)
        scale = max(np.abs(y[self.iu]).max(), 1e-300)
        lam_n = self._probe_loads(y)
        was = self.stuck.copy()
        rest = []
        for j in js:
            if np.linalg.norm(ut[j]) > 1e-12 * scale:
                self.stuck[j] = False
                self.slip_dir[j] = ut[j] / np.linalg.norm(ut[j])
            else:
                rest.append(j)
        cand = sorted(set(rest) | {j for j in np.flatnonzero(self.stuck) if lam_n[j] > 0
                                   or j in js})
        for j in cand:
            y[self.iu][s + 2 * j: s + 2 * j + 2] = 0.0
            self.stuck[j] = True
        while cand:
            mask = np.zeros(s, dtype=bool)
            mask[cand] = True
            lam_t = np.zeros((s, 2))
            slip = (lam_n > 0) & ~mask
            lam_t[slip] = -self.mu[slip, None] * lam_n[slip, None] * self.slip_dir[slip]
            lt = self._stick_forces(lam_n, lam_t, mask)
            norm = np.linalg.norm(lt, axis=1)
            cone = self.mu_s[cand] * lam_n[cand]
            excess = norm - cone * (1 + 1e-12)
            # A couple at zero load sticks only with zero force (to round-off of the loads).
            excess = np.where(cone > 0, excess, norm - 1e-12 * max(lam_n.max(), 1e-300))
            k = int(np.argmax(excess / np.maximum(cone, 1e-300)))
            if excess[k] <= 0:
                break
            j = cand.pop(k)
            self.stuck[j] = False
            self.slip_dir[j] = -lt[k] / norm[k]
        for j in sorted(set(js) | set(np.flatnonzero(was != self.stuck))):
            if self.stuck[j] and not was[j]:
                events.append(ImpactEvent(impulse, "stick", j))
            elif not self.stuck[j] and np.linalg.norm(ut[j]) <= 1e-12 * scale:
                events.append(ImpactEvent(impulse, "slip" if was[j] else "slip_reversal", j))

    def apply_event(self, y, kind, j, events, impulse):
        s = self.s
        x = y[self.ix]
        if kind == 0:
            if self.phase[j] == _COMP and x[j] > 0:
                # Maximal compression: W_c (Eq. 36) and the restitution law.
                eta, e = self.eta[j], self.e[j]
                self.wc[j] += self.kappa[j] * x[j] ** (eta + 1) / (eta + 1)
                events.append(ImpactEvent(impulse, "max_compression", j))
                self.phase[j] = _EXP
                self.comp_f[j] = 0.0
                if e == 0.0:
                    self._end(y, j, events, impulse)
                elif self.law == "paper":      # Eq. (54): E' = E - (1 - e^2) W_c
                    x[j] *= e ** (2.0 / (eta + 1))
                    self.x_end[j] = 0.0
                elif self.law == "mono":
                    self.x_end[j] = (1.0 - e * e) ** (1.0 / (eta + 1)) * x[j]
                else:                          # bi: dE = -(1/e^2) delta dP
                    self.rate[j] = 1.0 / (e * e)
                    self.x_end[j] = 0.0
            elif self.phase[j] == _COMP:
                # A gap closes: re-impact (or the first loading of a resting couple).
                x[j] = 0.0
                events.append(ImpactEvent(impulse, "re_impact", j))
                if self.friction:
                    self.select_friction_modes(y, [j], events, impulse)
            else:
                self._end(y, j, events, impulse)
        else:
            if self.stuck[j]:
                # The sticking force reached the static cone: slip along minus it (the others
                # that stick are decided again with it).
                lam_n = self._probe_loads(y)
                mask = self.stuck & ((lam_n > 0) | (np.arange(s) == j))
                lam_t = np.zeros((s, 2))
                slip = (lam_n > 0) & ~mask
                lam_t[slip] = -self.mu[slip, None] * lam_n[slip, None] * self.slip_dir[slip]
                lt = self._stick_forces(lam_n, lam_t, mask)[list(np.flatnonzero(mask)).index(j)]
                self.stuck[j] = False
                if np.linalg.norm(lt) > 0:
                    self.slip_dir[j] = -lt / np.linalg.norm(lt)
                events.append(ImpactEvent(impulse, "slip", j))
                others = [k for k in np.flatnonzero(self.stuck) if k != j]
                if others:
                    self.select_friction_modes(y, others, events, impulse)
            else:
                ut = y[self.iu][s:].reshape(s, 2)[j]
                scale = np.abs(y[self.iu]).max()
                if np.linalg.norm(ut) <= 1e-9 * scale:
                    self.select_friction_modes(y, [j], events, impulse)
                else:  # the slip direction turned by more than 90 deg: follow it
                    self.slip_dir[j] = ut / np.linalg.norm(ut)

    def _end(self, y, j, events, impulse):
        y[self.ix][j] = 0.0   # mono drops the remaining (1 - e^2) W_c here
        self.phase[j] = _COMP
        self.comp_f[j] = 1.0
        self.rate[j] = 1.0
        self.x_end[j] = 0.0
        self.stuck[j] = False
        events.append(ImpactEvent(impulse, "end", j))

    def finished(self, y):
        s = self.s
        x = y[self.ix]
        un = y[self.iun]
        # u is scaled by the largest approach speed: a residual approach of 1e-12 of it (the
        # round-off left when symmetric couples end together) does not start a new impact.
        return bool(np.all(x <= 0) and np.all(self.phase == _COMP) and np.all(un >= -1e-12))


def solve_lzb(M, Wn, v_minus, stiffness, eta, restitution, *, Wt=None, mu=0.0, mu_s=None,
              law="paper", initial_energy=None, rtol=1e-10, max_steps=200_000) -> ImpactResult:
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

    Returns an `ImpactResult`. Raises ValueError naming the argument for degenerate input (M not
    SPD, wrong shapes, non-finite values, a couple already separating) and NumericalError when
    the impact does not end within ``max_steps``.
    """
    M, L, Wn, v, Wt, n, s = _check_inputs(M, Wn, v_minus, Wt)
    if law not in LAWS:
        raise ValueError(f"law: expected one of {LAWS}, got {law!r}")
    if not 1e-14 <= rtol <= 1e-2:
        raise ValueError(f"rtol: expected 1e-14 <= rtol <= 1e-2, got {rtol}")
    K = _per_couple("stiffness", stiffness, s, positive=True)
    eta_ = _per_couple("eta", eta, s, positive=True)
    e = _per_couple("restitution", restitution, s, lo=0.0, hi=1.0)
    mu_ = _per_couple("mu", mu, s, lo=0.0)
    mu_s_ = mu_ if mu_s is None else _per_couple("mu_s", mu_s, s, lo=0.0)
    E0 = np.zeros(s) if initial_energy is None else \
        _per_couple("initial_energy", initial_energy, s, lo=0.0)
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
                         np.zeros(s), [], 0, [], KE_minus, KE_minus)
    if v_s == 0.0:
        return empty
    un0 = u_minus[:s]
    if np.any(un0 > 1e-12 * v_s):
        j = np.flatnonzero(un0 > 1e-12 * v_s)
        raise ValueError(f"v_minus: couple(s) {j.tolist()} already separating (normal relative "
                         f"velocity {un0[j]} > 0); pass only couples in contact or approaching")
    if np.all(un0 >= 0) and E0.max() == 0:
        return empty
    d_s = (m_s * v_s**2 / K[k_ref]) ** (1.0 / (eta_[k_ref] + 1.0))   # length scale
    t_s = d_s / v_s
    kappa = K * d_s**eta_ * t_s / (m_s * v_s)   # nondimensional stiffness (Eq. 28)
    x0 = ((eta_ + 1.0) * (E0 / (m_s * v_s**2)) / kappa) ** (1.0 / (eta_ + 1.0))
    prob = _Problem(G * m_s, u_minus / v_s, kappa, eta_, e, mu_, mu_s_, law, x0, friction)
    events = []
    y = prob.y0.copy()
    if friction:
        prob.select_friction_modes(y, [j for j in range(s) if x0[j] > 0 or un0[j] < 0],
                                   events, 0.0)
    steps = 0
    primary = []
    history = []
    t = 0.0
    atol = rtol * 1e-2
    h = None
    while not prob.finished(y):
        solver = DOP853(prob.rhs, t, y, np.inf, rtol=rtol, atol=atol, first_step=h)
        g_old = prob.event_values(y)
        restart = False
        while not restart:
            msg = solver.step()
            if solver.status == "failed":
                raise NumericalError(f"LZB integration failed: {msg}")
            steps += 1
            if steps > max_steps:
                raise NumericalError(f"LZB impact did not end within {max_steps} steps "
                                     f"(events so far: {len(events)})",
                                     couples=sorted({ev.couple for ev in events[-10:]}))
            y_new = solver.y
            g_new = prob.event_values(y_new)
            crossed = (g_old > 0) & (g_new <= 0)
            h = solver.step_size
            if crossed.any():
                dense = solver.dense_output()
                t_first, which = np.inf, None
                roots = []
                for kind, j in zip(*np.nonzero(crossed)):
                    f = lambda tt, kind=kind, j=j: prob.event_values(dense(tt))[kind, j]  # noqa
                    ta = solver.t_old
                    if f(ta) <= 0:    # started on the boundary: the event is at ta
                        tr = ta
                    else:
                        tr = brentq(f, ta, solver.t, xtol=1e-15 * max(1.0, abs(solver.t)),
                                    rtol=4 * np.finfo(float).eps)
                    roots.append((tr, kind, j))
                    if tr < t_first:
                        t_first, which = tr, (kind, j)
                # Move to the zero's far side (within round-off) so the crossing is consumed.
                y = dense(t_first)
                t = t_first
                impulse = y[prob.iP][:s].sum() * m_s * v_s
                prob.apply_event(y, which[0], which[1], events, impulse)
                # Simultaneous events (symmetric couples): every other crossing at the same
                # instant is applied now; after the restart its function starts at <= 0 and
                # its crossing would never be seen again.
                same = 1e-12 * max(1.0, abs(t_first))
                for tr, kind, j in sorted(roots):
                    if (kind, j) != which and tr <= t_first + same \
                            and prob.event_values(y)[kind, j] <= 0:
                        prob.apply_event(y, kind, j, events, impulse)
                restart = True
            else:
                y = y_new
                t = solver.t
                g_old = g_new
            history.append(y[prob.iP][:s] * m_s * v_s)
            energies = np.where(y[prob.ix] > 0, prob.kappa * np.maximum(y[prob.ix], 0)
                                ** (eta_ + 1) / (eta_ + 1), 0.0)
            if energies.max() > 0:
                p = int(np.argmax(energies))
                if not primary or primary[-1] != p:
                    primary.append(p)
            if not restart and prob.finished(y):
                break
    P = y[prob.iP] * m_s * v_s
    if not friction:
        P = np.concatenate([P, np.zeros(2 * s)])
    v_plus = v + MinvW @ P
    E_scale = m_s * v_s**2
    Pt = P[s:].reshape(s, 2)
    return ImpactResult(
        v_plus=v_plus, normal_impulse=P[:s], tangential_impulse=Pt,
        compression_work=prob.wc * E_scale,
        restitution_work=-y[prob.iwe] * E_scale,
        friction_loss=y[prob.iwf] * E_scale,
        primary_sequence=primary, steps=steps, events=events,
        kinetic_energy_minus=KE_minus, kinetic_energy_plus=0.5 * v_plus @ M @ v_plus,
        impulse_history=np.array(history))


def solve_lzb_fixed_step(M, Wn, v_minus, stiffness, eta, restitution, *, dP, law="paper"):
    """First-order reference variant (frictionless): the same equations and restitution laws
    as `solve_lzb`, advanced by explicit Euler steps of a fixed increment ``dP`` (N s) of the
    primary impulse P* (the couple of largest force, Eq. 32), with phase changes applied at the
    end of the step in which they occur (no event location). This is how fixed-step LZB codes
    (e.g. Siconos's MultipleImpact) integrate; it is first order in dP. For benchmarks.
    Returns v_plus."""
    M, L, Wn, v, _, n, s = _check_inputs(M, Wn, v_minus, None)
    K = _per_couple("stiffness", stiffness, s, positive=True)
    eta_ = _per_couple("eta", eta, s, positive=True)
    e = _per_couple("restitution", restitution, s, lo=0.0, hi=1.0)
    MinvW = np.linalg.solve(M, Wn)
    G = Wn.T @ MinvW
    u0 = Wn.T @ v
    if np.any(u0 > 0):
        raise ValueError("v_minus: a couple is already separating")
    zeros = np.zeros(s)
    prob = _Problem(np.pad(G, ((0, 2 * s), (0, 2 * s))), np.concatenate([u0, np.zeros(2 * s)]),
                    K, eta_, e, zeros, zeros, law, zeros, False)
    y = prob.y0.copy()
    events = []
    g_old = prob.event_values(y)
    j0 = int(np.argmin(u0))
    # First step from zero energy (Eq. 33-34): the time in which the fastest couple's impulse
    # reaches dP, x = |u| t, P = K |u|^eta t^(eta+1) / (eta+1).
    t_step = (dP * (eta_[j0] + 1) / (K[j0] * abs(u0[j0]) ** eta_[j0])) ** (1 / (eta_[j0] + 1))
    for _ in range(50_000_000):
        if prob.finished(y) and _ > 0:
            break
        y = y + t_step * prob.rhs(0.0, y)
        g_new = prob.event_values(y)
        for kind, j in zip(*np.nonzero((g_old > 0) & (g_new <= 0))):
            prob.apply_event(y, kind, j, events, 0.0)
        g_old = prob.event_values(y)
        lam = K * np.maximum(y[prob.ix], 0.0) ** eta_
        if lam.max() > 0:
            t_step = dP / lam.max()
    P = y[prob.iP]
    return v + MinvW @ P
