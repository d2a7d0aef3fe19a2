"""The predicted zeros of a set of witness functions from their last values (and rates), for
the step control of `drake_dock.systems.stepping.WitnessApproach`, over arrays, compiled.

Per witness with up to three points (t_k, w_k) of one epoch, w > 0 at the last: the earlier
of the secant through the last two and of the parabola through the last three (a witness
falling ever faster, such as the gap of a couple accelerating towards contact, is reached
earlier than its secant says); with known rates, also the first zero of its Taylor parabola
w + w' h + w'' h^2 / 2, w'' from the last two rates.
"""
from __future__ import annotations

import math

from numba import njit
from drake_dock.core.kernels.copies import copy1


@njit(cache=True, inline="always")
def lead_points(t0, w0, t1, w1, t2, w2, n):
    """Time from t2 to the predicted zero of the witness through its last n points (2 or 3,
    the oldest first: (t0, w0) only when n == 3), inf if none is predicted ahead."""
    lead = math.inf
    if n < 2:
        return lead
    s12 = (w2 - w1) / (t2 - t1)
    if s12 < 0.0:
        lead = w2 / -s12
    if n == 3:
        s01 = (w1 - w0) / (t1 - t0)
        c = (s12 - s01) / (t2 - t0)            # w(t2 + h) = w2 + b h + c h^2
        b = s12 + c * (t2 - t1)
        if c != 0.0:
            disc = b * b - 4.0 * c * w2
            if disc >= 0.0:
                r = math.sqrt(disc)
                # roots h = (-b -+ r) / (2c), written without cancellation
                q = -0.5 * (b + math.copysign(r, b))
                h1 = q / c
                h2 = w2 / q if q != 0.0 else math.inf
                best = math.inf
                if h1 > 0.0:
                    best = h1
                if h2 > 0.0:
                    best = min(best, h2)
                lead = min(lead, best)
    return lead


@njit(cache=True)
def lead_jet(w, wd, wdd):
    """Time to the first zero of w + wd h + wdd h^2 / 2, inf if none ahead."""
    a, b, c = 0.5 * wdd, wd, w
    if a == 0.0:
        return -c / b if b < 0.0 else math.inf
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return math.inf
    r = math.sqrt(disc)
    q = -0.5 * (b + math.copysign(r, b))
    h1 = q / a
    h2 = c / q if q != 0.0 else math.inf
    best = math.inf
    if h1 > 0.0:
        best = h1
    if h2 > 0.0:
        best = min(best, h2)
    return best


@njit(cache=True)
def earliest_zero(T, W, D, npts, need):
    """The earliest predicted zero time over the witnesses j (columns): T (3,) the times of the
    history's rows, the last row the current one, of which the last ``npts`` are valid (1 to
    3); W (3, n) the values, D (3, n) the rates (NaN where unknown). A witness with a current
    rate but no earlier one has need[j] set (its second rate is asked for, `lead_jet`).
    Returns the earliest zero time (inf if none)."""
    best = math.inf
    t2 = T[2]
    for j in range(W.shape[1]):
        w2 = W[2, j]
        need[j] = False
        if not w2 > 0.0:
            continue
        if npts >= 2:
            lead = lead_points(T[0], W[0, j], T[1], W[1, j], t2, w2, npts)
            best = min(best, t2 + lead)
        r2 = D[2, j]
        if not math.isnan(r2):
            if npts >= 2 and not math.isnan(D[1, j]):
                wdd = (r2 - D[1, j]) / (t2 - T[1])
                best = min(best, t2 + lead_jet(w2, r2, wdd))
            else:
                need[j] = True
    return best


@njit(cache=True)
def push(T, W, D, n, t, w, d):
    """Appends the point (t, w (n_w,), d (n_w,)) to the history (T (3,), W, D (3, n_w)) of n
    valid rows (the last ones), replacing the last row when t is not after it; returns the
    new number of valid rows (at most 3)."""
    if n > 0 and not T[2] < t:
        n -= 1
        for r in (1, 0):
            T[r + 1] = T[r]
            copy1(W[r + 1], W[r])
            copy1(D[r + 1], D[r])
    for r in range(2):
        T[r] = T[r + 1]
        copy1(W[r], W[r + 1])
        copy1(D[r], D[r + 1])
    T[2] = t
    copy1(W[2], w)
    copy1(D[2], d)
    return min(n + 1, 3)


def warm():
    """Compiles or loads the predictions on a history of two witnesses."""
    import numpy as np
    T, W, D = np.full(3, np.nan), np.zeros((3, 2)), np.full((3, 2), np.nan)
    n = 0
    for t in (0.0, 0.1, 0.2):
        n = push(T, W, D, n, t, np.array([1.0 - t, 2.0]), np.array([-1.0, np.nan]))
    earliest_zero(T, W, D, n, np.zeros(2, dtype=np.bool_))
    lead_jet(1.0, -1.0, 0.5)
