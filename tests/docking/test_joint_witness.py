"""The joint witness beside the held ones (`drake_dock.systems.witnesses`): where an armed
witness is not positive after an event (a hand-over guard left below zero), Drake is given the
joint witness of the others beside it. The run is the same, bit for bit, as with one function
per transition (`ContactOptions.joint_witness` off: a second implementation), on an IDSS sample
where a ring's hand-over guard stays below zero through many events."""
import dataclasses

import numpy as np

from drake_dock.campaign.plan import load_plan
from drake_dock.campaign.points import sample_specs
from drake_dock.campaign.sample import sample_scenario
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import PlacementCache, place
from drake_dock.docking.scenario.models_dir import MODELS_DIR

SAMPLE, DURATION = 6, 1.0      # its cc_Cring_T6 hand-over guard is below zero from 0.79 s


def _run(joint: bool):
    plan, base, fields = load_plan(MODELS_DIR / "idss_envelope.yaml")
    (spec,) = sample_specs(plan, fields, [SAMPLE])
    scenario = sample_scenario(base, spec[2])
    options = build_docking_diagram(DiagramSpec.of(scenario)).contact.options
    dd = build_docking_diagram(DiagramSpec.of(
        scenario, options=dataclasses.replace(options, joint_witness=joint)))
    return simulate(scenario, place(scenario, PlacementCache(dd.scene)), dd=dd,
                    duration=DURATION), dd.contact


def test_the_joint_witness_beside_held_ones_takes_the_same_run():
    joint, system = _run(True)
    each, system_each = _run(False)
    held = list(system._rest)
    assert held and all(kind == "handover" for h in held for _, kind in h)
    assert not system_each._rest
    assert joint.end_time == each.end_time and joint.evaluations == each.evaluations
    assert [(i.t, i.couples) for i in joint.impacts] == [(i.t, i.couples) for i in each.impacts]
    assert len(joint.impacts) > 0
    np.testing.assert_array_equal(np.array(joint.record.t), np.array(each.record.t))
    np.testing.assert_array_equal(np.array(joint.record.states), np.array(each.record.states))
