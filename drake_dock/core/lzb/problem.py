"""The state machine of one LZB multiple impact in contact space (Sect. 6): the phases of each
couple, the force rates, the right-hand side in the time-like parameter tau and the phase
events. The rules are stated in `drake_dock.core.lzb.solve`'s docstring; `solve_lzb` drives this."""
from __future__ import annotations

import dataclasses

import numpy as np

_COMP, _EXP, _LOCK = 0, 1, 2     # phases: compression, expansion, locked (e = 0)


@dataclasses.dataclass
class ImpactEvent:
    """A phase event: ``kind`` is one of 'max_compression', 'recompression', 'end',
    're_impact' (a separated couple loads again), 'lock', 'release' (e = 0), 'stick', 'slip',
    'slip_reversal'; ``impulse`` is the total normal impulse (N s) so far."""

    impulse: float
    kind: str
    couple: int


class ImpactProblem:
    """Nondimensional contact-space impact problem and its state machine (module docstring,
    "Phases")."""

    def __init__(self, G, u0, kappa, eta, e, mu, mu_s, law, x0, friction):
        self.s = s = len(kappa)
        self.kappa, self.eta, self.e, self.mu, self.mu_s = kappa, eta, e, mu, mu_s
        self.law = law
        self.friction = friction
        self.phase = np.full(s, _COMP)
        self.comp = np.ones(s, dtype=bool)    # phase == _COMP
        self.comp_f = np.ones(s)              # 1.0 in compression, 0.0 in expansion
        self.locked = np.zeros(s, dtype=bool)  # phase == _LOCK
        self.sep = np.zeros(s, dtype=bool)    # unloaded and separating (x = 0, u_n > 0)
        # A scalar exponent when all couples share eta (faster power).
        self.eta_pow = float(eta[0]) if np.all(eta == eta[0]) else eta
        self.rate = np.ones(s)           # dx/dtau = -rate * u_n
        self.x_end = np.zeros(s)         # expansion ends at x = x_end
        self.stuck = np.zeros(s, dtype=bool)
        self.v_tiny = 1e-12              # |u_t| (scaled velocity) below which a couple is at rest
        self._stick_cache = {}
        self.slip_dir = np.zeros((s, 2))
        self.wc = np.zeros(s)            # compression work, summed over episodes
        self.e_start = np.zeros(s)       # stored energy when the current compression began
        self.wc_open = np.zeros(s)       # compression work since the contact began (mono)
        self.settle = 1e-10              # set by solve_lzb from rtol
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

    def energy(self, x, j):
        """Stored energy of couple j at indentation x (Eq. 28 integrated)."""
        return self.kappa[j] * max(x, 0.0) ** (self.eta[j] + 1) / (self.eta[j] + 1)

    def indentation(self, E, j):
        """The indentation at which couple j stores the energy E (the loading curve)."""
        return ((self.eta[j] + 1) * max(E, 0.0) / self.kappa[j]) ** (1.0 / (self.eta[j] + 1))

    def _set_phase(self, j, phase, rate=1.0):
        self.phase[j] = phase
        self.comp[j] = phase == _COMP
        self.comp_f[j] = 0.0 if phase == _EXP else 1.0
        self.locked[j] = phase == _LOCK
        self.rate[j] = 0.0 if phase == _LOCK else rate

    # Forces ---------------------------------------------------------------------------------
    def _slip_dirs(self, ut, which):
        """Slip directions of the couples ``which``, lambda_t = -mu lambda_n d (Eq. 27). Near
        |u_t| = 0 (slip just started from rest) the slip direction is the one set by the
        stick-to-slip transition: the direction of a round-off-sized u_t is noise, and
        following it makes the force chatter."""
        nt = np.linalg.norm(ut[which], axis=1)
        big = nt > self.v_tiny
        d = np.where(big[:, None], ut[which] / np.where(big, nt, 1.0)[:, None],
                     self.slip_dir[which])
        return d

    def forces(self, y):
        """Normal and tangential force rates (lambda_n (s), lambda_t (s, 2)) at the state y:
        the force law (28) on the compliant couples, Coulomb's law (27) on the loaded ones, and
        the constraint forces of the couples held at rest: locked normally (e = 0) or stuck."""
        s = self.s
        x = y[self.ix]
        u = y[self.iu]
        lam_n = self.kappa * np.maximum(x, 0.0) ** self.eta_pow     # 0 where x <= 0
        lam_t = np.zeros((s, 2))
        if self.locked.any():
            lam_n[self.locked] = 0.0
            return self._constrained_forces(y, lam_n, lam_t)
        if self.friction:
            ut = u[s:].reshape(s, 2)
            loaded = lam_n > 0
            slip = loaded & ~self.stuck
            if slip.any():
                d = self._slip_dirs(ut, slip)
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

    def _constrained_forces(self, y, lam_n, lam_t):
        """Forces with locked couples (e = 0 after their maximal compression): the unknowns are
        the locked couples' normal force rates (a sliding locked couple carries -mu lambda_n
        along its slip direction) and the stuck couples' tangential ones; they keep u_n = 0 on
        the locked couples and u_t = 0 on the stuck ones: (G B z)_R = -(G lambda_known)_R."""
        s = self.s
        nu = len(self.G)
        ut = y[self.iu][s:].reshape(s, 2) if self.friction else None
        cols, rows = [], []
        for j in np.flatnonzero(self.locked):
            b = np.zeros(nu)
            b[j] = 1.0
            if self.friction and not self.stuck[j]:
                d = self._slip_dirs(ut, np.arange(s) == j)[0]
                b[s + 2 * j: s + 2 * j + 2] = -self.mu[j] * d
            cols.append(b)
            rows.append(j)
        if self.friction:
            slip = (lam_n > 0) & ~self.stuck & ~self.locked
            if slip.any():
                d = self._slip_dirs(ut, slip)
                lam_t[slip] = -self.mu[slip, None] * lam_n[slip, None] * d
            for j in np.flatnonzero(self.stuck & ((lam_n > 0) | self.locked)):
                for k in (s + 2 * j, s + 2 * j + 1):
                    b = np.zeros(nu)
                    b[k] = 1.0
                    cols.append(b)
                    rows.append(k)
        B = np.array(cols).T
        known = np.concatenate([lam_n, lam_t.ravel()]) if self.friction else lam_n
        z = np.linalg.lstsq((self.G @ B)[rows], -(self.G @ known)[rows], rcond=1e-12)[0]
        lam = known + B @ z
        return lam[:s].copy(), (lam[s:].reshape(s, 2).copy() if self.friction else lam_t)

    def rhs(self, t, y):
        s = self.s
        un = y[self.iun]
        if not self.locked.any():
            if not self.friction:
                # Fast path (most impacts): a handful of numpy operations.
                return self._assemble(y, self.kappa * np.maximum(y[self.ix], 0.0)
                                      ** self.eta_pow, un, 0.0)
            if not self.stuck.any():
                return self._rhs_sliding(y)
        lam_n, lam_t = self.forces(y)
        if self.friction:
            ut = y[self.iu][s:].reshape(s, 2)
            dy = self._assemble(y, np.concatenate([lam_n, lam_t.ravel()]), un,
                                -(lam_t * ut).sum(axis=1))
            held = self.stuck & ((lam_n > 0) | self.locked)
            for j in np.flatnonzero(held):     # u_t held at zero exactly
                dy[2 * s + 2 * j: 2 * s + 2 * j + 2] = 0.0
        else:
            dy = self._assemble(y, lam_n, un, 0.0)
        dy[s:2 * s][self.locked] = 0.0           # u_n held at zero exactly
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
        compression and expansion works, friction dissipation (Eq. 30-31, 35). An unloaded
        couple in compression indents only while it approaches (no gap: the configuration is
        frozen), dx/dtau = max(-u_n, 0)."""
        s, nu = self.s, len(lam)
        dy = np.empty_like(y)
        dx = -self.rate * un
        free = self.comp & (y[:s] <= 0)
        if free.any():
            dx = np.where(free, np.maximum(dx, 0.0), dx)
        dy[:s] = dx
        dy[s:s + nu] = self.G @ lam
        dy[s + nu:s + 2 * nu] = lam
        power = lam[:s] * un
        dy[s + 2 * nu:2 * s + 2 * nu] = -power * self.comp_f
        dy[2 * s + 2 * nu:3 * s + 2 * nu] = power * (self.comp_f - 1.0)
        dy[3 * s + 2 * nu:] = friction_power
        return dy

    # Events ---------------------------------------------------------------------------------
    def event_values(self, y):
        """Per couple, functions whose crossing from > 0 to <= 0 is a phase event (rows:
        0 = maximal compression, end of expansion or release of a locked couple; 1 = friction;
        2 = approach again: re-compression in expansion, re-loading of a separated couple)."""
        s = self.s
        x = y[self.ix]
        g = np.full((3, s), np.inf)
        g[0], g[2] = self.normal_event_values(y)
        if self.friction and not self.stuck.any() and not self.locked.any():
            # No couple sticks: the loaded ones (x > 0) slide.
            ut = y[2 * s:4 * s].reshape(s, 2)
            loaded = x > 0
            g[1][loaded] = np.einsum("ij,ij->i", ut, self.slip_dir)[loaded]
        elif self.friction or self.locked.any():
            lam_n, lam_t = self.forces(y)
            g[0][self.locked] = lam_n[self.locked]
            if self.friction:
                ut = y[self.iu][s:].reshape(s, 2)
                loaded = lam_n > 0
                slip = loaded & ~self.stuck
                g[1][slip] = np.einsum("ij,ij->i", ut[slip], self.slip_dir[slip])
                st = loaded & self.stuck
                g[1][st] = self.mu_s[st] * lam_n[st] - np.linalg.norm(lam_t[st], axis=1)
        return g

    def normal_event_values(self, Y):
        """Rows 0 and 2 of `event_values` (a locked couple's release excepted) for states Y
        (one per column, or one state): they need no forces, so a step's dense output is
        sampled with them."""
        x, un = Y[self.ix], Y[self.iun]
        col = (slice(None),) + (None,) * (Y.ndim - 1)
        loading = (self.comp & ~self.sep)[col]
        exp = (self.phase == _EXP)[col]
        g0 = np.where(loading, -un, np.where(exp, x - self.x_end[col], np.inf))
        g2 = np.where(exp | self.sep[col], un, np.inf)
        return g0, g2

    def turn_at_once(self, y, events, impulse):
        """At a restart, a loaded couple whose u_n is at zero within round-off takes the phase
        its motion starts: compression turns to expansion if u_n grows (maximal compression
        at once), expansion to compression if u_n falls (approach again at once; after
        Eq. 54's drop of force, or at a tangency of u_n with zero)."""
        s = self.s
        for _ in range(2 * s):
            x, un = y[self.ix], y[self.iun]
            near = np.abs(un) <= 1e-12
            if not near.any():
                return
            dun = self.rhs(0.0, y)[s:2 * s]
            turn = near & (((self.phase == _COMP) & (x > 0) & (dun > 0))
                           | ((self.phase == _EXP) & (dun < 0)))
            if not turn.any():
                return
            j = int(np.flatnonzero(turn)[0])
            self.apply_event(y, 0 if self.phase[j] == _COMP else 2, j, events, impulse)

    def classify(self, y):
        """Marks the unloaded couples in compression that separate (x = 0, u_n > 0 beyond
        round-off), whose next event is their approach; True if any changed."""
        x, un = y[self.ix], y[self.iun]
        new = self.comp & ~self.sep & (x <= 0) & (un > 1e-12)
        self.sep |= new
        return bool(new.any())

    def _probe_loads(self, y):
        """Normal forces for the friction-mode test: the current ones, or, when no couple is
        loaded yet (the instant of loading), their ratio as loading starts: couples closing at
        rates -u_n load as lambda = kappa (-u_n tau)^eta (Eq. 28)."""
        x, un = y[self.ix], y[self.iun]
        lam_n = self.forces(y)[0] if self.locked.any() else \
            np.where(x > 0, self.kappa * np.maximum(x, 0.0) ** self.eta, 0.0)
        if not (lam_n > 0).any():
            loading = (x >= 0) & (un < 0) & self.comp
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
        x = y[self.ix]
        if kind == 0:
            if self.phase[j] == _COMP and x[j] > 0:
                self._max_compression(y, j, events, impulse)
            elif self.phase[j] == _COMP:
                # u_n turned positive at zero indentation: the couple separates unloaded.
                self.sep[j] = True
            elif self.phase[j] == _LOCK:
                # A locked couple's force rate reached zero: it is released and separates.
                self._set_phase(j, _COMP)
                self.sep[j] = True
                events.append(ImpactEvent(impulse, "release", j))
            else:
                self._end(y, j, events, impulse)
        elif kind == 2:
            if self.phase[j] == _EXP:
                # Approaching again during expansion: compression resumes on the loading
                # curve from the energy stored now.
                self._set_phase(j, _COMP)
                self.e_start[j] = self.energy(x[j], j)
                events.append(ImpactEvent(impulse, "recompression", j))
            else:
                # A separated couple approaches again: it re-loads from zero indentation.
                self.sep[j] = False
                x[j] = 0.0
                events.append(ImpactEvent(impulse, "re_impact", j))
                if self.friction:
                    self.select_friction_modes(y, [j], events, impulse)
        elif kind == 1:
            self._friction_event(y, j, events, impulse)

    def _max_compression(self, y, j, events, impulse):
        """Maximal compression of couple j: the compression work of this episode,
        W = E - E_start, enters W_c (Eq. 36) and the law sets the expansion."""
        x = y[self.ix]
        E = self.energy(x[j], j)
        work = E - self.e_start[j]
        e = self.e[j]
        self.wc[j] += work
        self.wc_open[j] += work
        events.append(ImpactEvent(impulse, "max_compression", j))
        if e == 0.0:
            self._lock(y, j, events, impulse)
        elif self.law == "paper":      # Eq. (54): E' = E - (1 - e^2) W
            x[j] = self.indentation(E - (1.0 - e * e) * work, j)
            self._set_phase(j, _EXP)
            self.x_end[j] = 0.0
        elif self.law == "mono":       # ends when (1 - e^2) W_c is left (W_r = e^2 W_c)
            self._set_phase(j, _EXP)
            self.x_end[j] = self.indentation((1.0 - e * e) * self.wc_open[j], j)
        else:                          # bi: dE = -(1/e^2) delta dP
            self._set_phase(j, _EXP, rate=1.0 / (e * e))
            self.x_end[j] = 0.0

    def _lock(self, y, j, events, impulse):
        """e = 0: the stored energy is lost and the couple is held at u_n = 0 by a constraint
        force rate lambda_n >= 0 (the limit e -> 0 of every law, which otherwise re-impacts
        without end); a couple whose constraint force would pull, or that nothing presses,
        is released instead."""
        y[self.ix][j] = 0.0
        self.e_start[j] = self.wc_open[j] = 0.0
        self._set_phase(j, _LOCK)
        while self.locked.any():
            lam_n = self._probe_loads(y)
            held = np.flatnonzero(self.locked)
            k = held[int(np.argmin(lam_n[held]))]
            if lam_n[k] > 0:
                break
            self._set_phase(k, _COMP)
            if k != j:
                self.sep[k] = True
                events.append(ImpactEvent(impulse, "release", k))
        if self.locked[j]:
            events.append(ImpactEvent(impulse, "lock", j))
        else:
            events.append(ImpactEvent(impulse, "end", j))

    def _friction_event(self, y, j, events, impulse):
        s = self.s
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
        self._set_phase(j, _COMP)
        self.x_end[j] = 0.0
        self.e_start[j] = self.wc_open[j] = 0.0
        self.stuck[j] = False
        events.append(ImpactEvent(impulse, "end", j))

    def finished(self, y):
        """Every couple unloaded and none approaching, or the bodies settled: no couple
        approaches, nor could the stored energy move one, by more than ``settle`` times the
        impact's velocity scale (module docstring, "Repeated impacts")."""
        x = y[self.ix]
        un = y[self.iun]
        # u is scaled by the largest approach speed: a residual approach of 1e-12 of it (the
        # round-off left when symmetric couples end together) does not start a new impact.
        if np.all(x <= 0) and not (self.phase == _EXP).any() \
                and np.all(un[~self.locked] >= -1e-12):
            return True
        if un.min() < -self.settle:
            return False
        stored = self.kappa * np.maximum(x, 0.0) ** (self.eta + 1) / (self.eta + 1)
        return bool(stored.sum() <= 0.5 * self.settle ** 2)
