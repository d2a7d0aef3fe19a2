"""The seeded geometric sweep behind `drake_dock.docking.geometry.pairs.side_edge_pairs`: which
guide sides reach which edges (guide sides, tip arcs) of the other APDS's petals over random
relative poses.

A pose is the matched facing turned by a relative roll, tilted through the chaser's ring centre
and offset sideways, with the ring faces a distance d apart (`Approach`'s convention). A
candidate pair is *reached* at a pose when its closest couple (the compiled seek of Sect. 5.1)
is interior to both curves and closer than ``near``: the two edges are about to cross there, so
the generic C-C couple has an isolated contact to follow."""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from drake_dock.core.patches import posed
from drake_dock.core.seeking import seek_couple
from drake_dock.docking.geometry.apds import apds_patches
from drake_dock.docking.geometry.pairs import (R_MATCHED, PairSpec, side_edge_pairs,
                                               tip_tip_pairs)
from drake_dock.docking.geometry.rotations import rot_vec, rot_z
from drake_dock.docking.scenario.dimensions import ApdsGeometry


@dataclasses.dataclass(frozen=True)
class ReachBox:
    """The sampled ranges: roll (deg, uniform), tilt and lateral offset (uniform by area within
    the radii, deg and m), ring-face distance d (m, uniform)."""

    roll_deg: float = 60.0
    tilt_deg: float = 10.0
    offset: float = 0.15
    d: tuple = (-0.2, 0.45)


def side_candidates(g: ApdsGeometry) -> list[PairSpec]:
    """Every guide side against every non-partner guide side (Body 1 the chaser's) and every
    tip arc of the other APDS (Body 1 the side): `pairs.side_edge_pairs` at any reach."""
    return side_edge_pairs(apds_patches(g), R_MATCHED, reach=math.inf)


def tip_candidates(g: ApdsGeometry) -> list[PairSpec]:
    """Every chaser tip arc against every target tip arc (C-C): `pairs.tip_tip_pairs` at any
    reach; the sweep measures which the motion reaches."""
    return tip_tip_pairs(apds_patches(g), R_MATCHED, reach=math.inf)


def random_pose(rng, box: ReachBox):
    """(R, p) of the chaser APDS in the target APDS frame, and the roll (rad)."""
    roll = math.radians(box.roll_deg) * rng.uniform(-1.0, 1.0)
    r, a = math.radians(box.tilt_deg) * math.sqrt(rng.uniform()), rng.uniform(0, 2 * math.pi)
    ro, b = box.offset * math.sqrt(rng.uniform()), rng.uniform(0, 2 * math.pi)
    d = rng.uniform(*box.d)
    R = rot_vec((r * math.cos(a), r * math.sin(a), 0.0)) @ rot_z(-roll) @ R_MATCHED
    return R, np.array([ro * math.cos(b), ro * math.sin(b), d]), roll


def reach_sweep(g: ApdsGeometry, pairs, n: int, *, seed: int = 12, box=ReachBox(),
                near: float = 0.02) -> dict:
    """{pair name: (poses at which it is reached, least interior distance found (m, inf if
    none), (least, greatest) roll in deg where reached)} over n seeded random poses."""
    rng = np.random.default_rng(seed)
    out = {p.name: [0, math.inf, (math.inf, -math.inf)] for p in pairs}
    for _ in range(n):
        R, p, roll = random_pose(rng, box)
        poses = {"chaser_apds": (R, p), "target_apds": (np.eye(3), np.zeros(3))}
        for pr in pairs:
            c = seek_couple(posed(pr.patch1, *poses[pr.body1]),
                            posed(pr.patch2, *poses[pr.body2]))
            if not c.interior:
                continue
            row = out[pr.name]
            row[1] = min(row[1], c.distance)
            if c.distance < near:
                row[0] += 1
                lo, hi = row[2]
                row[2] = (min(lo, math.degrees(roll)), max(hi, math.degrees(roll)))
    return {k: tuple(v) for k, v in out.items()}
