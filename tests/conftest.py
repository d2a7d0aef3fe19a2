import pytest

from drake_dock.docking.apds import ApdsGeometry
from drake_dock.scenario import load_scenario


@pytest.fixture(scope="session")
def paper_scenario():
    return load_scenario()


@pytest.fixture(scope="session")
def geom():
    return ApdsGeometry().validate()
