"""Shared fixtures. Imports are inside the fixtures so that tests/core collects without Drake."""
import pytest


@pytest.fixture(scope="session")
def paper_scenario():
    from drake_dock.docking.scenario import load_scenario
    return load_scenario()


@pytest.fixture(scope="session")
def geom():
    from drake_dock.docking.apds import ApdsGeometry
    return ApdsGeometry().validate()
