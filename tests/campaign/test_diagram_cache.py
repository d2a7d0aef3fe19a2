"""The campaign's Diagram cache (`drake_dock.campaign.sample.diagram_for`, keyed on the
`DiagramSpec`) against fresh Diagrams: every scenario field a campaign plan can ``set`` or
``vary`` (each numeric or enum leaf of the scenario's dataclasses, found by walking them) is
changed in turn; where the changed scenario has the base's spec, so that the cache hands it the
base's Diagram, its row on that Diagram equals its row on a fresh one. Two short bases: one
captured before contact (the capture tolerances decide), one that reaches contact and an
impact. A stale Diagram, built for the base, gives another row where a capture tolerance
changes: a key without them would fail here."""
import copy
import dataclasses
import math
import typing

import pytest

from drake_dock.campaign import sample
from drake_dock.campaign.sample import diagram_for, sample_scenario, scenario_row
from drake_dock.core.lzb.solve import LAWS
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.diagram import DiagramSpec
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import PlacementCache, place
from drake_dock.docking.scenario.dimensions import PAIR_SETS
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.schema import Scenario
from drake_dock.docking.scenario.validation import INTEGRATION_SCHEMES
from drake_dock.errors import InputError

# The enum leaves (the scenario's string fields) and the values they may take.
ENUMS = {"contact.pairs": PAIR_SETS, "contact.impact_law": LAWS,
         "simulator_config.integration_scheme": INTEGRATION_SCHEMES}
# Leaves with a single valid value, which no plan can change.
FIXED = {"simulator_config.use_error_control", "simulator_config.start_time"}
# The capture tolerances, moved across the base's offset (5 mm) and tilt (0.3 deg).
ACROSS = {"simulation.capture_lateral": (0.004, 0.006), "simulation.capture_tilt_deg": (0.25, 0.35)}


def _fields(schema) -> dict:
    if dataclasses.is_dataclass(schema):
        return typing.get_type_hints(schema)
    return {f.name: f.type for f in schema.__fields__}          # Drake's SimulatorConfig


def _present(T):
    args = typing.get_args(T)
    return next(a for a in args if a is not type(None)) if type(None) in args else T


def leaves(node, schema=Scenario, path=""):
    """(dotted path, type, value) of every leaf of the scenario tree; an optional section the
    scenario leaves out is walked with its defaults (a plan's ``set`` adds it)."""
    for name, T in _fields(schema).items():
        T, value = _present(T), getattr(node, name)
        if dataclasses.is_dataclass(T) or hasattr(T, "__fields__"):
            yield from leaves(T() if value is None else value, T, f"{path}{name}.")
        else:
            yield f"{path}{name}", T, value


def _scalars(x):
    """Other values of a number: 10 % off either way, or for 0 and None a few magnitudes."""
    if x is None or x == 0:
        return [1.0, 0.6, 0.01, 0.001]
    return [1.1 * x, 0.9 * x]


def candidates(path, T, value) -> list:
    """The values a plan could give the leaf, the base's excluded."""
    if path in ACROSS:
        return [v for v in ACROSS[path] if v != value]
    if T is str:
        return [v for v in ENUMS[path] if v != value]
    if T is bool:
        return [not value]
    if typing.get_origin(T) is list:
        if typing.get_origin(typing.get_args(T)[0]) is list:   # thrust.pulses
            return [[[0.0, 0.001]]]
        return [[c, *value[1:]] for c in _scalars(value[0])]
    return _scalars(value)


def changed(base, path, T, value):
    """The base with the leaf changed to its first valid candidate, or None."""
    for v in candidates(path, T, value):
        try:
            return sample_scenario(base, {path: v})
        except InputError:
            continue
    return None


@pytest.fixture(scope="module")
def bases():
    """Base ``captured``: the paper example 1 mm from first contact, 5 mm off the axis and
    tilted 0.3 deg, within the capture tolerances at 0.5 mm of travel: captured before contact.
    Base ``contact``: the same with the lateral tolerance below the offset: it reaches contact
    and its first impact within the 3 ms it runs."""
    s = load_scenario(data="""
contact: {pairs: paper}
initial: {approach_travel: 0.001, lateral_offset: [0.005, 0.0], tilt_deg: [0.3, 0.0]}
simulation: {duration: 0.003, jam_time: 1.0, capture_lateral: 0.006, capture_tilt_deg: 0.35}
""")
    s.simulation.capture_distance = place(s).d_contact + 0.0005
    contact = sample_scenario(s, {"simulation.capture_lateral": 0.004})
    return {"captured": s, "contact": contact}


def test_every_leaf_a_plan_can_change_is_walked(bases):
    """The walk finds the scenario's leaves, each string leaf is a known enum, and every leaf
    but the `FIXED` ones has a valid other value."""
    base = bases["captured"]
    found = list(leaves(base))
    paths = [p for p, _, _ in found]
    assert {"geometry.R", "bodies.chaser.inertia", "contact.impact_law", "thrust.pulses",
            "simulation.capture_lateral", "simulator_config.accuracy"} <= set(paths)
    assert {p for p, T, _ in found if T is str} == set(ENUMS)
    assert {p for p, T, v in found if changed(base, p, T, v) is None} == FIXED


@pytest.mark.parametrize("name", ["captured", "contact"])
def test_a_cached_diagram_gives_the_row_a_fresh_one_gives(bases, name):
    base = bases[name]
    sample._DIAGRAMS.clear()
    sample._SCENES.clear()
    row = scenario_row(base)                                   # the cache holds the base's
    cached = next(reversed(sample._DIAGRAMS.values()))
    assert cached.scene is next(reversed(sample._SCENES.values()))
    assert row["outcome"] == ("captured" if name == "captured" else "timeout")
    assert (row["impacts"] == 0) == (name == "captured")
    spec = DiagramSpec.of(base)
    reused = []
    for path, T, value in leaves(base):
        if path in FIXED:
            continue
        s = changed(base, path, T, value)
        if DiagramSpec.of(s) != spec:
            continue                                           # the cache builds another
        got = scenario_row(s)
        assert next(reversed(sample._DIAGRAMS.values())) is cached, path
        assert len(sample._SCENES) == 1, path                 # its scene made once too
        fresh = scenario_row(s, reuse=False)
        diff = {k: (got[k], fresh[k]) for k in got if got[k] != fresh[k]
                and not (isinstance(got[k], float) and math.isnan(got[k])
                         and math.isnan(fresh[k]))}
        assert not diff, (path, diff)
        reused.append(path)
    # What a Diagram does not read: the approach, the run's length and the integrator's own
    # settings (the accuracy but through LZB's, which 10 % leaves at its bound, 1e-8); what it
    # reads: the energy scale (the closing speed), the capture rule, the contact law.
    assert {"initial.target_yaw_deg", "initial.lateral_offset", "simulation.duration",
            "simulator_config.integration_scheme", "simulator_config.accuracy"} <= set(reused)
    assert not {"initial.chaser_speed", "simulation.capture_lateral", "contact.mu"} & set(reused)


@pytest.mark.parametrize("path", sorted(ACROSS))
def test_a_stale_diagram_would_give_another_row(bases, path):
    """The base's Diagram asked to run the base with a capture tolerance moved across the
    offset or tilt (what a cache keyed without the tolerance would do) gives another outcome
    than a fresh Diagram of that scenario: the changed spec is what keeps them apart."""
    base = bases["captured"]
    s = sample_scenario(base, {path: ACROSS[path][0]})
    assert DiagramSpec.of(s) != DiagramSpec.of(base)
    stale = diagram_for(DiagramSpec.of(base))
    state = place(s, PlacementCache(stale.scene))
    fresh = scenario_row(s, reuse=False)
    assert simulate(s, state, dd=stale).outcome == "captured" != fresh["outcome"]


def test_a_scene_is_shared_exactly_by_the_scenarios_of_its_key(bases):
    """`scene_for` serves one `DockingScene` to every scenario of equal geometry and contact
    set, and a new one for another geometry or set (its key, `DockingScene.key_of`)."""
    base = bases["captured"]
    sample._SCENES.clear()
    scene = sample.scene_for(base)
    assert sample.scene_for(sample_scenario(base, {"initial.target_yaw_deg": 1.0})) is scene
    other_set = copy.deepcopy(base)
    other_set.contact.pairs = "complete" if base.contact.pairs != "complete" else "paper"
    wider = sample_scenario(base, {"geometry.R": base.geometry.R * 1.01})
    for s in (other_set, wider):
        got = sample.scene_for(s)
        assert got is not scene and got.key == DockingScene.key_of(s.geometry, s.contact.pairs)
    assert sample.scene_for(base) is scene and len(sample._SCENES) == 3
