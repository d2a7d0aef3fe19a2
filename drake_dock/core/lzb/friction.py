"""Stick or slip of the loaded couples of an LZB impact (Eq. 27, 53): the decisions taken at a
couple's loading and at its friction events. Functions of an `ImpactProblem` ``prob``; they set
``prob.stuck`` and ``prob.slip_dir`` and log `ImpactEvent`s."""
from __future__ import annotations

import numpy as np

from drake_dock.core.lzb.forces import probe_loads, stick_forces, tangential_pairs
from drake_dock.core.lzb.state import ImpactEvent


def _sticking_forces(prob, lam_n, mask):
    """Tangential force rates that keep the couples ``mask`` at rest, the other loaded couples
    sliding along their slip directions."""
    lam_t = np.zeros((prob.s, 2))
    slip = (lam_n > 0) & ~mask
    lam_t[slip] = -prob.mu[slip, None] * lam_n[slip, None] * prob.slip_dir[slip]
    return stick_forces(prob, lam_n, lam_t, mask)


def rest_speed(prob, scale) -> float:
    """The tangential speed within which a couple is at rest: twice the speed at which a
    sliding couple's friction event fires (``prob.settle``, the relative velocity that ends the
    impact: `ImpactProblem.event_values`), or 1e-9 of the largest velocity ``scale``. The
    compiled kernel's `apply_event` uses the same."""
    return max(1e-9 * scale, 2.0 * prob.settle)


def select_impact_friction_modes(prob, y, js, events, impulse):
    """Stick or slip for the couples ``js`` (loaded or loading, Eq. 27), decided jointly with
    the couples that stick now, since their sticking forces depend on each other: a couple
    that moves tangentially slips along its motion; the couples at rest all stick if the
    tangential forces that keep them at rest lie in their static cones; otherwise the one
    furthest outside its cone slips, along minus its sticking force, and the rest are tested
    again (at most s rounds). Testing one couple at a time, with the others' loads not yet
    counted, made three feet landing together slip and stick in turn without end."""
    s = prob.s
    ut = tangential_pairs(prob, y)
    scale = max(np.abs(y[prob.layout.u]).max(), 1e-300)
    lam_n = probe_loads(prob, y)
    was = prob.stuck.copy()
    rest = []
    v_rest = rest_speed(prob, scale)
    for j in js:
        if np.linalg.norm(ut[j]) > v_rest:
            prob.stuck[j] = False
            prob.slip_dir[j] = ut[j] / np.linalg.norm(ut[j])
        else:
            rest.append(j)
    cand = sorted(set(rest) | {j for j in np.flatnonzero(prob.stuck) if lam_n[j] > 0
                               or j in js})
    for j in cand:
        y[prob.layout.ut_of(j)] = 0.0
        prob.stuck[j] = True
    while cand:
        mask = np.zeros(s, dtype=bool)
        mask[cand] = True
        lt = _sticking_forces(prob, lam_n, mask)
        norm = np.linalg.norm(lt, axis=1)
        cone = prob.mu_s[cand] * lam_n[cand]
        excess = norm - cone * (1 + 1e-12)
        # A couple at zero load sticks only with zero force (to round-off of the loads).
        excess = np.where(cone > 0, excess, norm - 1e-12 * max(lam_n.max(), 1e-300))
        k = int(np.argmax(excess / np.maximum(cone, 1e-300)))
        if excess[k] <= 0:
            break
        j = cand.pop(k)
        prob.stuck[j] = False
        prob.slip_dir[j] = -lt[k] / norm[k]
    for j in sorted(set(js) | set(np.flatnonzero(was != prob.stuck))):
        if prob.stuck[j] and not was[j]:
            events.append(ImpactEvent(impulse, "stick", j))
        elif not prob.stuck[j] and np.linalg.norm(ut[j]) <= 1e-12 * scale:
            events.append(ImpactEvent(impulse, "slip" if was[j] else "slip_reversal", j))


def on_friction_event(prob, y, j, events, impulse):
    """Couple j's friction event function crossed zero: a sticking couple's force reached the
    static cone (it slips along minus that force, the others that stick are decided again with
    it), or a sliding couple's u_t along its slip direction fell to the speed of rest (within
    `rest_speed` it came to rest: decide; otherwise its direction turned: follow it)."""
    if prob.stuck[j]:
        lam_n = probe_loads(prob, y)
        mask = prob.stuck & ((lam_n > 0) | (np.arange(prob.s) == j))
        lt = _sticking_forces(prob, lam_n, mask)[list(np.flatnonzero(mask)).index(j)]
        prob.stuck[j] = False
        if np.linalg.norm(lt) > 0:
            prob.slip_dir[j] = -lt / np.linalg.norm(lt)
        events.append(ImpactEvent(impulse, "slip", j))
        others = [k for k in np.flatnonzero(prob.stuck) if k != j]
        if others:
            select_impact_friction_modes(prob, y, others, events, impulse)
    else:
        ut = tangential_pairs(prob, y)[j]
        scale = np.abs(y[prob.layout.u]).max()
        if np.linalg.norm(ut) <= rest_speed(prob, scale):
            select_impact_friction_modes(prob, y, [j], events, impulse)
        else:
            prob.slip_dir[j] = ut / np.linalg.norm(ut)
