"""The hand-over between an edge pair and a surface pair (docs/model.md, "Hand-over between
an edge and a surface"), as small pure functions on numbers.

Body 2 carries a surface S(a) (a = (a0, a1)) and a curve E(e) that is one of S's boundaries:
S's parameter ``fixed`` held at its lower or upper bound, the other one f = `SurfaceEdge.
to_surface` (e). Body 1's curve C (u1) meets either of them: the surface pair (C, S) has the
couple (u1, a), the edge pair (C, E) the couple (u1, e). At a point of the edge the two couples
are the same pair of points: the C-S contact form (Eq. 38) [s_u.d, s_v.d, t1.N] = 0 with a
on the edge, and the C-C form (Eq. 37) [t1.d, t2.d] = 0 with t2 = dE/de (one of s_u, s_v),
hold together exactly when t1.N = 0, i.e. when the C-C normal is the surface's normal. So:

- surface -> edge. Guard: the surface couple's ``fixed`` parameter reaches its bound (the
  domain-end witness). Reset: u = (u1, a) -> (u1, `to_edge` (f)).
- edge -> surface. Guard: `edge_guard`, n . b, the edge couple's normal n (oriented, from
  Body 2 to Body 1) along the surface's outward conormal b at the edge point (the unit tangent
  of S along ``fixed``, pointing out of the domain). Positive while C lies beyond the edge (the
  edge is the nearest part of the plate); at its zero n = +-N and C's point passes over the
  face. Reset: u = (u1, e) -> (u1, a) with a[fixed] on its bound and the other
  `to_surface` (e).

In both directions the pair handed to takes the mode of the pair it continues (tracked, sliding
or sticking) and the orientation sigma that keeps n (`carried_sigma`); the pair it leaves is far.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Callable


@dataclasses.dataclass(frozen=True)
class SurfaceEdge:
    """Curve E is the boundary of surface S where S's parameter ``fixed`` (0 or 1) is at its
    lower (``upper`` False) or upper bound; along it S's other parameter is ``to_surface(e)``
    and, inversely, E's parameter is ``to_edge(f)``. ``kernel_map`` states ``to_surface`` for
    the compiled hand-over guard (`drake_dock.core.kernels.engine.handover_guard`):
    ("affine", alpha, beta) for f = alpha e + beta, or ("component", c) for f = coordinate c
    of E's point E(e) in its frame."""

    fixed: int
    upper: bool
    to_surface: Callable[[float], float]
    to_edge: Callable[[float], float]
    kernel_map: tuple | None = None

    @property
    def free(self) -> int:
        return 1 - self.fixed


def surface_params(edge: SurfaceEdge, lower, upper, e: float) -> list:
    """The surface's parameters (a0, a1) at the edge's parameter e (lower, upper: the
    surface's bounds)."""
    a = [0.0, 0.0]
    a[edge.fixed] = float(upper[edge.fixed] if edge.upper else lower[edge.fixed])
    a[edge.free] = float(edge.to_surface(e))
    return a


#: A seek's couple on the boundary of its domain converges onto the bound from inside: within
#: this fraction of the parameter's span it lies on the edge (`reaches_edge`'s ``rtol``).
SEEK_EDGE_RTOL = 1e-8

#: A pair sought while a pair linked to it by a hand-over holds a contact at their shared
#: edge: its couple is that contact when it lies within this of the edge, as a fraction of the
#: span for a surface couple (`reaches_edge`'s ``rtol``), for an edge couple in its guard
#: (`edge_guard`, a cosine). A seek converges its couple to about 1e-8 of the span and the
#: edge couple's normal to about 1e-9, so at the edge the side it ends on is noise.
SEEK_HELD_TOL = 1e-6


def reaches_edge(edge: SurfaceEdge, lower, upper, a, rtol: float = 0.0) -> bool:
    """Rule: the surface couple a is on or past the edge (its ``fixed`` parameter at or past
    that bound, or within ``rtol`` of its span inside it) and along it (its other parameter
    within its bounds: a couple past a corner is on neither edge's curve)."""
    k, f = edge.fixed, edge.free
    if not lower[f] <= a[f] <= upper[f]:
        return False
    tol = rtol * (upper[k] - lower[k])
    return a[k] >= upper[k] - tol if edge.upper else a[k] <= lower[k] + tol


def to_edge(edge: SurfaceEdge, n1: int, u) -> list:
    """Reset surface -> edge: the couple (u1, a) of the surface pair as the edge pair's
    (u1, e)."""
    u = [float(x) for x in u]
    return u[:n1] + [float(edge.to_edge(u[n1 + edge.free]))]


def to_surface(edge: SurfaceEdge, n1: int, u, lower, upper) -> list:
    """Reset edge -> surface: the couple (u1, e) of the edge pair as the surface pair's
    (u1, a), a on the edge."""
    u = [float(x) for x in u]
    return u[:n1] + surface_params(edge, lower, upper, u[n1])


def edge_guard(edge: SurfaceEdge, n, tangents) -> float:
    """Guard edge -> surface: n . b, with ``tangents`` (s_0, s_1) the surface's world tangents
    at the edge point and b = +-s_fixed / |s_fixed| pointing out of the domain; n is
    perpendicular to the edge, so only the conormal part of s_fixed counts."""
    s = tangents[edge.fixed]
    norm = math.sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2])
    dot = n[0] * s[0] + n[1] * s[1] + n[2] * s[2]
    return (dot if edge.upper else -dot) / norm


def carried_sigma(n, n_raw) -> float:
    """The orientation sigma of the pair handed to that keeps the normal n of the pair it
    continues: sigma n_raw = n, n_raw the new couple's normal with sigma = 1."""
    return 1.0 if n[0] * n_raw[0] + n[1] * n_raw[1] + n[2] * n_raw[2] >= 0.0 else -1.0
