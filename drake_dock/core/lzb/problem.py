"""The state machine of one LZB multiple impact in contact space (Sect. 6): the phases of each
couple, the right-hand side in the time-like parameter tau and the phase events. The rules are
stated in `drake_dock.core.lzb.solve`'s docstring; `solve_lzb` drives this. The force rates are
in `drake_dock.core.lzb.forces`, the restitution laws in `drake_dock.core.lzb.laws`, the
stick-slip decisions in `drake_dock.core.lzb.friction`."""
from __future__ import annotations

import numpy as np

from drake_dock.core.lzb import laws
from drake_dock.core.lzb.forces import force_rates, forces, probe_loads, tangential_pairs
from drake_dock.core.lzb.friction import on_friction_event, select_impact_friction_modes
from drake_dock.core.lzb.state import COMPRESSION, EXPANSION, LOCKED, ImpactEvent, StateLayout

# Rows of `ImpactProblem.event_values`.
NORMAL, FRICTION, APPROACH = 0, 1, 2


class ImpactProblem:
    """Nondimensional contact-space impact problem and its state machine (module docstring of
    `drake_dock.core.lzb.solve`, "Phases"). G: the Delassus matrix in contact space, u0 the
    initial relative velocities (normal, then the tangential pairs), x0 the initial
    indentations; ``settle`` the relative velocity below which the impact has ended."""

    def __init__(self, G, u0, kappa, eta, e, mu, mu_s, law, x0, friction, settle=1e-10):
        self.s = s = len(kappa)
        self.kappa, self.eta, self.e, self.mu, self.mu_s = kappa, eta, e, mu, mu_s
        self.law = law
        self.unloading = laws.UNLOADING[law]
        self.friction = friction
        self.settle = settle
        self.phase = np.full(s, COMPRESSION)
        self.comp = np.ones(s, dtype=bool)    # phase == COMPRESSION
        self.comp_f = np.ones(s)              # 1.0 in compression, 0.0 in expansion
        self.locked = np.zeros(s, dtype=bool)  # phase == LOCKED
        self.sep = np.zeros(s, dtype=bool)    # unloaded and separating (x = 0, u_n > 0)
        # A scalar exponent when all couples share eta (faster power).
        self.eta_pow = float(eta[0]) if np.all(eta == eta[0]) else eta
        self.rate = np.ones(s)           # dx/dtau = -rate * u_n
        self.x_end = np.zeros(s)         # expansion ends at x = x_end
        self.stuck = np.zeros(s, dtype=bool)
        self.v_tiny = 1e-12              # |u_t| (scaled velocity) below which a couple is at rest
        self.stick_cache = {}
        self.slip_dir = np.zeros((s, 2))
        self.wc = np.zeros(s)            # compression work, summed over episodes
        self.e_start = np.zeros(s)       # stored energy when the current compression began
        self.wc_open = np.zeros(s)       # compression work since the contact began (mono)
        nu = 3 * s if friction else s
        if not friction:
            G, u0 = G[:s, :s], u0[:s]
        self.G = G
        self.layout = L = StateLayout(s, nu)
        y = np.zeros(L.size)
        y[L.x] = x0
        y[L.u] = u0
        self.y0 = y

    def energy(self, x, j):
        """Stored energy of couple j at indentation x (Eq. 28 integrated)."""
        return laws.stored_energy(self.kappa[j], self.eta[j], x)

    def _set_phase(self, j, phase, rate=1.0):
        self.phase[j] = phase
        self.comp[j] = phase == COMPRESSION
        self.comp_f[j] = 0.0 if phase == EXPANSION else 1.0
        self.locked[j] = phase == LOCKED
        self.rate[j] = 0.0 if phase == LOCKED else rate

    # Right-hand side ------------------------------------------------------------------------
    def rhs(self, t, y):
        """dy/dtau (Eq. 30-31, 35) from the force rates lambda (`forces.force_rates`):
        dx = -rate u_n (an unloaded couple in compression indents only while it approaches:
        the configuration is frozen, so there is no gap), du = G lambda, dP = lambda, the
        compression and expansion works -lambda_n u_n and the friction dissipation; u_n of a
        locked couple and u_t of a stuck loaded one are held at zero exactly."""
        L = self.layout
        lam, friction_power = force_rates(self, y)
        un = y[L.un]
        dy = np.empty_like(y)
        dx = -self.rate * un
        free = self.comp & (y[L.x] <= 0)
        if free.any():
            dx = np.where(free, np.maximum(dx, 0.0), dx)
        dy[L.x] = dx
        dy[L.u] = self.G @ lam
        dy[L.P] = lam
        power = lam[:self.s] * un
        dy[L.w_comp] = -power * self.comp_f
        dy[L.w_exp] = power * (self.comp_f - 1.0)
        dy[L.w_fric] = friction_power
        if self.friction:
            for j in np.flatnonzero(self.stuck & ((lam[:self.s] > 0) | self.locked)):
                dy[L.ut_of(j)] = 0.0
        dy[L.un][self.locked] = 0.0
        return dy

    # Event functions ------------------------------------------------------------------------
    def event_values(self, y):
        """Per couple, functions whose crossing from > 0 to <= 0 is a phase event (rows:
        NORMAL = maximal compression, end of expansion or release of a locked couple;
        FRICTION = a sliding couple's u_t along its slip direction down to ``settle``, the
        speed of rest (it came to rest, or turned), or a sticking couple's force at its static
        cone; APPROACH = re-compression in expansion, re-loading of a separated couple)."""
        s = self.s
        x = y[self.layout.x]
        g = np.full((3, s), np.inf)
        g[NORMAL], g[APPROACH] = self.normal_event_values(y)
        if self.friction and not self.stuck.any() and not self.locked.any():
            # No couple sticks: the loaded ones (x > 0) slide.
            ut = tangential_pairs(self, y)
            loaded = x > 0
            g[FRICTION][loaded] = (np.einsum("ij,ij->i", ut, self.slip_dir)[loaded]
                                   - self.settle)
        elif self.friction or self.locked.any():
            lam_n, lam_t = forces(self, y)
            g[NORMAL][self.locked] = lam_n[self.locked]
            if self.friction:
                ut = tangential_pairs(self, y)
                loaded = lam_n > 0
                slip = loaded & ~self.stuck
                g[FRICTION][slip] = (np.einsum("ij,ij->i", ut[slip], self.slip_dir[slip])
                                     - self.settle)
                st = loaded & self.stuck
                g[FRICTION][st] = self.mu_s[st] * lam_n[st] - np.linalg.norm(lam_t[st], axis=1)
        return g

    def normal_event_values(self, Y):
        """Rows NORMAL and APPROACH of `event_values` (a locked couple's release excepted) for
        states Y (one per column, or one state): they need no forces, so a step's dense output
        is sampled with them."""
        x, un = Y[self.layout.x], Y[self.layout.un]
        col = (slice(None),) + (None,) * (Y.ndim - 1)
        loading = (self.comp & ~self.sep)[col]
        exp = (self.phase == EXPANSION)[col]
        g0 = np.where(loading, -un, np.where(exp, x - self.x_end[col], np.inf))
        g2 = np.where(exp | self.sep[col], un, np.inf)
        return g0, g2

    def classify(self, y):
        """Marks the unloaded couples in compression that separate (x = 0, u_n > 0 beyond
        round-off), whose next event is their approach; True if any changed."""
        x, un = y[self.layout.x], y[self.layout.un]
        new = self.comp & ~self.sep & (x <= 0) & (un > 1e-12)
        self.sep |= new
        return bool(new.any())

    def finished(self, y):
        """Every couple unloaded and none approaching, or the bodies settled: no couple
        approaches, nor could the stored energy move one, by more than ``settle`` times the
        impact's velocity scale (module docstring, "Repeated impacts")."""
        x = y[self.layout.x]
        un = y[self.layout.un]
        # u is scaled by the largest approach speed: a residual approach of 1e-12 of it (the
        # round-off left when symmetric couples end together) does not start a new impact.
        if np.all(x <= 0) and not (self.phase == EXPANSION).any() \
                and np.all(un[~self.locked] >= -1e-12):
            return True
        if un.min() < -self.settle:
            return False
        stored = self.kappa * np.maximum(x, 0.0) ** (self.eta + 1) / (self.eta + 1)
        return bool(stored.sum() <= 0.5 * self.settle ** 2)

    # Event handlers -------------------------------------------------------------------------
    def apply_event(self, y, kind, j, events, impulse):
        """Couple j's event function of row ``kind`` crossed zero at the state y."""
        if kind == FRICTION:
            on_friction_event(self, y, j, events, impulse)
        elif kind == APPROACH:
            self._approach(y, j, events, impulse)
        elif self.phase[j] == COMPRESSION and y[self.layout.x][j] > 0:
            self._max_compression(y, j, events, impulse)
        elif self.phase[j] == COMPRESSION:
            # u_n turned positive at zero indentation: the couple separates unloaded.
            self.sep[j] = True
        elif self.phase[j] == LOCKED:
            # A locked couple's force rate reached zero: it is released and separates.
            self._set_phase(j, COMPRESSION)
            self.sep[j] = True
            events.append(ImpactEvent(impulse, "release", j))
        else:
            self._end(y, j, events, impulse)

    def _approach(self, y, j, events, impulse):
        x = y[self.layout.x]
        if self.phase[j] == EXPANSION:
            # Approaching again during expansion: compression resumes on the loading curve
            # from the energy stored now.
            self._set_phase(j, COMPRESSION)
            self.e_start[j] = self.energy(x[j], j)
            events.append(ImpactEvent(impulse, "recompression", j))
        else:
            # A separated couple approaches again: it re-loads from zero indentation.
            self.sep[j] = False
            x[j] = 0.0
            events.append(ImpactEvent(impulse, "re_impact", j))
            if self.friction:
                select_impact_friction_modes(self, y, [j], events, impulse)

    def _max_compression(self, y, j, events, impulse):
        """Maximal compression of couple j: the compression work of this episode,
        W = E - E_start, enters W_c (Eq. 36) and the law sets the expansion
        (`drake_dock.core.lzb.laws`)."""
        x = y[self.layout.x]
        E = self.energy(x[j], j)
        work = E - self.e_start[j]
        self.wc[j] += work
        self.wc_open[j] += work
        events.append(ImpactEvent(impulse, "max_compression", j))
        if self.e[j] == 0.0:
            self._lock(y, j, events, impulse)
            return
        u = self.unloading(self.kappa[j], self.eta[j], self.e[j], E, work, self.wc_open[j])
        if u.x_start is not None:
            x[j] = u.x_start
        self._set_phase(j, EXPANSION, rate=u.rate)
        self.x_end[j] = u.x_end

    def _lock(self, y, j, events, impulse):
        """e = 0: the stored energy is lost and the couple is held at u_n = 0 by a constraint
        force rate lambda_n >= 0 (the limit e -> 0 of every law, which otherwise re-impacts
        without end); a couple whose constraint force would pull, or that nothing presses,
        is released instead."""
        y[self.layout.x][j] = 0.0
        self.e_start[j] = self.wc_open[j] = 0.0
        self._set_phase(j, LOCKED)
        while self.locked.any():
            lam_n = probe_loads(self, y)
            held = np.flatnonzero(self.locked)
            k = held[int(np.argmin(lam_n[held]))]
            if lam_n[k] > 0:
                break
            self._set_phase(k, COMPRESSION)
            if k != j:
                self.sep[k] = True
                events.append(ImpactEvent(impulse, "release", k))
        events.append(ImpactEvent(impulse, "lock" if self.locked[j] else "end", j))

    def _end(self, y, j, events, impulse):
        y[self.layout.x][j] = 0.0   # mono drops the remaining (1 - e^2) W_c here
        self._set_phase(j, COMPRESSION)
        self.x_end[j] = 0.0
        self.e_start[j] = self.wc_open[j] = 0.0
        self.stuck[j] = False
        events.append(ImpactEvent(impulse, "end", j))

    def turn_at_once(self, y, events, impulse):
        """At a restart, a loaded couple whose u_n is at zero within round-off takes the phase
        its motion starts: compression turns to expansion if u_n grows (maximal compression
        at once), expansion to compression if u_n falls (approach again at once; after
        Eq. 54's drop of force, or at a tangency of u_n with zero)."""
        for _ in range(2 * self.s):
            x, un = y[self.layout.x], y[self.layout.un]
            near = np.abs(un) <= 1e-12
            if not near.any():
                return
            dun = self.rhs(0.0, y)[self.layout.un]
            turn = near & (((self.phase == COMPRESSION) & (x > 0) & (dun > 0))
                           | ((self.phase == EXPANSION) & (dun < 0)))
            if not turn.any():
                return
            j = int(np.flatnonzero(turn)[0])
            self.apply_event(y, NORMAL if self.phase[j] == COMPRESSION else APPROACH, j,
                             events, impulse)
