"""The plan: a bad value exits 2 naming the field, before anything runs or is written; the
shipped IDSS plan loads; the samplers' points against closed forms."""
import math

import numpy as np
import pytest

from drake_dock.cli import main

GOOD = """scenario: {scenario}
samples: 4
seed: 1
sampler: sobol
vary:
  initial.lateral_offset: {{uniform: [[-0.1, 0.1], [-0.1, 0.1]]}}
  initial.target_yaw_deg: {{normal: [5.0, 0.5]}}
"""


@pytest.mark.parametrize("change, field", [
    (("sampler: sobol", "sampler: halton"), "sampler"),
    (("samples: 4", "samples: 0"), "samples"),
    (("samples: 4", "samples: 2.5"), "samples"),
    (("seed: 1", "seeds: 1"), "seeds"),
    (("initial.target_yaw_deg", "initial.yaw"), "vary.initial.yaw"),
    (("[[-0.1, 0.1], [-0.1, 0.1]]", "[[-0.1, 0.1]]"), "vary.initial.lateral_offset.uniform"),
    (("[[-0.1, 0.1], [-0.1, 0.1]]", "[[-0.1, 0.1], [-0.7, 0.7]]"), "vary.initial.lateral_offset"),
    (("normal: [5.0, 0.5]", "normal: [5.0, -0.5]"), "vary.initial.target_yaw_deg.normal"),
    (("normal: [5.0, 0.5]", "lognormal: [5.0, 0.5]"), "vary.initial.target_yaw_deg"),
])
def test_a_bad_plan_exits_2_naming_the_field(tmp_path, capsys, change, field):
    from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
    plan = tmp_path / "plan.yaml"
    plan.write_text(GOOD.format(scenario=PAPER_EXAMPLE).replace(*change))
    out = tmp_path / "out"
    assert main(["campaign", str(plan), "--out", str(out)]) == 2
    err = " ".join(capsys.readouterr().err.split())      # the paragraph, unwrapped
    assert "bad input" in err and f"{field} = " in err, err
    assert not out.exists()


def test_the_good_plan_and_the_shipped_idss_plan_load(tmp_path):
    from drake_dock.campaign.plan import load_plan
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.docking.scenario.models_dir import MODELS_DIR, PAPER_EXAMPLE
    plan = tmp_path / "plan.yaml"
    plan.write_text(GOOD.format(scenario=PAPER_EXAMPLE))
    assert [f.path for f in load_plan(plan)[2]] == ["initial.lateral_offset",
                                                    "initial.target_yaw_deg"]
    idss, base, fields = load_plan(MODELS_DIR / "idss_envelope.yaml")
    # The paper example with the plan's `set`: every pair, and post-contact thrust.
    from drake_dock.docking.scenario.schema import ThrustParams
    paper = load_scenario(PAPER_EXAMPLE)
    assert paper.contact.pairs == "paper" and paper.thrust is None
    paper.contact.pairs = "complete"
    paper.thrust = ThrustParams(force=300.0, duration=3.0)
    assert base == paper
    assert sum(f.dims for f in fields) == 11         # the eleven random initial parameters
    funnel, base_f, fields_f = load_plan(MODELS_DIR / "idss_envelope_funnel.yaml")
    assert base_f.geometry == load_scenario(MODELS_DIR / "apds_funnel.yaml").geometry
    assert base_f.thrust == paper.thrust and base_f.contact.pairs == "complete"
    assert [f.path for f in fields_f] == [f.path for f in fields]
    assert (funnel.samples, funnel.seed) == (idss.samples, idss.seed)


@pytest.mark.parametrize("set_, field, named", [
    ("{initial.no_such_field: 1.0}", "set", "no_such_field"),
    ("{simulation.capture_lateral: -1.0}", "set", "simulation.capture_lateral"),
    ("[1, 2]", "set", "dotted path"),
    ("{initial.chaser_speed.x: 1.0}", "set.initial.chaser_speed.x", "scenario field")])
def test_a_bad_set_is_named_before_anything_runs(tmp_path, set_, field, named):
    """A plan's `set` writes values into the base scenario: a path that is not a scenario
    field, or a value the scenario refuses, is an InputError naming `set` and the field."""
    from drake_dock.campaign.plan import load_plan
    from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
    from drake_dock.errors import InputError
    plan = tmp_path / "plan.yaml"
    plan.write_text(GOOD.format(scenario=PAPER_EXAMPLE) + f"set: {set_}\n")
    with pytest.raises(InputError) as e:
        load_plan(plan)
    assert e.value.field == field and named in str(e.value)


def test_set_values_reach_every_sample(tmp_path):
    from drake_dock.campaign.plan import load_plan
    from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
    plan = tmp_path / "plan.yaml"
    plan.write_text(GOOD.format(scenario=PAPER_EXAMPLE)
                    + "set: {contact.mu: 0.05, simulation.capture_tilt_deg: null}\n")
    _, base, _ = load_plan(plan)
    assert base.contact.mu == 0.05 and base.simulation.capture_tilt_deg is None


def test_edges_sampler_follows_the_arcsine_law_and_sobol_points_keep_their_index():
    from drake_dock.campaign.points import unit_points
    u = unit_points("edges", 3, 2, list(range(1024)), 1024)
    # The arcsine law: P(u < a) = (2 / pi) asin(sqrt(a)); Sobol' points match it closely.
    for a in (0.05, 0.1, 0.5):
        expected = 2.0 / math.pi * math.asin(math.sqrt(a))
        assert np.all(np.abs((u < a).mean(axis=0) - expected) < 0.01)
    first = unit_points("sobol", 3, 2, list(range(8)), 8)
    assert np.array_equal(first, unit_points("sobol", 3, 2, list(range(100)), 100)[:8])
    assert np.array_equal(unit_points("uniform", 3, 2, [5], 10),
                          unit_points("uniform", 3, 2, [9, 5], 1000)[1:])


@pytest.mark.parametrize("extra, field", [(["--workers", "0"], "--workers"),
                                          (["--resume"], "--resume")])
def test_bad_options_exit_2_naming_them(tmp_path, capsys, extra, field):
    from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
    plan = tmp_path / "plan.yaml"
    plan.write_text(GOOD.format(scenario=PAPER_EXAMPLE))
    out = tmp_path / "out"
    assert main(["campaign", str(plan), "--out", str(out), *extra]) == 2
    assert f"{field} = " in " ".join(capsys.readouterr().err.split())
    assert not out.exists()


def test_a_plan_varies_the_thrust_of_a_base_without_one(tmp_path):
    """A plan may vary the keys of the optional `thrust` section on a base scenario that has
    none: the section is added with its defaults, then the sampled key is set."""
    from drake_dock.campaign.plan import load_plan, set_field
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
    plan = tmp_path / "plan.yaml"
    plan.write_text(GOOD.format(scenario=PAPER_EXAMPLE)
                    + "  thrust.force: {uniform: [100.0, 400.0]}\n")
    fields = load_plan(plan)[2]
    assert "thrust.force" in [f.path for f in fields]
    s = load_scenario(PAPER_EXAMPLE)
    set_field(s, "thrust.force", 250.0)
    assert s.thrust.force == 250.0 and s.thrust.delay == 0.0 and s.thrust.duration is None


def test_the_diagram_key_holds_what_the_diagram_reads():
    """The campaign's Diagram key, the `DiagramSpec`, changes with every field the docking
    Diagram reads (the capture rule's tolerances and the thrust among them), and not with the
    approach (misalignment, roll) or the run's length (tests/campaign/test_diagram_cache.py
    walks every field)."""
    from drake_dock.campaign.plan import set_field
    from drake_dock.docking.model.diagram import DiagramSpec
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
    base = DiagramSpec.of(load_scenario(PAPER_EXAMPLE))
    for path, value in (("simulation.capture_lateral", 0.02),
                        ("simulation.capture_tilt_deg", 1.0),
                        ("simulation.capture_distance", 0.004), ("thrust.force", 100.0),
                        ("contact.mu", 0.2), ("geometry.Rs", 0.45)):
        s = load_scenario(PAPER_EXAMPLE)
        set_field(s, path, value)
        assert DiagramSpec.of(s) != base, path
    for path, value in (("initial.lateral_offset", [0.05, 0.0]),
                        ("initial.target_yaw_deg", 2.0), ("simulation.duration", 3.0)):
        s = load_scenario(PAPER_EXAMPLE)
        set_field(s, path, value)
        assert DiagramSpec.of(s) == base and hash(DiagramSpec.of(s)) == hash(base), path


def test_a_field_path_through_no_field_is_refused_by_name():
    """`set_field` names a path that no scenario field holds instead of adding an attribute
    to a section (a dataclass takes any name): in a section, in an optional section the
    scenario leaves out (left out still), in Drake's SimulatorConfig and below a value."""
    from drake_dock.campaign.plan import set_field
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
    from drake_dock.errors import InputError
    s = load_scenario(PAPER_EXAMPLE)
    assert s.thrust is None
    for path, bad in (("simulation.max_step_size", "max_step_size"),
                      ("simulator_config.max_step", "max_step"), ("initial.tilt", "tilt"),
                      ("thrust.forse", "forse"), ("contact.mu.real", "real"),
                      ("simulator_config.max_step_size.real", "real")):
        with pytest.raises(InputError, match=f"no field '{bad}'"):
            set_field(s, path, 0.01)
    assert s == load_scenario(PAPER_EXAMPLE)
    set_field(s, "simulator_config.max_step_size", 0.01)
    set_field(s, "thrust.force", 250.0)
    assert s.simulator_config.max_step_size == 0.01 and s.thrust.force == 250.0
