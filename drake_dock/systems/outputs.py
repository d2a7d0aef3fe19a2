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
        self._points = Memo(2 * len(ev.pairs))

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

    def _far_points(self, i, u):
        p = self.ev.pairs[i]
        n1 = p.patch1.dim
        return (np.array(p.patch1.jet([float(c) for c in u[:n1]])[0]),
                np.array(p.patch2.jet([float(c) for c in u[n1:]])[0]))

