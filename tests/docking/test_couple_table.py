"""`couple_table` (all couples' outputs at once, the far pairs' rows filled together) against
a second implementation: each couple's own output port, evaluated one by one, on a docking run
with the complete set, before contact and after its impacts (far, tracked and in-contact pairs
alike)."""
import numpy as np
import pytest

from drake_dock.docking.diagram import build_docking_diagram
from drake_dock.docking.scenario import load_scenario
from drake_dock.docking.scene import initial_state
from drake_dock.docking.simulate import docking_simulator


def test_the_table_is_the_couple_ports():
    s = load_scenario()
    s.contact.pairs = "complete"
    s.initial.tilt_deg = [1.0, 0.5]
    s.initial.lateral_offset = [0.02, -0.01]
    dd = build_docking_diagram(s)
    sim = docking_simulator(dd, initial_state(s), s.simulator_config)
    modes_seen = set()
    for t in (0.002, 0.03, 0.06):
        sim.AdvanceTo(t)
        ctx = dd.contact.GetMyContextFromRoot(sim.get_context())
        table = dd.contact.couple_table(ctx)
        for i, p in enumerate(dd.contact.pairs):
            port = dd.contact.get_couple_output_port(p.name).Eval(ctx)
            # A far row's points are placed by one stacked product (rounding within a few ulp).
            tol = 4 * np.spacing(np.abs(port).max()) if table[i][0] == 0 else 0.0
            np.testing.assert_allclose(table[i], port, rtol=0, atol=tol, err_msg=p.name)
        modes_seen |= set(table[:, 0].astype(int).tolist())
        # The far rows from pair states that are not the evaluation's own list (a context
        # whose modes are not those of its cached evaluation): the travel bounds from each
        # state's own reference pose.
        E = dd.contact._cache.Eval(ctx)
        far = [i for i, c in enumerate(E.evals) if c is None]
        Y = np.zeros_like(table)
        x = ctx.get_continuous_state_vector().CopyToVector()
        dd.contact._rows.fill_far(Y, x, E, list(E.modes.pairs), far)
        np.testing.assert_array_equal(Y[far], table[far])
    # Far rows and at least one couple that is tracked or in contact were compared.
    assert 0 in modes_seen and len(modes_seen) > 1
