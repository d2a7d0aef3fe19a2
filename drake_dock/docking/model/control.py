"""A controller on the chaser: the docking Diagram wrapped with a system that drives its
``chaser_wrench`` input ([torque, force] on the chaser at its mass centre, world frame, N m and
N), fed with the plant state [q, v] if it has an input. The result is a `DockingDiagram` that
`drake_dock.docking.model.simulate.simulate` and `drake_dock.run.run` (argument ``dd``) accept; the
work of the wrench is the energy ledger's ``input_work``.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from pydrake.systems.framework import BasicVector, DiagramBuilder, LeafSystem

from drake_dock.docking.model.diagram import DockingDiagram

WRENCH_SIZE = 6


def with_controller(dd: DockingDiagram, controller) -> DockingDiagram:
    """``dd`` with ``controller`` (a Drake system: output port 0 the 6-vector wrench; input
    port 0, if any, the plant state) connected to its ``chaser_wrench`` input. Every output
    port of ``dd`` is exported under its name."""
    builder = DiagramBuilder()
    inner = builder.AddSystem(dd.diagram)
    inner.set_name("docking")
    ctrl = builder.AddSystem(controller)
    if ctrl.num_input_ports():
        builder.Connect(inner.GetOutputPort("state"), ctrl.get_input_port(0))
    builder.Connect(ctrl.get_output_port(0), inner.GetInputPort("chaser_wrench"))
    for k in range(inner.num_output_ports()):
        port = inner.get_output_port(k)
        builder.ExportOutput(port, port.get_name())
    return dataclasses.replace(dd, diagram=builder.Build())


class WrenchController(LeafSystem):
    """A controller from a Python function: ``law(t, x) -> [torque, force]`` (world frame) of
    the time and the plant state x = [q, v] (`drake_dock.docking.report.results` reads the same
    state)."""

    def __init__(self, state_size: int, law):
        super().__init__()
        self.law = law
        self.DeclareVectorInputPort("state", state_size)
        self.DeclareVectorOutputPort("chaser_wrench", BasicVector(WRENCH_SIZE), self._out)

    def _out(self, context, out):
        x = self.get_input_port(0).Eval(context)
        out.SetFromVector(np.asarray(self.law(context.get_time(), x), float))
