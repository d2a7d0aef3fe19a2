"""Parametric curves and surfaces ("patches", Definition 1 of the paper).

A patch maps parameters u (shape (..., dim), dim = 1 for a curve, 2 for a surface) to points of
R^3 in its body frame. Every patch provides, vectorised over leading axes:

- ``position(u)``  -> (..., 3)
- ``first(u)``     -> (..., 3, dim)       d r / d u
- ``second(u)``    -> (..., 3, dim, dim)  d^2 r / d u d u

and, for one parameter point, ``jet(u)`` -> (r, T, K): the same three as tuples of floats (r a
3-tuple, T[a] and K[a][b] 3-tuples), the form the couple evaluation works in (a patch evaluated
at one point is cheaper in plain floats than in numpy); and a box domain lower <= u <= upper; a
parameter may be periodic (a full circle), wrapped instead of bounded. `posed` maps a patch to
the world through a body pose, Eq. (20): r = p_WB + R_WB r'(u).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np


class Patch:
    """Base class. Subclasses set ``dim``, ``lower``, ``upper``, ``periodic`` and implement the
    three evaluation methods."""

    dim: int
    lower: np.ndarray
    upper: np.ndarray
    periodic: tuple[bool, ...]

    def position(self, u):
        raise NotImplementedError

    def first(self, u):
        raise NotImplementedError

    def second(self, u):
        raise NotImplementedError

    def jet(self, u):
        """(r, T, K) at one point u as tuples of floats (module docstring); this default goes
        through the vectorised methods, subclasses write it out."""
        u = np.asarray(u, dtype=float)
        r = tuple(self.position(u).tolist())
        T = tuple(tuple(c) for c in self.first(u).T.tolist())
        K2 = self.second(u)
        K = tuple(tuple(tuple(K2[:, a, b].tolist()) for b in range(self.dim))
                  for a in range(self.dim))
        return r, T, K

    # Domain helpers -------------------------------------------------------------------------
    def wrap(self, u):
        """Wraps periodic parameters into [lower, upper)."""
        u = np.array(u, dtype=float)
        for k, per in enumerate(self.periodic):
            if per:
                span = self.upper[k] - self.lower[k]
                u[..., k] = self.lower[k] + np.mod(u[..., k] - self.lower[k], span)
        return u

    def clip(self, u):
        """Wraps periodic parameters and clips the others into the domain."""
        u, bounded = self.wrap(u), ~np.asarray(self.periodic, dtype=bool)
        u[..., bounded] = np.clip(u[..., bounded], self.lower[bounded], self.upper[bounded])
        return u

    def margin(self, u):
        """Per parameter, the distance to the nearest end of the domain (negative outside);
        +inf for periodic parameters. Shape (..., dim)."""
        u = np.asarray(u, dtype=float)
        m = np.minimum(u - self.lower, self.upper - u)
        m[..., np.asarray(self.periodic, dtype=bool)] = np.inf
        return m

    def grid(self, n):
        """A tensor grid of n points per parameter covering the domain, shape (n**dim, dim).
        Periodic parameters are sampled without repeating the end point."""
        axes = [np.linspace(self.lower[k], self.upper[k], n, endpoint=not self.periodic[k])
                for k in range(self.dim)]
        mesh = np.meshgrid(*axes, indexing="ij")
        return np.stack([m.ravel() for m in mesh], axis=-1)

    def grid_points(self, n):
        """(`grid` (n), positions there), computed once per patch and n (read-only arrays):
        the coarse grid every seek of the patch starts from."""
        cache = self.__dict__.setdefault("_grid_points", {})
        hit = cache.get(n)
        if hit is None:
            U = self.grid(n)
            r = self.position(U)
            U.flags.writeable = False
            r.flags.writeable = False
            hit = cache[n] = (U, r)
        return hit

    def kernel_domain(self, n):
        """(lower, upper, periodic, `grid` (n)) as the seek's kernels take them (writable copies:
        one compiled signature), computed once per patch and n."""
        cache = self.__dict__.setdefault("_kernel_domain", {})
        if n not in cache:
            cache[n] = (np.array(self.lower, dtype=float), np.array(self.upper, dtype=float),
                        np.array(self.periodic), np.array(self.grid_points(n)[0]))
        return cache[n]

    @property
    def span(self):
        return self.upper - self.lower


class Circle(Patch):
    """Circle of radius ``radius`` in the plane z = ``height`` of its frame, centred on the z axis;
    u = (theta,), periodic on [0, 2 pi)."""

    dim = 1
    periodic = (True,)

    def __init__(self, radius: float, height: float = 0.0):
        self.radius = float(radius)
        self.height = float(height)
        self.lower = np.array([0.0])
        self.upper = np.array([2.0 * np.pi])

    def position(self, u):
        th = np.asarray(u, dtype=float)[..., 0]
        return np.stack([self.radius * np.cos(th), self.radius * np.sin(th),
                         np.full_like(th, self.height)], axis=-1)

    def first(self, u):
        th = np.asarray(u, dtype=float)[..., 0]
        d = np.stack([-self.radius * np.sin(th), self.radius * np.cos(th), np.zeros_like(th)],
                     axis=-1)
        return d[..., None]

    def second(self, u):
        th = np.asarray(u, dtype=float)[..., 0]
        d = np.stack([-self.radius * np.cos(th), -self.radius * np.sin(th), np.zeros_like(th)],
                     axis=-1)
        return d[..., None, None]

    def jet(self, u):
        R = self.radius
        c, s = math.cos(u[0]), math.sin(u[0])
        return (R * c, R * s, self.height), ((-R * s, R * c, 0.0),), (((-R * c, -R * s, 0.0),),)


class Point(Patch):
    """A point ``p`` of its frame (a 0-D patch, u = ()), rounded to a sphere of radius
    ``radius`` >= 0 (a petal corner, `drake_dock.core.couple`, kinds "PC" and "PS"): its
    couple with a curve has the gap |p - c(s)| - radius, with a surface n . (p - s(u)) -
    radius."""

    dim = 0
    periodic = ()

    def __init__(self, p, radius: float = 0.0):
        self.p = np.asarray(p, dtype=float).reshape(3)
        self.radius = float(radius)
        self.lower = np.zeros(0)
        self.upper = np.zeros(0)

    def position(self, u):
        u = np.asarray(u, dtype=float)
        return np.broadcast_to(self.p, u.shape[:-1] + (3,)).copy()

    def first(self, u):
        return np.zeros(np.asarray(u).shape[:-1] + (3, 0))

    def second(self, u):
        return np.zeros(np.asarray(u).shape[:-1] + (3, 0, 0))

    def jet(self, u):
        return tuple(self.p.tolist()), (), ()

    def grid(self, n):
        return np.zeros((1, 0))


class Arc(Circle):
    """Arc of the circle of radius ``radius`` in the plane z = ``height`` of its frame, centred
    on the z axis, for theta in ``theta_range`` (a petal's tip arc); u = (theta,), bounded."""

    periodic = (False,)

    def __init__(self, radius: float, height: float, theta_range):
        super().__init__(radius, height)
        self.lower = np.array([min(theta_range)], dtype=float)
        self.upper = np.array([max(theta_range)], dtype=float)


class Annulus(Patch):
    """The plane region r_in <= rho <= r_out of the plane z = ``height`` (a ring's face),
    u = (rho, theta), theta periodic on [0, 2 pi); its normal N = r_rho x r_theta is +z."""

    dim = 2
    periodic = (False, True)

    def __init__(self, r_in: float, r_out: float, height: float = 0.0):
        self.height = float(height)
        self.lower = np.array([float(r_in), 0.0])
        self.upper = np.array([float(r_out), 2.0 * np.pi])

    def position(self, u):
        u = np.asarray(u, dtype=float)
        rho, th = u[..., 0], u[..., 1]
        return np.stack([rho * np.cos(th), rho * np.sin(th), np.full_like(th, self.height)],
                        axis=-1)

    def first(self, u):
        u = np.asarray(u, dtype=float)
        rho, th = u[..., 0], u[..., 1]
        c, s, z = np.cos(th), np.sin(th), np.zeros_like(th)
        return np.stack([np.stack([c, s, z], -1), np.stack([-rho * s, rho * c, z], -1)], -1)

    def second(self, u):
        u = np.asarray(u, dtype=float)
        rho, th = u[..., 0], u[..., 1]
        c, s, z = np.cos(th), np.sin(th), np.zeros_like(th)
        r_rt = np.stack([-s, c, z], axis=-1)
        out = np.zeros(th.shape + (3, 2, 2))
        out[..., 0, 1] = out[..., 1, 0] = r_rt
        out[..., 1, 1] = np.stack([-rho * c, -rho * s, z], axis=-1)
        return out

    def jet(self, u):
        rho, th = float(u[0]), float(u[1])
        c, s = math.cos(th), math.sin(th)
        r_rt = (-s, c, 0.0)
        return ((rho * c, rho * s, self.height), ((c, s, 0.0), (-rho * s, rho * c, 0.0)),
                (((0.0, 0.0, 0.0), r_rt), (r_rt, (-rho * c, -rho * s, 0.0))))


class AnnularSector(Annulus):
    """The part theta_range of an `Annulus` (a petal's tip land): the same u = (rho, theta)
    and normal +z, theta bounded, not periodic."""

    periodic = (False, False)

    def __init__(self, r_in: float, r_out: float, height: float, theta_range):
        super().__init__(r_in, r_out, height)
        self.lower[1], self.upper[1] = min(theta_range), max(theta_range)


class Segment(Patch):
    """Straight segment a + u (b - a), u in [0, 1]."""

    dim = 1
    periodic = (False,)

    def __init__(self, a, b):
        self.a = np.asarray(a, dtype=float)
        self.b = np.asarray(b, dtype=float)
        self.lower = np.array([0.0])
        self.upper = np.array([1.0])

    def position(self, u):
        s = np.asarray(u, dtype=float)[..., :1]
        return self.a + s * (self.b - self.a)

    def first(self, u):
        s = np.asarray(u, dtype=float)[..., 0]
        return np.broadcast_to((self.b - self.a)[:, None], s.shape + (3, 1)).copy()

    def second(self, u):
        s = np.asarray(u, dtype=float)[..., 0]
        return np.zeros(s.shape + (3, 1, 1))

    def jet(self, u):
        a, b, s = self.a, self.b, float(u[0])
        e = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
        return ((a[0] + s * e[0], a[1] + s * e[1], a[2] + s * e[2]), (e,),
                (((0.0, 0.0, 0.0),),))


class PlaneRect(Patch):
    """Rectangle o + u0 e0 + u1 e1, u in [0, a] x [0, b] (e0, e1 need not be unit)."""

    dim = 2
    periodic = (False, False)

    def __init__(self, origin, e0, e1, size=(1.0, 1.0)):
        self.o = np.asarray(origin, dtype=float)
        self.e0 = np.asarray(e0, dtype=float)
        self.e1 = np.asarray(e1, dtype=float)
        self.lower = np.zeros(2)
        self.upper = np.asarray(size, dtype=float)

    def position(self, u):
        u = np.asarray(u, dtype=float)
        return self.o + u[..., :1] * self.e0 + u[..., 1:2] * self.e1

    def first(self, u):
        u = np.asarray(u, dtype=float)
        return np.broadcast_to(np.stack([self.e0, self.e1], axis=-1),
                               u.shape[:-1] + (3, 2)).copy()

    def second(self, u):
        u = np.asarray(u, dtype=float)
        return np.zeros(u.shape[:-1] + (3, 2, 2))

    def jet(self, u):
        o, e0, e1 = self.o, self.e0, self.e1
        a, b = float(u[0]), float(u[1])
        z = (0.0, 0.0, 0.0)
        return (tuple((o + a * e0 + b * e1).tolist()), (tuple(e0.tolist()), tuple(e1.tolist())),
                ((z, z), (z, z)))


class Cone(Patch):
    """Right circular cone about the z axis, rho = R0 - z cot(alpha), parameters
    u = (theta, z) on the box [theta0, theta1] x [z0, z1] (Eq. 12 with R0 = R)."""

    dim = 2
    periodic = (False, False)

    def __init__(self, R0: float, alpha: float, theta_range, z_range):
        self.R0 = float(R0)
        self.cot = 1.0 / np.tan(alpha)
        self.lower = np.array([theta_range[0], z_range[0]], dtype=float)
        self.upper = np.array([theta_range[1], z_range[1]], dtype=float)

    def position(self, u):
        u = np.asarray(u, dtype=float)
        th, z = u[..., 0], u[..., 1]
        rho = self.R0 - z * self.cot
        return np.stack([rho * np.cos(th), rho * np.sin(th), z], axis=-1)

    def first(self, u):
        u = np.asarray(u, dtype=float)
        th, z = u[..., 0], u[..., 1]
        rho = self.R0 - z * self.cot
        c, s = np.cos(th), np.sin(th)
        r_th = np.stack([-rho * s, rho * c, np.zeros_like(th)], axis=-1)
        r_z = np.stack([-self.cot * c, -self.cot * s, np.ones_like(th)], axis=-1)
        return np.stack([r_th, r_z], axis=-1)

    def second(self, u):
        u = np.asarray(u, dtype=float)
        th, z = u[..., 0], u[..., 1]
        rho = self.R0 - z * self.cot
        c, s = np.cos(th), np.sin(th)
        zero = np.zeros_like(th)
        r_thth = np.stack([-rho * c, -rho * s, zero], axis=-1)
        r_thz = np.stack([self.cot * s, -self.cot * c, zero], axis=-1)
        r_zz = np.stack([zero, zero, zero], axis=-1)
        out = np.empty(th.shape + (3, 2, 2))
        out[..., 0, 0] = r_thth
        out[..., 0, 1] = r_thz
        out[..., 1, 0] = r_thz
        out[..., 1, 1] = r_zz
        return out

    def jet(self, u):
        th, z = float(u[0]), float(u[1])
        cot = self.cot
        rho = self.R0 - z * cot
        c, s = math.cos(th), math.sin(th)
        r_thz = (cot * s, -cot * c, 0.0)
        return ((rho * c, rho * s, z), ((-rho * s, rho * c, 0.0), (-cot * c, -cot * s, 1.0)),
                (((-rho * c, -rho * s, 0.0), r_thz), (r_thz, (0.0, 0.0, 0.0))))


class Reparametrized(Patch):
    """A patch composed with a parameter map phi: s -> u = phi(s), so that r(s) = base(phi(s)).

    ``phi`` is an object with ``value(s)`` (..., dim), ``jac(s)`` (..., dim, dim) and
    ``hess(s)`` (..., dim, dim, dim) (d u_i / d s_a d s_b), and the box ``lower``/``upper`` of s.
    Derivatives follow the chain rule:
        r_a = sum_i B_i u_i,a
        r_ab = sum_ij B_ij u_i,a u_j,b + sum_i B_i u_i,ab
    """

    def __init__(self, base: Patch, phi):
        self.base = base
        self.phi = phi
        self.dim = base.dim
        self.lower = np.asarray(phi.lower, dtype=float)
        self.upper = np.asarray(phi.upper, dtype=float)
        self.periodic = (False,) * self.dim

    def position(self, s):
        return self.base.position(self.phi.value(s))

    def first(self, s):
        u = self.phi.value(s)
        return np.einsum("...xi,...ia->...xa", self.base.first(u), self.phi.jac(s))

    def second(self, s):
        u = self.phi.value(s)
        J = self.phi.jac(s)
        return (np.einsum("...xij,...ia,...jb->...xab", self.base.second(u), J, J)
                + np.einsum("...xi,...iab->...xab", self.base.first(u), self.phi.hess(s)))

    def jet(self, s):
        """The chain rule of the class docstring on floats; ``phi.jet(s)`` -> (u, J, Hs) as
        nested tuples if the map has it."""
        if hasattr(self.phi, "jet"):
            u, J, Hs = self.phi.jet(s)
        else:
            s = np.asarray(s, dtype=float)
            u, J, Hs = (self.phi.value(s).tolist(), self.phi.jac(s).tolist(),
                        self.phi.hess(s).tolist())
        rb, Tb, Kb = self.base.jet(u)
        if self.dim == 1:
            (j,), = J
            (h,), = Hs[0]
            (t,), ((k,),) = Tb, Kb
            return rb, ((j * t[0], j * t[1], j * t[2]),), \
                (((j * j * k[0] + h * t[0], j * j * k[1] + h * t[1], j * j * k[2] + h * t[2]),),)
        (j00, j01), (j10, j11) = J
        B0, B1 = Tb
        (B00, B01), (_, B11) = Kb
        T = (tuple(B0[x] * j00 + B1[x] * j10 for x in range(3)),
             tuple(B0[x] * j01 + B1[x] * j11 for x in range(3)))
        jj = ((j00, j10), (j01, j11))              # jj[a] = (u_0,a, u_1,a)

        def second(a, b):
            (ua0, ua1), (ub0, ub1) = jj[a], jj[b]
            h0, h1 = Hs[0][a][b], Hs[1][a][b]
            c00, c01, c10, c11 = ua0 * ub0, ua0 * ub1, ua1 * ub0, ua1 * ub1
            return tuple(B00[x] * c00 + B01[x] * (c01 + c10) + B11[x] * c11 + B0[x] * h0
                         + B1[x] * h1 for x in range(3))

        K01 = second(0, 1)
        K = ((second(0, 0), K01), (K01, second(1, 1)))
        return rb, T, K


@dataclasses.dataclass(frozen=True)
class Posed:
    """A patch placed in the world by a body pose (R_WB, p_WB): Eq. (20)."""

    patch: Patch
    R: np.ndarray
    p: np.ndarray

    def position(self, u):
        return self.patch.position(u) @ self.R.T + self.p

    def first(self, u):
        return np.einsum("xy,...ya->...xa", self.R, self.patch.first(u))

    def second(self, u):
        return np.einsum("xy,...yab->...xab", self.R, self.patch.second(u))


def posed(patch: Patch, R_WB, p_WB) -> Posed:
    """Eq. (20): r(q, u) = r_O(q) + A(q) r'(u)."""
    return Posed(patch, np.asarray(R_WB, dtype=float), np.asarray(p_WB, dtype=float))


class PolarCurve(Patch):
    """Curve given in cylindrical coordinates by theta: r = (rho cos theta, rho sin theta, z).

    ``radial(theta)`` and ``axial(theta)`` each return a triple (f, f', f'') of arrays; the
    parameter is u = (theta,) on [lower, upper]."""

    dim = 1
    periodic = (False,)

    def __init__(self, radial, axial, theta_range, parts=None, kernel_params=None):
        self.radial = radial
        self.axial = axial
        # For a curve in the sine form of Eq. (14), its parameters for the compiled kernels
        # (drake_dock.core.kernels.jets, kind SINE_POLAR); None otherwise.
        self.kernel_params = kernel_params
        # Optional th -> (radial triple, axial triple) at one float theta, for curves whose
        # axial part follows from the radial one (`jet` then evaluates them once).
        self.parts = parts
        self.lower = np.array([min(theta_range)], dtype=float)
        self.upper = np.array([max(theta_range)], dtype=float)

    def _parts(self, u):
        th = np.asarray(u, dtype=float)[..., 0]
        return th, self.radial(th), self.axial(th), np.cos(th), np.sin(th)

    def position(self, u):
        th, (r, _, _), (z, _, _), c, s = self._parts(u)
        return np.stack([r * c, r * s, z], axis=-1)

    def first(self, u):
        th, (r, r1, _), (z, z1, _), c, s = self._parts(u)
        return np.stack([r1 * c - r * s, r1 * s + r * c, z1], axis=-1)[..., None]

    def second(self, u):
        th, (r, r1, r2), (z, z1, z2), c, s = self._parts(u)
        return np.stack([r2 * c - 2 * r1 * s - r * c, r2 * s + 2 * r1 * c - r * s, z2],
                        axis=-1)[..., None, None]

    def jet(self, u):
        th = float(u[0])
        if self.parts is not None:
            (r, r1, r2), (z, z1, z2) = self.parts(th)
        else:
            r, r1, r2 = (float(a) for a in self.radial(th))
            z, z1, z2 = (float(a) for a in self.axial(th))
        c, s = math.cos(th), math.sin(th)
        return ((r * c, r * s, z), ((r1 * c - r * s, r1 * s + r * c, z1),),
                (((r2 * c - 2 * r1 * s - r * c, r2 * s + 2 * r1 * c - r * s, z2),),))
