"""The values of the contact system's couple output ports (layout `COUPLE_SLICES`)."""
from __future__ import annotations

import numpy as np

from drake_dock.systems.contact_types import COUPLE_SLICES
from drake_dock.systems.memo import Memo

_EYE = np.eye(3).ravel()


class CoupleRows:
    """Rows of the couple outputs of the pairs of a `PlantEvaluator` ``ev``."""

    def __init__(self, ev):
        self.ev = ev
        # Far pairs' points in their body frames, by (pair, u*): they change only when the
        # pair is sought again.
        self._points = Memo(4 * len(ev.pairs))
        self._entries = {}      # `_u_entries`, by the tuple of far pairs

    def fill(self, y, x, E, st, i):
        """Fills the zeroed row y of pair i (state x, evaluation E, `PairState` st)."""
        ev = self.ev
        c = E.evals[i]
        S = COUPLE_SLICES
        if c is None:
            a, b = ev.fidx[i]
            base = ev.nq + ev.nv
            u = x[base + ev.uoff[i]:base + ev.uoff[i + 1]]
            y[S["gap"]] = st.distance - ev.bound(E, i, st)
            y[S["u"]][:len(u)] = u
            r1, r2 = self._points.get((i, u.tobytes()), lambda: self._far_points(i, u))
            y[S["p1"]] = E.poses[a][0] @ r1 + E.poses[a][1]
            y[S["p2"]] = E.poses[b][0] @ r2 + E.poses[b][1]
            y[S["frame"]] = _EYE
        else:
            y[S["status"]] = int(st.mode)    # Mode is the status code
            y[S["gap"]], y[S["vn"]] = c.gap, c.vn
            y[S["lambda_n"]], y[S["lambda_t"]] = E.lam_n[i], E.lam_t[i]
            y[S["vt"]] = c.vt
            y[S["u"]][:len(c.u)] = c.u
            y[S["p1"]], y[S["p2"]] = c.p1, c.p2
            frame = y[S["frame"]].reshape(3, 3)     # columns ta, tb, n (CoupleEval.frame)
            frame[:, 0], frame[:, 1], frame[:, 2] = c.ta, c.tb, c.n

    def fill_far(self, Y, x, E, states, far):
        """Fills the zeroed rows Y[far] of the far pairs ``far`` (each one's `PairState` in
        ``states``) at once: what `fill` writes for each."""
        ev, S = self.ev, COUPLE_SLICES
        if not len(far):
            return
        base = ev.nq + ev.nv
        if states is E.modes.pairs:     # E's own far pairs (its index's), all bounds at once
            ev.bound(E, far[0], states[far[0]])
            distance, bound = E.modes.index().distance, E.bound[far]
        else:
            distance = np.array([states[i].distance for i in far])
            bound = ev.far.bounds(far, E.poses, states)
        Y[far, S["gap"].start] = distance - bound
        at = self._u_entries(far)
        us = x[base + at[2]]
        Y[at[0], S["u"].start + at[1]] = us
        r1, r2, a, b = self._far_block(far, at, us)
        Rf = np.array([R for R, _ in E.poses])
        pf = np.array([o for _, o in E.poses])
        for col, r, f in ((S["p1"], r1, a), (S["p2"], r2, b)):
            Y[far, col] = np.einsum("kij,kj->ki", Rf[f], r) + pf[f]
        Y[far, S["frame"]] = _EYE

    def _far_block(self, far, at, us):
        """(points on patches 1, on patches 2 in their body frames (K, 3), frames 1, frames 2)
        of the far pairs ``far`` at their couples' entries ``us``: one memo entry per far set
        and couples, which change only when a pair is sought again, from each pair's own
        entry (by its couple) where that pair's couple did not change."""
        def compute():
            r1, r2 = [], []
            for i in far:
                u = us[at[0] == i]
                p, q = self._points.get((i, u.tobytes()), lambda: self._far_points(i, u))
                r1.append(p)
                r2.append(q)
            fidx = np.array([self.ev.fidx[i] for i in far], dtype=np.intp).reshape(-1, 2)
            return np.array(r1), np.array(r2), fidx[:, 0], fidx[:, 1]

        return self._points.get((tuple(far), us.tobytes()), compute)

    def _u_entries(self, far):
        """(rows of Y, places in a row's u, places in u*) of the far pairs' u* entries."""
        key = tuple(far)
        hit = self._entries.get(key)
        if hit is None:
            ev = self.ev
            rows, cols, xs = [], [], []
            for i in far:
                for c, k in enumerate(range(ev.uoff[i], ev.uoff[i + 1])):
                    rows.append(i)
                    cols.append(c)
                    xs.append(k)
            if len(self._entries) > 256:
                self._entries.clear()
            hit = self._entries[key] = tuple(np.array(v, dtype=np.intp) for v in (rows, cols, xs))
        return hit

    def _far_points(self, i, u):
        p = self.ev.pairs[i]
        n1 = p.patch1.dim
        return (np.array(p.patch1.jet([float(c) for c in u[:n1]])[0]),
                np.array(p.patch2.jet([float(c) for c in u[n1:]])[0]))

