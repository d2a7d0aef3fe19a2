"""The initial state of a docking run: the three bodies' poses and velocities at t = 0, and
where the first contact lies (found by `drake_dock.docking.placement`, set into the plant by
`drake_dock.docking.model.plant.set_initial_state`). Plain Python (no Drake)."""
from __future__ import annotations

import dataclasses


@dataclasses.dataclass
class InitialState:
    """World poses (R, p) and spatial velocities (w, v) of the three bodies at t = 0."""

    X_WB: dict
    V_WB: dict
    d_contact: float           # ring-face distance at first contact
    d0: float                  # initial ring-face distance
    closing_pairs: list
    contact_offset: tuple = (0.0, 0.0)   # the ring centre's lateral offset at first contact
    # The `DockingScene` the placement found it in (`simulate` builds its Diagram on it when
    # it is the scenario's; not compared).
    scene: object = dataclasses.field(default=None, compare=False, repr=False)
