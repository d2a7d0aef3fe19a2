"""What a run leaves behind on its Diagram. pydrake keeps a Python LeafSystem alive for as
long as the process lives once a DiagramBuilder has held it, so a campaign that builds a
Diagram per sample keeps every Diagram; what each keeps must not grow with the run. The modes
indices (each holding what the engine derived of it) alive after a run are counted after a
short and a ten times longer run of the same scenario: each Diagram keeps a handful (the
last modes' index and the layouts the contact system derived), not one per mode change or
seek. The count uses `type(o)`, which does not dereference a dead weakref proxy among the
collector's objects (`isinstance` does, and raises ReferenceError)."""
import gc

from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import MODELS_DIR
from drake_dock.systems.contact_types import ModesIndex


def _indices_alive_after(scenario, state, duration) -> tuple[int, int]:
    dd = build_docking_diagram(DiagramSpec.of(scenario))
    r = simulate(scenario, state, dd=dd, duration=duration)
    changes = r.mode_changes + sum(r.timing["seeks_per_pair"].values())
    del r
    gc.collect()
    return sum(type(o) is ModesIndex for o in gc.get_objects()), changes


def test_a_longer_run_leaves_no_more_behind():
    s = load_scenario(MODELS_DIR / "idss_box_corner.yaml")
    state = place(s)
    base, _ = _indices_alive_after(s, state, 0.0)
    short, c_short = _indices_alive_after(s, state, 0.05)
    long, c_long = _indices_alive_after(s, state, 0.5)
    assert c_long > c_short + 50          # the longer run made many more modes
    assert short - base <= 5 and long - short <= 5
