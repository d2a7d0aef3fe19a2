"""`couple_table` (all couples' outputs at once, compiled) against an independent assembly: per
pair, its points from the patches' own jets (`drake_dock.core.patches`) at the row's couple,
placed by Drake's frame poses; the row's couple is the state's u* for a far pair; a contact
frame that is a rotation with n its third column; the gap of a tracked or contact couple
along n between its points (a point pair's sphere radius apart), and a far pair's gap a lower
bound of its points' distance. On a docking run with the complete set, before contact and after
its impacts (far, tracked and in-contact pairs alike); every couple port equals its row."""
import numpy as np

from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import docking_simulator
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.systems.contact_types import COUPLE_SLICES as S


def test_the_table_is_the_pairs_points_frames_and_gaps():
    s = load_scenario()
    s.contact.pairs = "complete"
    s.initial.tilt_deg = [1.0, 0.5]
    s.initial.lateral_offset = [0.02, -0.01]
    dd = build_docking_diagram(DiagramSpec.of(s))
    sim = docking_simulator(dd, place(s), s.simulator_config)
    system = dd.contact
    plant = dd.dp.plant
    modes_seen = set()
    for t in (0.002, 0.03, 0.06):
        sim.AdvanceTo(t)
        ctx = system.GetMyContextFromRoot(sim.get_context())
        table = system.couple_table(ctx)
        x = ctx.get_continuous_state_vector().CopyToVector()
        pc = plant.CreateDefaultContext()
        plant.SetPositionsAndVelocities(pc, x[:system.nq + system.nv])
        modes = system.get_modes(ctx)
        for i, p in enumerate(system.pairs):
            row = table[i]
            np.testing.assert_array_equal(row, system.get_couple_output_port(p.name).Eval(ctx))
            assert row[S["status"]][0] == int(modes.pairs[i].mode)
            n1, n2 = p.patch1.dim, p.patch2.dim
            u = row[S["u"]][:n1 + n2]
            if modes.pairs[i].mode == 0:
                np.testing.assert_array_equal(u, x[system.nq + system.nv:][system.couple_slice(i)])
            X1, X2 = p.frame1.CalcPoseInWorld(pc), p.frame2.CalcPoseInWorld(pc)
            c1 = X1.multiply(np.asarray(p.patch1.jet(list(u[:n1]))[0], dtype=float))
            c2 = X2.multiply(np.asarray(p.patch2.jet(list(u[n1:]))[0], dtype=float))
            frame = row[S["frame"]].reshape(3, 3)
            np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-12)
            n = frame[:, 2]
            p1, p2 = row[S["p1"]], row[S["p2"]]
            radius = getattr(p.patch1, "radius", 0.0) if n1 == 0 else 0.0
            inside = all(np.all((P.lower <= v) & (v <= P.upper))
                         for P, v in ((p.patch1, u[:n1]), (p.patch2, u[n1:])))
            if modes.pairs[i].mode == 0:
                # A pair the broad phase kept far without a seek has no couple: u* = 0, maybe
                # outside its domain, where a patch's formula is its kernel's choice.
                if inside:
                    np.testing.assert_allclose(p1, c1, atol=1e-12, err_msg=p.name)
                    np.testing.assert_allclose(p2, c2, atol=1e-12, err_msg=p.name)
                    # The gap bounds the patches' distance from below, which points of the
                    # patches bound from above.
                    assert row[S["gap"]][0] <= np.linalg.norm(p1 - p2) + 1e-12
            else:
                # A point pair's p1 is its sphere's point towards body 2: centre - r n.
                np.testing.assert_allclose(p2, c2, atol=1e-12, err_msg=p.name)
                np.testing.assert_allclose(p1 + radius * n, c1, atol=1e-12, err_msg=p.name)
                assert abs(row[S["gap"]][0] - (n @ (c1 - p2) - radius)) < 1e-12
        modes_seen |= set(table[:, 0].astype(int).tolist())
    # Far rows and at least one couple that is tracked or in contact were compared.
    assert 0 in modes_seen and len(modes_seen) > 1
