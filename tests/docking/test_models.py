"""Every scenario file in models/ (the campaign plan idss_envelope.yaml aside) loads, validates
and places its first contact: a named pair of its contact set closes on its approach, and the
initial ring distance is that contact's plus the stated approach travel."""
from pathlib import Path

import pytest

from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario

MODELS = sorted(p for p in (Path(__file__).resolve().parents[2] / "models").glob("*.yaml")
                if not p.name.startswith("idss_envelope"))


def test_the_models_are_the_documented_ones():
    assert {p.stem for p in MODELS} >= {"paper_example", "paper_table1_literal",
                                        "idss_box_corner", "idss_lateral", "idss_tilted"}


@pytest.mark.parametrize("path", MODELS, ids=lambda p: p.stem)
def test_each_model_places_its_first_contact(path):
    s = load_scenario(path)
    state = place(s)
    names = {p.name for p in DockingScene.of(s).pairs}
    assert state.closing_pairs and set(state.closing_pairs) <= names
    assert state.d0 == pytest.approx(state.d_contact + s.initial.approach_travel, abs=1e-12)
