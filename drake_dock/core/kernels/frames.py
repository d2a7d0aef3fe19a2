"""The contact frame and its rates along a couple (Definition 2; the Eq. 52 bias terms) for the
couple kernels (`couples`), the 3-vector arithmetic they share (3-vectors are tuples of
floats), and `Frame`, the record of a body-fixed frame's pose and twist that the couples and
the bushing take."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit


class Frame(NamedTuple):
    """A body-fixed frame in the world: its rotation R (3, 3), its origin o, and its twist, the
    angular velocity w and the velocity v of its origin (3-tuples)."""
    R: np.ndarray
    o: tuple
    w: tuple
    v: tuple


def frame(R, o, w=(0.0, 0.0, 0.0), v=(0.0, 0.0, 0.0)) -> Frame:
    """The `Frame` of a pose (R, o) and a twist (w, v) given as any arrays, in the types the
    kernels are compiled for: R C-contiguous float64, the vectors 3-tuples of floats (from
    Python; `frame_of` builds them in compiled code)."""
    def vec(a):
        return float(a[0]), float(a[1]), float(a[2])
    return Frame(np.ascontiguousarray(R, dtype=float), vec(o), vec(w), vec(v))


@njit(cache=True)
def frame_of(a, R, o, w, vf):
    """Frame a's `Frame` from the frames' stacked poses and twists: R (F, 3, 3), o, w, vf
    (F, 3)."""
    return Frame(R[a], (o[a, 0], o[a, 1], o[a, 2]), (w[a, 0], w[a, 1], w[a, 2]),
                 (vf[a, 0], vf[a, 1], vf[a, 2]))


@njit(cache=True)
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True)
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True)
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@njit(cache=True)
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True)
def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


@njit(cache=True)
def axpy(s, a, b):
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


@njit(cache=True)
def unit(a):
    na = math.sqrt(dot(a, a))
    if na == 0.0:
        return a, 1.0
    return mul(a, 1.0 / na), na


@njit(cache=True)
def perp_rate(unit, rate, norm):
    """d/dt (a/|a|) = (I - u u^T) a' / |a|."""
    return mul(axpy(-dot(unit, rate), unit, rate), 1.0 / norm)


@njit(cache=True, inline="always")
def frame_rates_cc(t1, t2, t1dot, t2dot, w1, w2, u1dot, u2dot, sigma):
    """C-C: n = sigma t1 x t2 / |t1 x t2|, ta = t2 / |t2| and their rates from the tangents'
    rates; conv, the part of the contact points' relative acceleration due to the couple's
    motion along the bodies, w1 x t1 u1' - w2 x t2 u2'. Returns (n, n', ta, ta', conv)."""
    n_hat, c_norm = unit(cross(t1, t2))
    n = mul(n_hat, sigma)
    ndot = mul(perp_rate(n_hat, add(cross(t1dot, t2), cross(t1, t2dot)), c_norm), sigma)
    ta, t2_norm = unit(t2)
    tadot = perp_rate(ta, t2dot, t2_norm)
    conv = sub(cross(w1, mul(t1, u1dot)), cross(w2, mul(t2, u2dot)))
    return n, ndot, ta, tadot, conv


@njit(cache=True)
def frame_rates_cs(t1, su, sv, sudot, svdot, N, w1, w2, u1dot, u2dot_a, u2dot_b, sigma):
    """C-S: n = sigma N / |N| (N = su x sv), ta = su / |su| and their rates; conv as for C-C
    with the surface point moving along su u2a' + sv u2b'. Returns (n, n', ta, ta', conv)."""
    N_hat, N_norm = unit(N)
    n = mul(N_hat, sigma)
    ndot = mul(perp_rate(N_hat, add(cross(sudot, sv), cross(su, svdot)), N_norm), sigma)
    ta, su_norm = unit(su)
    tadot = perp_rate(ta, sudot, su_norm)
    conv = sub(cross(w1, mul(t1, u1dot)), cross(w2, axpy(u2dot_b, sv, mul(su, u2dot_a))))
    return n, ndot, ta, tadot, conv


@njit(cache=True, inline="always")
def frame_rates_pc(d, t2, ddot, t2dot, w2, u2dot, sigma):
    """P-C (a point against a curve, d = p - c(s)): n = sigma d / |d|, ta = t2 / |t2| and their
    rates from d' (= v_rel - t2 s') and t2'; conv = -w2 x t2 s' (the point has no parameter).
    Returns (n, n', ta, ta', conv)."""
    d_hat, d_norm = unit(d)
    n = mul(d_hat, sigma)
    ndot = mul(perp_rate(d_hat, ddot, d_norm), sigma)
    ta, t2_norm = unit(t2)
    tadot = perp_rate(ta, t2dot, t2_norm)
    conv = mul(cross(w2, t2), -u2dot)
    return n, ndot, ta, tadot, conv
