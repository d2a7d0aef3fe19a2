"""The straight approach's path before its first contact, checked by the independent
interpenetration check (`drake_dock.docking.checks.penetration`): a feature that crosses the other
APDS before any pair of the set closes is a contact the set does not model, reported before
any simulation (docs/model.md, "Initial conditions")."""
from __future__ import annotations

import numpy as np

from drake_dock.docking.checks.penetration import deepest_penetration
from drake_dock.docking.placement.search import FirstContact
from drake_dock.errors import NumericalError

# Deeper than this, a feature crossing the other APDS on the approach is a contact (m).
FREE_APPROACH_TOL = 1e-4
# How far past a first contact with no isolated couple the path is checked (m of travel).
LINE_PROBE = 1e-2


class NoPairCloses(NumericalError):
    """No pair of the contact set closes on the approach down to a ring-face distance of -H."""


class MissedContact(NumericalError):
    """A feature crosses the other APDS on the approach before the set's first contact."""


def check_path(cache, approach, found: FirstContact, *, line: bool = False):
    """The straight path of ``approach`` from the search's start (``found.start``) down to its
    first contact ``found`` (a search's on the scene of ``cache``, a `PlacementCache`, where the
    crossing found is remembered), checked by the independent interpenetration check: a
    feature crossing the other APDS deeper than `FREE_APPROACH_TOL` is a contact the set does
    not model.

    - Where no pair of the set closes, the chaser may still meet the target's APDS with such a
      feature: the path is followed down to the ring-face plane, and a crossing is a
      `NoPairCloses` naming it. A clear approach (a roll of 0: the petals pass between each
      other) goes on to the faces. A crossing within the tolerance of a petal's edge grazes it:
      in the paper's geometry (Rs = R - H cot(alpha1)) a ring's inside circle passes exactly
      through the petal tips of a coaxial approach.
    - The complete set's first contact is verified: a crossing on the way is a `MissedContact`
      naming the feature, the petal and the ring-face distance. With ``line`` (the closing
      pairs have no isolated couple, `search.point_contact`: coaxial arcs of one radius
      touching along an arc) the path is followed `LINE_PROBE` further: a ring's inside circle
      at the tip arcs of a coaxial approach grazes them and the way on is clear; a line
      contact that no pair can follow would let the petals pass through each other
      (docs/model.md). Tip arcs meeting tip arcs coaxially close on the corner-land pairs,
      which are isolated. The paper's set is not checked past its pairs."""
    if found.closing and cache.scene.pair_set != "complete":
        return
    lam0, lam_c = found.start, found.travel()
    end = lam_c - LINE_PROBE if line else lam_c
    key = (approach, lam0, end)
    crossing = cache.paths.get(key)
    if crossing is None:
        crossing = cache.paths[key] = _crossing(cache.scene.geometry, approach, lam0, end)
    if crossing.depth <= FREE_APPROACH_TOL:
        return
    at = lam0 + crossing.time * (end - lam0)
    if not found.closing:
        raise NoPairCloses(
            f"no pair of contact.pairs: {cache.scene.pair_set} closes on the approach "
            f"{approach}, but there the {crossing.feature} passes through the {crossing.solid} "
            f"(by {crossing.depth * 1e3:.3g} mm at the ring-face distance "
            f"{approach.height(at):.4g} m): a contact the set does not model")
    what = ("past its first contact, which has no isolated couple (a line contact of coaxial "
            "arcs)" if line and at < lam_c else "before its first contact")
    raise MissedContact(
        f"on the approach {approach} the {crossing.feature} passes through the "
        f"{crossing.solid} {what} (contact.pairs: complete, first contact at the ring-face"
        f" distance {approach.height(lam_c):.4g} m; deepest {crossing.depth * 1e3:.3g} mm, at"
        f" {approach.height(at):.4g} m): a contact the set does not model")


def _crossing(g, approach, lam0: float, lam1: float):
    """The deepest crossing (`deepest_penetration`) on the straight path from lam0 to lam1."""
    (R0, p0), (R1, p1) = approach.pose(lam0), approach.pose(lam1)
    eye, zero = np.eye(3), np.zeros(3)
    return deepest_penetration(g, np.array([0.0, 1.0]), np.array([[eye, R0], [eye, R1]]),
                               np.array([[zero, p0], [zero, p1]]), ("target", "chaser"),
                               graze=FREE_APPROACH_TOL, sparse=True)
