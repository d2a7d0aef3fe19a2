"""The docking scene's initial configuration (Sect. 8.2): the chaser placed on its straight
approach at the scenario's travel before the first contact (`place`; the search:
`drake_dock.docking.placement.search`), with the consistent aim for a lateral velocity
(`drake_dock.docking.placement.aim`), and its path checked
(`drake_dock.docking.placement.path_check`). What a caller keeps between placements of one
scene is its `PlacementCache`: a placement's searches are pure functions of the scene and their
arguments, so a result found once serves every later ask."""
from __future__ import annotations

import math

import numpy as np

from drake_dock.docking.geometry.rotations import rot_z
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.initial_state import InitialState
from drake_dock.docking.placement.aim import aim_height
from drake_dock.docking.placement.path_check import NoPairCloses, check_path
from drake_dock.docking.placement.search import Approach
from drake_dock.docking.placement.search import first_contact, point_contact
from drake_dock.errors import InputError, numerical_failure


class PlacementCache:
    """The searches (`drake_dock.docking.placement.search.first_contact`) and path checks
    (`drake_dock.docking.placement.path_check.check_path`) done on ``scene`` (a
    `DockingScene`), by their arguments. The caller owns it: `place` makes one for a single
    placement where none is given; one kept across placements of a scene serves them all
    (the scene's patches keep their covers and coarse grids too)."""

    def __init__(self, scene):
        self.scene = scene
        self.searches = {}
        self.paths = {}


def place(scenario, cache: PlacementCache | None = None) -> InitialState:
    """Sect. 8.2 (docs/model.md): the target at the origin turned by yaw about its docking axis,
    its APDS at the Stewart element's equilibrium, the chaser on its straight approach
    (`contact_approach`) at ring-face distance d_contact + approach_travel, moving at
    chaser_speed towards the target; all else at rest. ``cache``: the caller's
    `PlacementCache` of the scenario's scene (one for this placement where None). Raises
    `InputError` for a capture distance not below that initial ring distance or a cache of
    another scene, the placement's typed errors (`NoPairCloses`, `MissedContact`,
    `SeekingError`), and any other failure as a `NumericalError`."""
    cache = cache or PlacementCache(DockingScene.of(scenario))
    if (cache.scene.geometry, cache.scene.pair_set) != (scenario.geometry,
                                                        scenario.contact.pairs):
        raise InputError("cache", cache.scene.pair_set, "a PlacementCache of the scenario's "
                         "scene (its geometry and contact.pairs)", "another scene's")
    with numerical_failure("the initial placement", lambda: (0.0, ())):
        return _placed(scenario, cache)


def _placed(scenario, cache) -> InitialState:
    ic = scenario.initial
    if ic.approach_travel < 0:
        raise InputError("initial.approach_travel", ic.approach_travel,
                         ">= 0 m (a negative travel means initial interpenetration)")
    approach, d_c, closing = contact_approach(scenario, cache)
    d0 = d_c + ic.approach_travel
    cap = scenario.simulation.capture_distance
    if not cap < d0:
        raise InputError("simulation.capture_distance", cap,
                         f"< the initial ring distance {d0:.6g} m (first contact at {d_c:.6g} m "
                         f"+ initial.approach_travel {ic.approach_travel:g} m)",
                         "capture would hold from t = 0 and never be detected: the rings would "
                         "pass through each other")
    yaw = math.radians(ic.target_yaw_deg)
    R_WT, p_WT = rot_z(yaw), np.zeros(3)
    p_TA = np.asarray(scenario.stewart.p_TA, dtype=float)
    R_WA, p_WA = R_WT, p_WT + R_WT @ p_TA
    R_AC, p_AC = approach.pose(d0)
    R_WCA, p_WCA = R_WA @ R_AC, p_WA + R_WA @ p_AC
    # Chaser body: its APDS frame sits at chaser_apds_offset in the body frame, same axes.
    p_C_CA = np.asarray(scenario.chaser_apds_offset, dtype=float)
    R_WC, p_WC = R_WCA, p_WCA - R_WCA @ p_C_CA
    zero = np.zeros(3)
    if ic.lateral_velocity == [0.0, 0.0] and ic.angular_velocity_deg_s == [0.0, 0.0, 0.0]:
        w_WC, v_WC = zero, -ic.chaser_speed * R_WA[:, 2]
    else:
        # The ring centre moves at (lateral_velocity, -chaser_speed); the chaser's mass centre
        # adds w x (p_WC - p_WCA).
        w_WC = R_WA @ np.radians(ic.angular_velocity_deg_s)
        v_ring = R_WA @ np.array([*ic.lateral_velocity, -ic.chaser_speed])
        v_WC = v_ring + np.cross(w_WC, p_WC - p_WCA)
    return InitialState(
        X_WB={"target": (R_WT, p_WT), "target_apds": (R_WA, p_WA), "chaser": (R_WC, p_WC)},
        V_WB={"target": (zero, zero), "target_apds": (zero, zero), "chaser": (w_WC, v_WC)},
        d_contact=d_c, d0=d0, closing_pairs=closing,
        contact_offset=tuple((np.array(approach.aim) - approach.height(d_c) * np.array(
            ic.lateral_velocity) / ic.chaser_speed).tolist()), scene=cache.scene)


def contact_approach(scenario, cache: PlacementCache | None = None):
    """The scenario's straight approach and its first contact: (Approach, lam_c, closing
    pairs of the scene of ``cache``, the scenario's own where None; lam_c = 0 and none where no
    pair closes and the ring faces meet first). The lateral offset is the ring centre's at
    first contact. With a lateral velocity the aim point (where the path meets the target's
    ring-face plane) is aim = offset + s v_lateral / chaser_speed, where s, the ring-face
    distance at contact, solves s = h_c(aim(s)) (`aim_height`). The path to the first contact
    is checked (`check_path`)."""
    ic = scenario.initial
    cache = cache or PlacementCache(DockingScene.of(scenario))
    g = cache.scene.geometry
    yaw = math.radians(ic.target_yaw_deg)
    tilt = tuple(math.radians(t) for t in ic.tilt_deg)
    v = np.array([*ic.lateral_velocity, -ic.chaser_speed])
    direction = tuple((v / np.linalg.norm(v)).tolist()) if v[0] or v[1] else (0.0, 0.0, -1.0)
    offset = np.array(ic.lateral_offset, dtype=float)
    slope = np.array(ic.lateral_velocity) / ic.chaser_speed

    def approach(s):
        return Approach(yaw, tilt, tuple((offset + s * slope).tolist()), direction)

    s = 0.0
    if slope.any():
        s = aim_height(cache, approach, Approach(yaw, tilt, tuple(offset.tolist())),
                       2.0 * g.H + 0.05)
        if s is None:
            raise NoPairCloses(
                f"no straight approach at initial.lateral_velocity {ic.lateral_velocity} m/s "
                f"has its first contact (contact.pairs: {cache.scene.pair_set}) at or before "
                f"initial.lateral_offset {ic.lateral_offset} m")
    a = approach(s)
    found = first_contact(cache, a)
    line = (bool(found.closing) and cache.scene.pair_set == "complete"
            and not point_contact(cache.scene, a, found))
    check_path(cache, a, found, line=line)
    return a, found.travel(), list(found.closing)

