"""Initial contact conditions off the axis: the scenario's misalignment fields, validated, and
the placement of the chaser along its straight relative motion."""
import math

import numpy as np
import pytest
import yaml

from drake_dock.docking.geometry.pairs import CHASER_APDS, TARGET_APDS
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.placement.place import contact_approach, place
from drake_dock.docking.placement.search import pair_couples
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.errors import InputError

OFF_AXIS = dict(lateral_offset=[0.02, -0.01], tilt_deg=[1.0, 0.5], lateral_velocity=[0.01, 0.0],
                angular_velocity_deg_s=[0.1, -0.2, 0.3], chaser_speed=0.1)


def scenario_with(**initial):
    data = yaml.safe_load(PAPER_EXAMPLE.read_text())
    data["initial"].update(initial)
    return load_scenario(data=yaml.safe_dump(data))


@pytest.mark.parametrize("field, value", [
    ("lateral_offset", [0.7, 0.0]), ("lateral_offset", [0.1]), ("tilt_deg", [30.0, 1.0]),
    ("lateral_velocity", [float("nan"), 0.0]), ("angular_velocity_deg_s", [0.0, 100.0, 0.0])])
def test_bad_misalignment_names_the_field(field, value):
    with pytest.raises(InputError, match=f"initial.{field}"):
        scenario_with(**{field: value})


def test_off_axis_placement():
    """At t = 0 the chaser ring centre moves at (lateral_velocity, -chaser_speed) in the target
    APDS frame; going approach_travel along that motion brings the first couple to zero
    distance, with the ring centre at lateral_offset and the chaser tilted by tilt_deg."""
    sc = scenario_with(**OFF_AXIS)
    ic = sc.initial
    st = place(sc)
    R_WA, p_WA = st.X_WB["target_apds"]
    R_WC, p_WC = st.X_WB["chaser"]
    w_WC, v_WC = st.V_WB["chaser"]
    p_WCA = p_WC + R_WC @ np.array(sc.chaser_apds_offset)     # the chaser's ring centre
    v_ring = R_WA.T @ (v_WC + np.cross(w_WC, p_WCA - p_WC))
    np.testing.assert_allclose(v_ring, [*ic.lateral_velocity, -ic.chaser_speed], atol=1e-15)
    np.testing.assert_allclose(R_WA.T @ w_WC, np.radians(ic.angular_velocity_deg_s), atol=1e-15)
    # The pose after approach_travel along the motion (translation only).
    p_A = R_WA.T @ (p_WCA - p_WA)
    p_contact = p_A + ic.approach_travel * v_ring / np.linalg.norm(v_ring)
    np.testing.assert_allclose(p_contact[:2], ic.lateral_offset, atol=1e-9)
    R_AC = R_WA.T @ R_WC
    tilt = math.degrees(math.acos(np.clip(-R_AC[2, 2], -1, 1)))
    assert tilt == pytest.approx(math.hypot(*ic.tilt_deg), abs=1e-9)
    pairs = DockingScene(sc.geometry, "paper").pairs
    at = {TARGET_APDS: (np.eye(3), np.zeros(3))}
    start = pair_couples(pairs, {**at, CHASER_APDS: (R_AC, p_A)})
    contact = pair_couples(pairs, {**at, CHASER_APDS: (R_AC, p_contact)})
    names = [p.name for p in pairs]
    assert min(c.distance for c in start if c.interior) > 1e-4
    for name in st.closing_pairs:
        assert contact[names.index(name)].distance < 1e-8


def test_zero_misalignment_is_the_coaxial_search():
    sc = load_scenario(PAPER_EXAMPLE)
    approach, lam_c, closing = contact_approach(sc)
    assert approach.pose(lam_c)[1].tolist() == [0.0, 0.0, lam_c]
    assert closing == place(sc).closing_pairs
