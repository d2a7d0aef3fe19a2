"""Every documented bad input raises InputError naming the field (one test per case)."""
import pytest

from drake_dock.docking.apds import ApdsGeometry
from drake_dock.errors import InputError
from drake_dock.scenario import load_scenario


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
    e = _fails(f"simulation: {{integration_scheme: {value}}}", "simulation.integration_scheme")
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
