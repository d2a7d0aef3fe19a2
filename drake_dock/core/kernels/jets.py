"""Patch jets (r, T, K) of Definition 1 by kind code and parameter array, compiled.

A patch is described to the kernels by an integer kind and a float64 parameter array
(`patch_spec`); `jet` evaluates it at one parameter point with the floating-point operations,
in their order, of the patch's own `jet` (drake_dock.core.patches). The kinds:

- CIRCLE  [radius, height]: `Circle`.
- SEGMENT [a (3), b (3)]: `Segment`.
- PLANE   [o (3), e0 (3), e1 (3)]: `PlaneRect`.
- CONE    [R0, cot alpha]: `Cone`.
- SINE_POLAR [A, sigma, phi, tan alpha1, R, alpha2, w_lo, w_hi]: a `PolarCurve` in the sine
  form of Eq. (14), rho = A / sin(w), w = alpha2 + sigma (theta - phi), z = (R - rho) tan alpha1
  (a guide side); beyond its reach w_lo <= w <= w_hi (w modulo 2 pi) rho is held.
- ANNULUS [height]: `Annulus`, u = (rho, theta). An `Arc` is a CIRCLE (its domain is the
  patch's, not the kernel's).
- PETAL [R0, cot alpha, phi0, cot alpha1, A, alpha2, R, w0, z_lo, z_hi]: a `Cone`
  reparametrized across the petal between two guide sides, theta = phi0 + theta_1(z) +
  s (w0 - 2 theta_1(z)) with theta_1 of Eq. (13) and w0 the petal's angle at its root (pi/3 in
  the paper; a guide surface); beyond its reach z_lo <= z <= z_hi theta_1 is held.

The holds continue a guide side and a guide surface beyond their domains so that every
evaluation is finite (docs/model.md, "Patches beyond their domains").

Each jet is returned as six 3-tuples (r, T0, T1, K00, K01, K11); a curve's T1, K01, K11 are
zero. `position` is r alone, with the same operations as `jet` (the same bits) and none of the
derivatives: the seek's grids need only points.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from drake_dock.core.patches import Annulus, Circle, Cone, PlaneRect, PolarCurve, \
    Reparametrized, Segment

CIRCLE, SEGMENT, PLANE, CONE, SINE_POLAR, PETAL, ANNULUS = range(7)
N_PARAMS = 10
_Z = (0.0, 0.0, 0.0)


def patch_spec(patch):
    """(kind, parameters (N_PARAMS,)) of a patch, or None for a patch no kernel describes."""
    prm = np.zeros(N_PARAMS)
    if isinstance(patch, Circle):
        kind, vals = CIRCLE, [patch.radius, patch.height]
    elif isinstance(patch, Segment):
        kind, vals = SEGMENT, [*patch.a, *patch.b]
    elif isinstance(patch, PlaneRect):
        kind, vals = PLANE, [*patch.o, *patch.e0, *patch.e1]
    elif isinstance(patch, Annulus):
        kind, vals = ANNULUS, [patch.height]
    elif isinstance(patch, Cone):
        kind, vals = CONE, [patch.R0, patch.cot]
    elif isinstance(patch, PolarCurve) and patch.kernel_params is not None:
        kind, vals = SINE_POLAR, list(patch.kernel_params)
    elif (isinstance(patch, Reparametrized) and type(patch.base) is Cone
          and getattr(patch.phi, "kernel_params", None) is not None):
        kind, vals = PETAL, [patch.base.R0, patch.base.cot, *patch.phi.kernel_params]
    else:
        return None
    prm[:len(vals)] = [float(v) for v in vals]
    return kind, prm


@njit(cache=True, inline="always")
def _polar(r, r1, r2, z, z1, z2, th):
    c, s = math.cos(th), math.sin(th)
    return ((r * c, r * s, z), (r1 * c - r * s, r1 * s + r * c, z1), _Z,
            (r2 * c - 2 * r1 * s - r * c, r2 * s + 2 * r1 * c - r * s, z2), _Z, _Z)


@njit(cache=True)
def _cone(R0, cot, th, z):
    rho = R0 - z * cot
    c, s = math.cos(th), math.sin(th)
    r_thz = (cot * s, -cot * c, 0.0)
    return ((rho * c, rho * s, z), (-rho * s, rho * c, 0.0), (-cot * c, -cot * s, 1.0),
            (-rho * c, -rho * s, 0.0), r_thz, _Z)


@njit(cache=True)
def _petal_z(prm, z):
    """(z held in a PETAL's reach [z_lo, z_hi], whether z lies in it)."""
    inside = prm[8] <= z <= prm[9]
    return (z if inside else min(max(z, prm[8]), prm[9])), inside


@njit(cache=True, inline="always")
def _petal(prm, a, z):
    """`_PetalMap.jet` composed with the cone's jet by `Reparametrized.jet`'s chain rule;
    theta_1 held beyond the reach (its derivatives zero there)."""
    cot, phi0, A, alpha2, R = prm[3], prm[2], prm[4], prm[5], prm[6]
    zh, inside = _petal_z(prm, z)
    rho = R - zh * cot
    x = A / rho
    x1 = x * cot / rho
    x2 = 2.0 * x * math.pow(cot, 2.0) / math.pow(rho, 2.0)
    q = math.sqrt(1.0 - x * x)
    t1 = math.asin(x) - alpha2
    d1, d2 = 0.0, 0.0
    if inside:
        d1, d2 = x1 / q, x2 / q + x * math.pow(x1, 2.0) / math.pow(q, 3.0)
    w = prm[7] - 2 * t1
    j00, j01, j10, j11 = w, d1 * (1 - 2 * a), 0.0, 1.0
    h001 = -2 * d1
    h011 = d2 * (1 - 2 * a)
    rb, B0, B1, B00, B01, B11 = _cone(prm[0], prm[1], phi0 + t1 + a * w, z)
    T0 = (B0[0] * j00 + B1[0] * j10, B0[1] * j00 + B1[1] * j10, B0[2] * j00 + B1[2] * j10)
    T1 = (B0[0] * j01 + B1[0] * j11, B0[1] * j01 + B1[1] * j11, B0[2] * j01 + B1[2] * j11)
    K00 = _second(B0, B1, B00, B01, B11, j00, j10, j00, j10, 0.0, 0.0)
    K01 = _second(B0, B1, B00, B01, B11, j00, j10, j01, j11, h001, 0.0)
    K11 = _second(B0, B1, B00, B01, B11, j01, j11, j01, j11, h011, 0.0)
    return rb, T0, T1, K00, K01, K11


@njit(cache=True)
def _second(B0, B1, B00, B01, B11, ua0, ua1, ub0, ub1, h0, h1):
    c00, c01, c10, c11 = ua0 * ub0, ua0 * ub1, ua1 * ub0, ua1 * ub1
    return (B00[0] * c00 + B01[0] * (c01 + c10) + B11[0] * c11 + B0[0] * h0 + B1[0] * h1,
            B00[1] * c00 + B01[1] * (c01 + c10) + B11[1] * c11 + B0[1] * h0 + B1[1] * h1,
            B00[2] * c00 + B01[2] * (c01 + c10) + B11[2] * c11 + B0[2] * h0 + B1[2] * h1)


@njit(cache=True)
def _sine_angle(prm, u0):
    """A SINE_POLAR's angle w = alpha2 + sigma (theta - phi) and whether rho is held: w taken
    modulo 2 pi (into [w_0, w_0 + 2 pi), w_0 = (w_lo + w_hi) / 2 - pi) when it lies outside
    the reach [w_lo, w_hi], and held at the reach's nearer end beyond it."""
    w = prm[5] + prm[1] * (u0 - prm[2])
    lo, hi = prm[6], prm[7]
    if lo <= w <= hi:
        return w, False
    w0 = 0.5 * (lo + hi) - math.pi
    w = w0 + (w - w0) % (2.0 * math.pi)
    if lo <= w <= hi:
        return w, False
    return min(max(w, lo), hi), True


@njit(cache=True)
def jet(kind, prm, u0, u1):
    """(r, T0, T1, K00, K01, K11) of the patch (kind, prm) at u = (u0[, u1])."""
    if kind == CIRCLE:
        R, h = prm[0], prm[1]
        c, s = math.cos(u0), math.sin(u0)
        return (R * c, R * s, h), (-R * s, R * c, 0.0), _Z, (-R * c, -R * s, 0.0), _Z, _Z
    if kind == SEGMENT:
        e = (prm[3] - prm[0], prm[4] - prm[1], prm[5] - prm[2])
        return ((prm[0] + u0 * e[0], prm[1] + u0 * e[1], prm[2] + u0 * e[2]), e, _Z, _Z, _Z,
                _Z)
    if kind == PLANE:
        e0 = (prm[3], prm[4], prm[5])
        e1 = (prm[6], prm[7], prm[8])
        return ((prm[0] + u0 * e0[0] + u1 * e1[0], prm[1] + u0 * e0[1] + u1 * e1[1],
                 prm[2] + u0 * e0[2] + u1 * e1[2]), e0, e1, _Z, _Z, _Z)
    if kind == CONE:
        return _cone(prm[0], prm[1], u0, u1)
    if kind == SINE_POLAR:
        A, sigma, tan1, R = prm[0], prm[1], prm[3], prm[4]
        w, held = _sine_angle(prm, u0)
        sw, cw = math.sin(w), math.cos(w)
        rho = A / sw
        r1, r2 = 0.0, 0.0
        if not held:
            r1 = -sigma * A * cw / math.pow(sw, 2.0)
            r2 = A * (1.0 + math.pow(cw, 2.0)) / math.pow(sw, 3.0)
        return _polar(rho, r1, r2, (R - rho) * tan1, -r1 * tan1, -r2 * tan1, u0)
    if kind == ANNULUS:
        c, s = math.cos(u1), math.sin(u1)
        r_rt = (-s, c, 0.0)
        return ((u0 * c, u0 * s, prm[0]), (c, s, 0.0), (-u0 * s, u0 * c, 0.0), _Z, r_rt,
                (-u0 * c, -u0 * s, 0.0))
    return _petal(prm, u0, u1)


@njit(cache=True)
def position(kind, prm, u0, u1):
    """r of `jet` (the same operations, the same bits) without the derivatives."""
    if kind == CIRCLE:
        return prm[0] * math.cos(u0), prm[0] * math.sin(u0), prm[1]
    if kind == SEGMENT:
        return (prm[0] + u0 * (prm[3] - prm[0]), prm[1] + u0 * (prm[4] - prm[1]),
                prm[2] + u0 * (prm[5] - prm[2]))
    if kind == PLANE:
        return (prm[0] + u0 * prm[3] + u1 * prm[6], prm[1] + u0 * prm[4] + u1 * prm[7],
                prm[2] + u0 * prm[5] + u1 * prm[8])
    if kind == CONE:
        rho = prm[0] - u1 * prm[1]
        return rho * math.cos(u0), rho * math.sin(u0), u1
    if kind == SINE_POLAR:
        rho = prm[0] / math.sin(_sine_angle(prm, u0)[0])
        return rho * math.cos(u0), rho * math.sin(u0), (prm[4] - rho) * prm[3]
    if kind == ANNULUS:
        return u0 * math.cos(u1), u0 * math.sin(u1), prm[0]
    return petal_point(prm, u0, u1, petal_row(prm, u1))


@njit(cache=True)
def petal_row(prm, z):
    """What a PETAL's point at zeta = z shares with the others at that z (`_petal`): theta_1
    (Eq. 13), the petal's angle w0 - 2 theta_1 and the cone's radius (Eq. 12)."""
    t1 = math.asin(prm[4] / (prm[6] - _petal_z(prm, z)[0] * prm[3])) - prm[5]
    return t1, prm[7] - 2 * t1, prm[0] - z * prm[1]


@njit(cache=True)
def petal_point(prm, s, z, row):
    """A PETAL's r at (s, z) from its `petal_row` at z."""
    t1, w, rho = row
    th = prm[2] + t1 + s * w
    return rho * math.cos(th), rho * math.sin(th), z
