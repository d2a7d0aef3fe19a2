"""The first-contact search (`first_contact`) against a full scan: every pair's signed gap
(`signed_gaps`) at every point of the travel grid, the pairs' sides continued from point to
point, and brentq on the first step where a finite gap turns <= 0. The search seeks a pair only
in the steps its covers can touch; the travel, the closing pairs and the typed error are the
scan's, bit for bit."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from drake_dock.docking.apds import ApdsGeometry
from drake_dock.docking.scene import (Approach, apds_pairs, first_contact, first_contact_seeks,
                                      signed_gaps, travel_grid)
from drake_dock.errors import NumericalError


def full_scan(g, approach, xtol=1e-13, which="paper"):
    """(lam, names, seeks) of the scan of every pair at every grid point."""
    pairs = apds_pairs(g, which)
    grid = travel_grid(g, approach)
    gaps, refs = signed_gaps(pairs, approach, grid[0], [None] * len(pairs))
    seeks = len(pairs)
    for d, d_lo in zip(grid[:-1], grid[1:]):
        gaps_lo, refs_lo = signed_gaps(pairs, approach, d_lo, refs)
        seeks += len(pairs)
        closing = np.flatnonzero((gaps_lo <= 0) & np.isfinite(gaps))
        if closing.size:
            roots = {}
            for j in closing:
                roots[pairs[j].name] = brentq(
                    lambda x, j=j: signed_gaps([pairs[j]], approach, x, [refs[j]])[0][0],
                    d_lo, d, xtol=xtol, rtol=1e-15)
            d_c = max(roots.values())
            return d_c, sorted(n for n, r in roots.items() if r >= d_c - 1e-9), seeks
        gaps, refs = gaps_lo, refs_lo
    raise NumericalError(f"no pair closes on the approach {approach}")


APPROACHES = {
    "paper": Approach(math.radians(5.0)),
    "tilted, off axis": Approach(math.radians(-3.0), (0.05, -0.02), (0.07, -0.04),
                                 (0.3, 0.2, -0.932737905308882)),
    "ring first": Approach(math.radians(2.0), (-0.06, 0.03), (-0.08, 0.05), (0.0, 0.0, -1.0)),
    "no contact": Approach(0.0, (0.0, 0.0), (0.8, 0.8), (0.0, 0.0, -1.0)),
}


@pytest.mark.parametrize("name", APPROACHES)
def test_search_equals_the_full_scan(name):
    g = ApdsGeometry()
    approach = APPROACHES[name]
    try:
        expected = full_scan(g, approach)
    except NumericalError:
        with pytest.raises(NumericalError, match="no pair closes"):
            first_contact(g, approach)
        return
    lam, names = first_contact(g, approach)
    assert (lam, names) == expected[:2]
    assert first_contact_seeks(g, approach) < expected[2]


def _random_approach(rng):
    """A straight approach inside the IDSS box's misalignments, weighted to its edges: roll and
    tilt within 4 deg, aim within 0.1 m, lateral rate up to 0.4 of the closing rate."""
    edge = lambda lim, n: lim * np.sign(rng.uniform(-1, 1, n)) * rng.uniform(0.5, 1.0, n) ** 0.5
    v = np.array([*edge(0.4, 2), -1.0])
    return Approach(float(edge(math.radians(4.0), 1)[0]),
                    tuple(edge(math.radians(4.0), 2).tolist()), tuple(edge(0.1, 2).tolist()),
                    tuple((v / np.linalg.norm(v)).tolist()))


@pytest.mark.parametrize("which, seed", [("paper", s) for s in range(6)]
                         + [("complete", s) for s in range(6, 9)])
def test_search_equals_the_full_scan_on_random_approaches(which, seed):
    """Seeded random approaches: the search (covers, pairs built once per geometry, the compiled
    seek) closes the full scan's pairs at its travel, bit for bit, in fewer seeks."""
    g = ApdsGeometry()
    approach = _random_approach(np.random.default_rng(seed))
    try:
        expected = full_scan(g, approach, which=which)
    except NumericalError:
        with pytest.raises(NumericalError, match="no pair closes"):
            first_contact(g, approach, which=which)
        return
    assert first_contact(g, approach, which=which) == expected[:2]
    assert first_contact_seeks(g, approach, which=which) < expected[2]
