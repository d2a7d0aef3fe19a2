"""Every documented bad input raises InputError naming the field (one test per case)."""
import math

import pytest

from drake_dock.docking.scenario.dimensions import ApdsGeometry
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.errors import InputError


def _fails(data, field):
    with pytest.raises(InputError) as e:
        load_scenario(data=data)
    assert e.value.field == field
    assert field in str(e.value)
    return e.value


def test_petal_reaching_the_axis():   # H cot(alpha1) >= R
    e = _fails("geometry: {H: 0.6}", "geometry.H")
    assert "0.6" in e.allowed


def test_petal_sides_crossing():      # the two sides of a petal meet below zeta = H
    _fails("geometry: {H: 0.3}", "geometry.H")


def test_ring_radius_not_below_outer_radius():
    _fails("geometry: {Rs: 0.6}", "geometry.Rs")


@pytest.mark.parametrize("angle", [0.0, 90.0, -10.0, 120.0])
def test_angles_outside_open_interval(angle):
    _fails(f"geometry: {{alpha1_deg: {angle}}}", "geometry.alpha1_deg")
    _fails(f"geometry: {{alpha2_deg: {angle}}}", "geometry.alpha2_deg")


def test_non_finite_geometry():
    with pytest.raises(InputError) as e:
        ApdsGeometry(R=float("inf")).validate()
    assert e.value.field == "geometry.R"


def test_nan_value():
    _fails("contact: {mu: .nan}", "contact.mu")


def test_unknown_key():
    e = _fails("bodies: {chaser: {mas: 3.0}}", "bodies.chaser.mas")
    assert "mass" in str(e)


@pytest.mark.parametrize("mass", [0.0, -5.0])
def test_non_positive_mass(mass):
    _fails(f"bodies: {{target: {{mass: {mass}}}}}", "bodies.target.mass")


def test_inertia_not_positive_definite():
    _fails("bodies: {chaser: {inertia: [1.0, -2.0, 1.0]}}", "bodies.chaser.inertia[1]")


def test_inertia_not_physical():
    _fails("bodies: {chaser: {inertia: [1.0, 1.0, 3.0]}}", "bodies.chaser.inertia")


def test_negative_stiffness():
    _fails("stewart: {force_stiffness: [1.0, -1.0, 1.0]}", "stewart.force_stiffness[1]")


def test_negative_damping():
    _fails("stewart: {torque_damping: [1.0, 1.0, -0.5]}", "stewart.torque_damping[2]")


def test_wrong_type():
    _fails("initial: {chaser_speed: fast}", "initial.chaser_speed")


@pytest.mark.parametrize("value, allowed", [("euler", "one of bogacki_shampine3"),
                                            ("3", "a string")])
def test_unknown_integration_scheme(value, allowed):
    e = _fails(f"simulator_config: {{integration_scheme: {value}}}",
               "simulator_config.integration_scheme")
    assert e.allowed.startswith(allowed)


def test_initial_interpenetration():
    _fails("initial: {approach_travel: -0.02}", "initial.approach_travel")


def test_unreadable_file(tmp_path):
    with pytest.raises(InputError) as e:
        load_scenario(tmp_path / "missing.yaml")
    assert e.value.field == "scenario file"


def test_paper_example_loads_tables():
    s = load_scenario()
    assert (s.bodies.chaser.mass, s.bodies.target.mass, s.bodies.target_apds.mass) == \
        (7600.0, 1000.0, 150.0)
    assert s.stewart.force_stiffness == [938.0, 71400.0, 947.0]


def test_contact_static_friction_defaults_to_sliding_friction():
    """contact.mu_s may be left out (it is then mu); a non-number is named by its field."""
    s = load_scenario(data="contact: {mu: 0.3}")
    assert s.contact.mu_s is None and s.contact.static_mu == 0.3
    _fails("contact: {mu_s: fast}", "contact.mu_s")
    _fails("contact: {impact_law: elastic}", "contact.impact_law")


def test_contact_pairs_names_the_contact_set(paper_scenario):
    """contact.pairs: ``paper`` (the paper's 12 pairs, which the paper's example states) or
    ``complete`` (134 pairs, the default); anything else is named by its field."""
    from drake_dock.docking.geometry.scene import DockingScene
    assert paper_scenario.contact.pairs == "paper"
    assert len(DockingScene.of(paper_scenario).pairs) == 12
    s = load_scenario(data="contact: {pairs: complete}")
    assert len(DockingScene.of(s).pairs) == 134
    assert load_scenario(data="contact: {mu: 0.1}").contact.pairs == "complete"
    _fails("contact: {pairs: all}", "contact.pairs")
    _fails("contact: {pairs: 12}", "contact.pairs")


# Physical consistency -----------------------------------------------------------------------
# case: (scenario, the field named, what else the message names)
PHYSICAL = {
    "static friction below sliding": ("contact: {mu: 0.3, mu_s: 0.1}", "contact.mu_s",
                                      "contact.mu = 0.3"),
    "no closing speed": ("initial: {chaser_speed: 0.0}", "initial.chaser_speed", "> 0 m/s"),
    "chaser moving away": ("initial: {chaser_speed: -1.0}", "initial.chaser_speed", "> 0 m/s"),
    "chaser APDS at its mass centre": ("chaser_apds_offset: [0.0, 0.0, 0.0]",
                                       "chaser_apds_offset[2]", "chaser body"),
    "chaser APDS behind its mass centre": ("chaser_apds_offset: [0.5, 0.0, -1.0]",
                                           "chaser_apds_offset[2]", "chaser body"),
    "target APDS behind the target": ("stewart: {p_TA: [0.0, 0.0, -5.03]}", "stewart.p_TA[2]",
                                      "target body"),
    "more steps than a run can take": ("simulator_config: {max_step_size: 1.0e-12}",
                                       "simulator_config.max_step_size", "simulation.duration"),
    "no error control": ("simulator_config: {use_error_control: false}",
                         "simulator_config.use_error_control", "accuracy"),
    "a run not starting at 0": ("simulator_config: {start_time: 1.0}",
                                "simulator_config.start_time", "t = 0"),
    "no output period": ("simulation: {output_period: 0.0}", "simulation.output_period",
                         "> 0"),
    "more samples than a run can hold": ("simulation: {output_period: 1.0e-12}",
                                         "simulation.output_period", "or null"),
    "no lateral capture tolerance": ("simulation: {capture_lateral: 0.0}",
                                     "simulation.capture_lateral", "or null"),
    "a lateral capture tolerance beyond the ring": ("simulation: {capture_lateral: 0.7}",
                                                    "simulation.capture_lateral", "R = 0.6 m"),
    "a tilt capture tolerance of a right angle": ("simulation: {capture_tilt_deg: 90.0}",
                                                  "simulation.capture_tilt_deg", "< 90 deg"),
    "a negative tilt capture tolerance": ("simulation: {capture_tilt_deg: -0.5}",
                                          "simulation.capture_tilt_deg", "0 < tolerance"),
    "a run paced to stand still": ("simulator_config: {target_realtime_rate: 1.0e-300}",
                                   "simulator_config.target_realtime_rate", "as fast as"),
}


@pytest.mark.parametrize("case", sorted(PHYSICAL))
def test_physically_inconsistent(case):
    data, field, named = PHYSICAL[case]
    assert named in str(_fails(data, field))


def test_target_apds_near_its_mass_centre_builds():
    """p_TA z in (0, 1] m is valid (the target's display hull used to refuse it)."""
    from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
    build_docking_diagram(DiagramSpec.of(load_scenario(data="stewart: {p_TA: [0.0, 0.0, 0.5]}")))


def test_binary_file(tmp_path):
    f = tmp_path / "scenario.yaml"
    f.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe")
    with pytest.raises(InputError) as e:
        load_scenario(f)
    assert e.value.field == "scenario file" and "UTF-8" in str(e.value)


@pytest.mark.parametrize("beyond", [0.0, 0.1])
def test_capture_distance_at_or_beyond_the_start(beyond):
    """The initial ring distance is the first-contact distance plus the approach travel; a
    capture distance at or beyond it is refused when the chaser is placed, before simulating,
    naming both fields."""
    from drake_dock.docking.geometry.scene import DockingScene
    from drake_dock.docking.placement.place import PlacementCache, place
    from drake_dock.docking.placement.search import Approach
    from drake_dock.docking.placement.search import first_contact
    s = load_scenario()
    d_c = first_contact(PlacementCache(DockingScene.of(s)),
                        Approach(math.radians(s.initial.target_yaw_deg))).lam
    s.simulation.capture_distance = d_c + s.initial.approach_travel + beyond
    with pytest.raises(InputError) as e:
        place(s)
    assert e.value.field == "simulation.capture_distance"
    assert "initial.approach_travel" in str(e.value)
    s.simulation.capture_distance = 0.99 * (d_c + s.initial.approach_travel)
    assert place(s).d0 == d_c + s.initial.approach_travel


def test_a_scenario_pickles_and_compares_with_its_simulator_config(paper_scenario):
    """Dask sends scenarios to its workers by pickle; Drake's SimulatorConfig does not pickle
    on its own and has no ==, so the scenario handles both, field by field."""
    import copy
    import pickle
    back = pickle.loads(pickle.dumps(paper_scenario))
    assert back == paper_scenario and back is not paper_scenario
    other = copy.deepcopy(paper_scenario)
    other.simulator_config.accuracy *= 2
    assert other != paper_scenario and pickle.loads(pickle.dumps(other)) == other
