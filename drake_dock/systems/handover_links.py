"""The declared hand-overs between edge pairs and surface pairs (`Handover`), by pair index: the
guard of an edge pair and the pair a couple is handed to, with the rules of
`drake_dock.core.handover`."""
from __future__ import annotations

import numpy as np

from drake_dock.core import handover as rule


class HandoverLinks:
    """``of_edge[i]``: [(surface pair j, `SurfaceEdge`)] of edge pair i; ``of_surface[j]``:
    [(edge pair i, `SurfaceEdge`)] of surface pair j."""

    def __init__(self, pairs, handovers):
        index = {p.name: k for k, p in enumerate(pairs)}
        self.pairs = pairs
        self.of_edge, self.of_surface = {}, {}
        for h in handovers:
            for name in (h.edge_pair, h.surface_pair):
                if name not in index:
                    raise ValueError(f"handovers: no pair named {name!r}")
            i, j = index[h.edge_pair], index[h.surface_pair]
            e, s = pairs[i], pairs[j]
            if (e.patch1.dim, e.patch2.dim, s.patch2.dim) != (1, 1, 2) \
                    or e.patch1 is not s.patch1 \
                    or e.frame1 is not s.frame1 or e.frame2 is not s.frame2:
                raise ValueError(f"handovers[{h.edge_pair}, {h.surface_pair}]: must be a C-C "
                                 f"and a C-S pair with the same curve on the same frames")
            self.of_edge.setdefault(i, []).append((j, h.edge))
            self.of_surface.setdefault(j, []).append((i, h.edge))

    def _guards(self, i, n, u, R2):
        """(surface pair j, edge, guard value) for edge pair i's couple u with normal n (world),
        Body 2 turned by R2 (`drake_dock.core.handover.edge_guard`)."""
        for j, edge in self.of_edge.get(i, ()):
            S = self.pairs[j].patch2
            _, T, _ = S.jet(rule.surface_params(edge, S.lower, S.upper, float(u[-1])))
            yield j, edge, rule.edge_guard(edge, n, [R2 @ np.asarray(t) for t in T])

    def guard(self, i, n, u, R2) -> float:
        """Edge pair i's guard: the least over its surfaces (+inf if it has none)."""
        return min((w for _, _, w in self._guards(i, n, u, R2)), default=np.inf)

    def due(self, i, u, n, R2, tol: float = 0.0):
        """(pair j, j's couple) for each hand-over of pair i's couple u whose guard is met
        within ``tol``: a surface pair's couple on or past a declared edge (or within tol of
        its span, `rule.reaches_edge`); an edge pair's guard not above tol for its normal n
        (world; None: not checked), Body 2 turned by R2."""
        S = self.pairs[i].patch2
        for j, edge in self.of_surface.get(i, ()):
            if rule.reaches_edge(edge, S.lower, S.upper, u[1:], tol):
                yield j, np.array(rule.to_edge(edge, 1, u))
        if n is None:
            return
        for j, edge, w in self._guards(i, n, u, R2):
            if w <= tol:
                S = self.pairs[j].patch2
                yield j, np.array(rule.to_surface(edge, 1, u, S.lower, S.upper))

    def outward_rate(self, j, i, udot) -> float:
        """The rate of surface pair j's held parameter at its edge shared with edge pair i,
        from its couple's rate udot (Eq. 47), positive out of the domain."""
        dim1 = self.pairs[j].patch1.dim
        edge = next(e for k, e in self.of_surface[j] if k == i)
        rate = float(udot[dim1 + edge.fixed])
        return rate if edge.upper else -rate

    def target(self, i, u, n, R2, states):
        """Where pair i's couple is handed (`due`): (pair j, j's couple) for the first pair j
        that is not in contact; else None."""
        return next(((j, uj) for j, uj in self.due(i, u, n, R2)
                     if not states[j].mode.in_contact), None)


def applied(due: dict) -> dict:
    """The hand-overs an event makes of those due, {pair i: (pair j, j's couple)}, decided on the
    states the event found (`HandoverLinks.target`): {j: i} where j takes the couple of the one
    pair whose couple is due to it and does not hand its own couple on. A chain, an exchange or
    two couples due to one pair wait for the next event (their couples are sought where they
    leave their domains), so that no outcome depends on the pairs' order."""
    targets = [j for j, _ in due.values()]
    return {j: i for i, (j, _) in due.items() if j not in due and targets.count(j) == 1}


def accepts(ev, i, to, n, kin) -> bool:
    """Rules for a hand-over due from pair i of the `RigidContactSystem` ``ev`` (couple normal
    n; the bodies' `Kinematics` kin) to pair j (``to`` = (j, j's couple on the edge)), on j's
    couple there (Eq. 47, with the sigma that keeps n):
    - j's couple must be regular (conditioning above ``conditioning_min``): a ring coaxial
      with a petal's cone has no isolated couple with it, and a singular couple would jump at
      its first projection.
    - j's couple must be the same pair of points as i's: its closest-point conditions
      (Eq. 37-38) hold there to within ``handover_tol`` of its domain (one Newton step moves it
      less). They hold exactly at the guard's zero; a guard found negative at a later event,
      after the couple went on along the edge, is past it.
    - edge to surface: j's couple must move into its domain, the rate of its held parameter
      pointing inwards (`HandoverLinks.outward_rate` < 0). Otherwise it would reach the edge
      again at once and be handed back: off contact the edge guard and the surface couple's
      domain end need not agree, and a couple would go to and fro at every event.
    When a rule fails, pair i keeps its couple; a surface couple past its edge is then sought
    again, as at any domain end."""
    j, uj = to
    eng = ev.engine
    raw = eng.couple(j, uj, kin.still(), 1.0, project=False)
    cj = eng.couple(j, uj, kin, rule.carried_sigma(n, raw.n))
    if cj.conditioning <= ev.options.conditioning_min:
        return False
    if (np.abs(cj.drift) / eng.model.spans[j, :len(cj.drift)]).max() > ev.options.handover_tol:
        return False
    return i not in ev.links.of_edge or ev.links.outward_rate(j, i, cj.udot) < 0.0
