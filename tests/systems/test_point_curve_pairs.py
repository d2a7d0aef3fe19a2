"""The point-curve pairs (kind "PC") in the contact system: the side witness and the re-seek
of a couple on the curve's convex side (docs/model.md, "The petal corner")."""
import math

import numpy as np

from drake_dock.core.couple import evaluate_couple
from drake_dock.core.patches import Circle, Point

R_C = 0.4


def test_side_witness_is_armed_and_reseeks():
    """The contact system arms the side witness of a point-curve pair that is not far, and
    seeks its couple again once the point has reached the curve's convex side
    (`transitions._reseek`), the value `point_curve_side` in closed form changing sign."""
    from drake_dock.core.hybrid import Mode
    from drake_dock.systems.contact_types import ContactPair, PairState
    from drake_dock.systems.transitions import _reseek
    from drake_dock.systems.witnesses import armed
    states = [PairState(Mode.TRACKED), PairState(Mode.FAR), PairState(Mode.SLIDING)]
    got = armed(states, (), {0, 1, 2})
    assert (0, "side") in got and (2, "side") in got and (1, "side") not in got
    assert all(kind != "side" for _, kind in armed(states))
    ring, X = Circle(R_C), (np.eye(3), np.zeros(3))
    pair = ContactPair("pc", "PC", None, Point((0.0, 0.0, 0.0)), None, ring)
    for rho, due in ((R_C - 0.01, False), (R_C + 0.01, True)):
        point = Point((rho * math.cos(0.3), rho * math.sin(0.3), 0.02))
        ev = evaluate_couple("PC", point, X, (np.zeros(3),) * 2, ring, X, (np.zeros(3),) * 2,
                             [0.3], 1.0)
        assert _reseek(pair, ev, np.array([np.inf]), X[0], 1e-6) == due
