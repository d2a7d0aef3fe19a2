"""Shared fixtures. Imports are inside the fixtures so that tests/core collects without Drake."""
import pytest


@pytest.fixture(scope="session")
def paper_scenario():
    from drake_dock.docking.scenario.loading import load_scenario
    return load_scenario()


@pytest.fixture(scope="session")
def geom():
    from drake_dock.docking.scenario.dimensions import ApdsGeometry
    return ApdsGeometry().validate()


BOX_CORNER_SECONDS = 1.5     # of models/idss_box_corner.yaml: impacts and sliding on 4 couples


@pytest.fixture(scope="session")
def box_corner(tmp_path_factory):
    """The off-axis corner of the IDSS box (`models/idss_box_corner.yaml`), its first
    BOX_CORNER_SECONDS run once for the session with `drake_dock.run.run`: (the full namespace,
    the output directory)."""
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.docking.scenario.models_dir import MODELS_DIR
    from drake_dock.run import run
    scenario = load_scenario(MODELS_DIR / "idss_box_corner.yaml")
    scenario.simulation.duration = BOX_CORNER_SECONDS
    out = tmp_path_factory.mktemp("box_corner") / "idss_box_corner"
    return run(scenario, out, full=True, name="idss_box_corner"), out
