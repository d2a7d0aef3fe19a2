"""The witness table: which witness functions a pair has in each `Mode`, their names, direction
and values. One guard per transition (module docstring of `contact_system`); every witness is
positive while its transition is not due and triggers when it reaches zero from above."""
from __future__ import annotations

import math

import numpy as np
from pydrake.systems.framework import WitnessFunctionDirection

from drake_dock.core.couple import point_curve_side
from drake_dock.core.hybrid import Mode

FAR_WITNESS = "far pairs clearance"   # the one witness of all far pairs ("clear")
DIRECTION = WitnessFunctionDirection.kPositiveThenNonPositive


def _gap(ev, E, st, i):
    """The gap g of a tracked couple: its zero is an impact."""
    c = E.evals[i]
    return 1.0 if c is None else c.gap


def _apex(ev, E, st, i):
    """The gap rate while the gap is not positive, else 1. Just after an impact the gap is at
    or below zero (the impact is isolated to within Drake's window), so the gap witness cannot
    trigger; a couple that closes again before its gap has become positive would be missed.
    This witness triggers if it turns back (v_n reaches zero) while the gap is still not
    positive. Once the gap is positive the gap witness takes over: the value jumps from v_n > 0
    to 1 (no trigger) on the way out, and from 1 to v_n < 0 on the way back, at the gap's zero,
    together with the gap witness (a rate witness active at every bounce's apex would cost an
    isolated event each)."""
    c = E.evals[i]
    return 1.0 if c is None or c.gap > 0.0 else c.vn


def _end(ev, E, st, i):
    """The smallest margin of a bounded parameter to its domain's ends, relative to the span
    (periodic parameters have none): the couple reaches the end of its domain."""
    c = E.evals[i]
    if c is None:
        return 1.0
    w = math.inf
    for a, b in zip(c.u.tolist(), ev.bounded[i]):
        if b is not None:
            w = min(w, (a - b[0]) / b[2], (b[1] - a) / b[2])
    return w


def _cond(ev, E, st, i):
    """The conditioning of J above ``conditioning_min``: Eq. (39) fails at its zero."""
    c = E.evals[i]
    return 1.0 if c is None else c.conditioning - ev.options.conditioning_min


# The hand-over guard's witness fires at n . b = -GUARD_BAND: a couple that rides on the
# switching surface (n . b = 0 to round-off, as where a symmetric motion keeps a ring's circle
# over a petal's edge) does not trigger an event at every step.
GUARD_BAND = 1e-9


def _handover(ev, E, st, i):
    """The guard of an edge pair with a declared hand-over (`drake_dock.core.handover`): n . b,
    positive while its curve lies beyond the edge; at its zero the couple passes onto the
    surface and is handed to the surface pair."""
    c = E.evals[i]
    if c is None:
        return 1.0
    return ev.links.guard(i, c.n, c.u, E.poses[ev.fidx[i][1]][0]) + GUARD_BAND


def _side(ev, E, st, i):
    """A point-curve pair's side (`drake_dock.core.couple.point_curve_side`): positive while the
    point lies on the curve's concave side; at its zero the pair is sought again (a potential
    contact only there)."""
    c = E.evals[i]
    if c is None:
        return 1.0
    p = ev.pairs[i]
    return point_curve_side(p.patch2, E.poses[ev.fidx[i][1]][0], c.u[0], c.n)


def _lambda(ev, E, st, i):
    """lambda_n of a couple in contact: it detaches at its zero (Eq. 50-51)."""
    return E.lam_n[i] if st.mode.in_contact else 1.0


def _slip(ev, E, st, i):
    """The sliding velocity along its direction: it stops or reverses at its zero."""
    c = E.evals[i]
    if st.mode != Mode.SLIDING or c is None or st.slide_dir is None:
        return 1.0
    return c.vt @ st.slide_dir


def _cone(ev, E, st, i):
    """mu_s lambda_n - |lambda_t| of a sticking couple: it reaches the static cone (Eq. 51)."""
    if st.mode != Mode.STICKING:
        return 1.0
    return ev.mu_s * E.lam_n[i] - math.hypot(*E.lam_t[i])


def _clear(ev, E, st, i):
    """All far pairs' witness: the smallest clearance left, min (clearance - travel bound) (1
    if no pair is far); its event seeks again every far pair whose clearance is used up."""
    pairs, index = E.modes.pairs, E.modes.index()
    far = index.far
    if not len(far):
        return 1.0
    unknown = np.flatnonzero(np.isnan(E.bound[far]))
    if len(unknown):                        # fills every far pair's unknown bound at once
        k = int(far[unknown[0]])
        ev.bound(E, k, pairs[k])
    w = float(np.min(index.clearance - E.bound[far]))
    return 1.0 if w == math.inf else w


# kind: (name after the pair's name, value(evaluator, evaluation, pair state, pair index))
WITNESSES = {"gap": ("gap", _gap), "end": ("domain end", _end), "cond": ("Eq. 39", _cond),
             "lambda": ("lambda_n", _lambda), "slip": ("slip", _slip),
             "cone": ("friction cone", _cone), "apex": ("gap rate", _apex),
             "handover": ("hand-over", _handover), "side": ("concave side", _side)}

# The witnesses of a pair in each mode, in the order they are armed.
BY_MODE = {Mode.FAR: (),
           Mode.TRACKED: ("end", "cond", "gap", "apex"),
           Mode.SLIDING: ("end", "cond", "lambda", "slip"),
           Mode.STICKING: ("end", "cond", "lambda", "cone")}


def value(kind, ev, E, st, i) -> float:
    """The value of witness ``kind`` ("clear" for the far pairs' one, with i None)."""
    return float((_clear if kind == "clear" else WITNESSES[kind][1])(ev, E, st, i))


def declare(system, pairs, value_at, event):
    """The witness functions of ``system``: per pair a dict kind -> witness (named
    "<pair> <name>"), and the far pairs' one; ``value_at(context, i, kind)`` gives the value."""
    per_pair = [{kind: system.MakeWitnessFunction(f"{p.name} {name}", DIRECTION,
                                                  lambda c, i=i, k=kind: value_at(c, i, k),
                                                  event)
                 for kind, (name, _) in WITNESSES.items()}
                for i, p in enumerate(pairs)]
    far = system.MakeWitnessFunction(FAR_WITNESS, DIRECTION,
                                     lambda c: value_at(c, None, "clear"), event)
    return per_pair, far


def armed(states, edge_pairs=(), side_pairs=()) -> list:
    """(pair index or None, kind) of every witness armed for the pairs' `PairState`s: the far
    pairs' clearance when a pair is far, then each pair's witnesses of its mode, the
    hand-over guard of the pairs in ``edge_pairs`` and the side of the point-curve pairs in
    ``side_pairs`` that are not far."""
    out = [(None, "clear")] if any(st.mode == Mode.FAR for st in states) else []
    for i, st in enumerate(states):
        out += [(i, kind) for kind in BY_MODE[st.mode]]
        if st.mode != Mode.FAR and i in edge_pairs:
            out.append((i, "handover"))
        if st.mode != Mode.FAR and i in side_pairs:
            out.append((i, "side"))
    return out
