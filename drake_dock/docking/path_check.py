"""The straight approach's path before its first contact, checked by the independent
interpenetration check (`drake_dock.docking.penetration`): a feature that crosses the other
APDS before any pair of the set closes is a contact the set does not model, reported before
any simulation (docs/model.md, "Initial conditions")."""
from __future__ import annotations

import dataclasses
import functools

import numpy as np

from drake_dock.docking.apds import ApdsGeometry
from drake_dock.docking.penetration import deepest_penetration
from drake_dock.errors import NumericalError

# Deeper than this, a feature crossing the other APDS on the approach is a contact (m).
FREE_APPROACH_TOL = 1e-4
# How far past a first contact with no isolated couple the path is checked (m of travel).
LINE_PROBE = 1e-2


class NoPairCloses(NumericalError):
    """No pair of the contact set closes on the approach down to a ring-face distance of -H."""


class MissedContact(NumericalError):
    """A feature crosses the other APDS on the approach before the set's first contact."""


def _crossing(g: ApdsGeometry, approach, lam0: float, lam1: float):
    """The deepest crossing (`deepest_penetration`) on the straight path from lam0 to lam1."""
    (R0, p0), (R1, p1) = approach.pose(lam0), approach.pose(lam1)
    eye, zero = np.eye(3), np.zeros(3)
    return deepest_penetration(g, np.array([0.0, 1.0]), np.array([[eye, R0], [eye, R1]]),
                               np.array([[zero, p0], [zero, p1]]), ("target", "chaser"),
                               graze=FREE_APPROACH_TOL, sparse=True)


def check_free_approach(g: ApdsGeometry, approach, which: str, lam0: float):
    """Where no pair of the set closes, the chaser may still meet the target's APDS with a
    feature the set does not model: the check follows the straight approach from the search's
    start ``lam0`` down to the ring-face plane, and a crossing deeper than `FREE_APPROACH_TOL`
    is a `NoPairCloses` naming it. A clear approach (a roll of 0: the petals pass between each
    other) goes on to the faces. A crossing within the tolerance of a petal's edge grazes it:
    in the paper's geometry (Rs = R - H cot(alpha1)) a ring's inside circle passes exactly
    through the petal tips of a coaxial approach."""
    found = _crossing(g, approach, lam0, 0.0)
    if found.depth > FREE_APPROACH_TOL:
        height = approach.height(lam0) * (1.0 - found.time)
        raise NoPairCloses(
            f"no pair of contact.pairs: {which} closes on the approach {approach}, but there "
            f"the {found.feature} passes through the {found.solid} (by {found.depth * 1e3:.3g}"
            f" mm at the ring-face distance {height:.4g} m): a contact the set does not model")


def check_path_to_contact(g: ApdsGeometry, approach, lam0: float, lam_c: float, *,
                          line: bool = False):
    """The complete set's first contact at ``lam_c`` verified: the straight approach from
    ``lam0`` down to it crosses nothing deeper than `FREE_APPROACH_TOL`, else `MissedContact`
    names the feature, the petal and the ring-face distance. With ``line`` (the closing pairs
    have no isolated couple: coaxial arcs of one radius touching along an arc) the path is
    followed `LINE_PROBE` further: a ring's inside circle at the tip arcs of a coaxial
    approach grazes them and the way on is clear; a line contact that no pair can follow
    would let the petals pass through each other (docs/model.md). Tip arcs meeting tip arcs
    coaxially close on the corner-land pairs, which are isolated."""
    end = lam_c - LINE_PROBE if line else lam_c
    found = _checked(dataclasses.astuple(g), approach, lam0, end)
    if found.depth > FREE_APPROACH_TOL:
        height = approach.height(lam0 + found.time * (end - lam0))
        past = line and lam0 + found.time * (end - lam0) < lam_c
        what = ("past its first contact, which has no isolated couple (a line contact of "
                "coaxial arcs)" if past else "before its first contact")
        raise MissedContact(
            f"on the approach {approach} the {found.feature} passes through the "
            f"{found.solid} {what} (contact.pairs: complete, first contact at the ring-face"
            f" distance {approach.height(lam_c):.4g} m; deepest {found.depth * 1e3:.3g} mm, at"
            f" {height:.4g} m): a contact the set does not model")


@functools.lru_cache(maxsize=64)
def _checked(geometry: tuple, approach, lam0: float, lam_c: float):
    return _crossing(ApdsGeometry(*geometry), approach, lam0, lam_c)
