"""The floors the bench scripts print (`target_floor.py`, `paper_example.py`, `evaluation.py`,
`offnominal.py`): the same plant integrated by Drake without contact, and the least a
Python LeafSystem costs per derivative evaluation in Drake's simulator."""
import time

from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from drake_dock.docking.model.plant import PlantSpec, add_docking_plant, set_initial_state
from drake_dock.systems.simulator import make_simulator


def free_flight(scenario, state, t_end):
    """Wall seconds and derivative evaluations of the scenario's plant alone (free flight with
    the Stewart element, no contact) from ``state`` to ``t_end`` with its `SimulatorConfig`."""
    builder = DiagramBuilder()
    dp = add_docking_plant(builder, PlantSpec.of(scenario))
    diagram = builder.Build()
    sim = make_simulator(diagram, scenario.simulator_config, lambda root: set_initial_state(
        dp, dp.plant.GetMyMutableContextFromRoot(root), state))
    t0 = time.perf_counter()
    sim.Initialize()
    sim.AdvanceTo(t_end)
    return time.perf_counter() - t0, sim.get_integrator().get_num_derivative_evaluations()


class _Empty(LeafSystem):
    """Two states, a derivative that copies numbers: the least a Python LeafSystem costs."""

    def __init__(self):
        super().__init__()
        self.DeclareContinuousState(2)
        self.n = 0

    def DoCalcTimeDerivatives(self, context, derivatives):
        self.n += 1
        x = context.get_continuous_state_vector().CopyToVector()
        derivatives.get_mutable_vector().SetFromVector([x[1], -1e4 * x[0]])


def empty_leaf_cost(scheme, n_min=3000) -> float:
    """Wall seconds per derivative evaluation of `_Empty` under ``scheme``."""
    s = _Empty()
    sim = make_simulator(s, SimulatorConfig(integration_scheme=scheme, accuracy=1e-3),
                         lambda root: root.SetContinuousState([1.0, 0.0]))
    t0 = time.perf_counter()
    sim.Initialize()
    t = 0.0
    while s.n < n_min:
        t += 0.1
        sim.AdvanceTo(t)
    return (time.perf_counter() - t0) / s.n
