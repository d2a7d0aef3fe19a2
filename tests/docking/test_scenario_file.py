"""A scenario file's defaults and the full scenario a run uses: docs/scenario.md's table lists
every field with its default (against the dataclasses), its partial example loads to the
defaults with those fields changed, and the printed scenario (`--print-scenario`, summary.json's
`scenario`) reads back to the same scenario for every shipped model."""
import json
import re
from pathlib import Path

import pytest
import yaml

from drake_dock.cli import main
from drake_dock.docking.scenario.loading import load_scenario, scenario_dict, scenario_yaml
from drake_dock.docking.scenario.models_dir import MODELS_DIR
from drake_dock.docking.scenario.schema import Scenario, ThrustParams

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenario.md"


def _flat(node, prefix=""):
    for key, value in node.items():
        if isinstance(value, dict):
            yield from _flat(value, f"{prefix}{key}.")
        else:
            yield f"{prefix}{key}", value


def _table():
    rows = re.findall(r"^\| `([a-z_A-Z0-9.]+)` \| ([^|]*) \|", DOC.read_text(), re.M)
    return {field: yaml.safe_load(default.strip()) for field, default in rows}


def test_the_table_lists_every_field_with_its_default():
    table = _table()
    defaults = dict(_flat(scenario_dict(Scenario())))
    assert sorted(table) == sorted(defaults)
    for field, value in defaults.items():
        assert table[field] == value, field


def test_the_partial_example_is_the_defaults_with_its_fields():
    text = re.search(r"```yaml\n(.*?)```", DOC.read_text(), re.S).group(1)
    s = load_scenario(data=text)
    expected = Scenario()
    expected.initial.lateral_offset = [0.05, 0.0]
    expected.initial.chaser_speed = 0.1
    assert s == expected and s.contact.pairs == "complete"


@pytest.mark.parametrize("model", sorted(p.name for p in MODELS_DIR.glob("*.yaml")
                                         if not p.name.startswith("idss_envelope")))
def test_the_printed_scenario_reads_back_the_same(model, capsys):
    """`drake-dock run MODEL --print-scenario` prints every field (nothing left to a default)
    and nothing else; read back, it is the same scenario."""
    assert main(["run", str(MODELS_DIR / model), "--print-scenario"]) == 0
    printed = capsys.readouterr().out
    scenario = load_scenario(MODELS_DIR / model)
    assert printed == scenario_yaml(scenario)
    assert load_scenario(data=printed) == scenario
    every = scenario_dict(Scenario())
    if scenario.thrust is not None:             # an optional section, every field when given
        every["thrust"] = scenario_dict(ThrustParams())
    assert dict(_flat(yaml.safe_load(printed))).keys() == dict(_flat(every)).keys()


def test_print_scenario_applies_duration_and_a_null_tolerance(tmp_path, capsys):
    f = tmp_path / "s.yaml"
    f.write_text("simulation: {capture_lateral: null}\n")
    assert main(["run", str(f), "--print-scenario", "--duration", "2.5"]) == 0
    printed = yaml.safe_load(capsys.readouterr().out)
    assert printed["simulation"]["duration"] == 2.5
    assert printed["simulation"]["capture_lateral"] is None
    assert json.loads(json.dumps(printed)) == printed
