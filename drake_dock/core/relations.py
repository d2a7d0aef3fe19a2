"""The relation of each pair kind (Siconos keeps the nonsmooth law, the relation and the
integrator apart): what its two patches are, which couple kernel evaluates it, and how its
normal's orientation sigma (Definition 2) is taken. Every decision that depends on a pair's
kind reads it here; the compiled kernels dispatch on ``code``.

- "CC": a curve against a curve; "CS": a curve against a surface.
- "PC": a point (a sphere of radius r, a petal corner) against a curve. Its normal is along
  d = p - c(s) (sigma = +1 always), undefined where the point lies on the curve, and on the
  curve's convex side the couple is not isolated (sought again).
- "PS": a point (a sphere of radius r) against a surface; its side is its centre's."""
from __future__ import annotations

import dataclasses

from drake_dock.core.kernels import couples as K


@dataclasses.dataclass(frozen=True)
class Relation:
    """A pair kind: ``dims`` the patches' dimensions (0 a point, 1 a curve, 2 a surface),
    ``code`` the couple kernels' code, ``along_d`` whether n is along d = p - c(s) (a point
    against a curve)."""

    kind: str
    dims: tuple
    code: int
    along_d: bool = False

    @property
    def point(self) -> bool:
        """Patch 1 is a point (a sphere of radius r)."""
        return self.dims[0] == 0

    def sigma(self, declared: float | None, gap: float, radius: float = 0.0) -> float:
        """The orientation sigma of n (Definition 2): +1 for a normal along d; else the
        declared one, else the side the patches are on: ``gap`` (taken with sigma = +1), plus
        ``radius`` for a point (a sphere of radius r that overlaps the surface from the +N
        side is on that side)."""
        if self.along_d:
            return 1.0
        if declared is not None:
            return declared
        if self.point:
            gap = gap + radius
        return 1.0 if gap >= 0.0 else -1.0


RELATIONS = {r.kind: r for r in (Relation("CC", (1, 1), K.CC), Relation("CS", (1, 2), K.CS),
                                 Relation("PC", (0, 1), K.PC, along_d=True),
                                 Relation("PS", (0, 2), K.PS))}


def relation(kind: str) -> Relation:
    """The `Relation` of ``kind``; ValueError naming the kinds for another."""
    try:
        return RELATIONS[kind]
    except (KeyError, TypeError):
        raise ValueError(f"pair kind: one of {', '.join(RELATIONS)}, got {kind!r}") from None


def kind_of(dim1: int, dim2: int) -> str:
    """The pair kind of patches of dimensions dim1 and dim2 (`Relation.dims`); ValueError for
    dimensions no relation has."""
    for r in RELATIONS.values():
        if r.dims == (dim1, dim2):
            return r.kind
    raise ValueError(f"pair kind: no relation between patches of dimensions {dim1} and {dim2} "
                     f"(allowed: {', '.join(str(r.dims) for r in RELATIONS.values())})")
