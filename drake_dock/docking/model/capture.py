"""Capture in the docking Diagram (docs/model.md, "Capture"): the rings within the latches'
tolerances (`CaptureRule`): the axial distance between the guide rings' centres, measured along
the target APDS axis, within ``simulation.capture_distance``, their lateral offset and the tilt
between their axes within ``simulation.capture_lateral`` and ``capture_tilt_deg``.
`CaptureMonitor` declares it as a witness function on the distance to capture whose publish
event ends the simulation (`EventStatus.ReachedTermination`), so the capture time is located to
the witness isolation accuracy."""
from __future__ import annotations

import math

import numpy as np
from pydrake.systems.framework import (EventStatus, LeafSystem, PublishEvent,
                                       WitnessFunctionDirection)

from drake_dock.core.kernels.free_bodies import frame_poses
from drake_dock.docking.model.outcome import CaptureRule, misalignment
from drake_dock.docking.model.plant import DockingPlant
from drake_dock.systems.witness_source import WitnessNow

_LAYOUT = ("capture",)
_NO_RATE = np.full(1, np.nan)


def ring_poses(dp: DockingPlant, plant_context):
    """World rotation and centre of the target's and the chaser's ring (APDS) frames."""
    XT = dp.apds_frames["target_apds"].CalcPoseInWorld(plant_context)
    XC = dp.apds_frames["chaser_apds"].CalcPoseInWorld(plant_context)
    return XT.rotation().matrix(), XT.translation(), XC.rotation().matrix(), XC.translation()


def axial_ring_distance(dp: DockingPlant, plant_context) -> float:
    """Distance from the target's ring centre to the chaser's, along the target APDS axis."""
    return misalignment(*ring_poses(dp, plant_context))[0]


class CaptureMonitor(LeafSystem):
    """Input ``state`` (the plant's [q, v]); output ``ring_distance`` (m, axial); a witness on
    `CaptureRule.to_go` - capture_distance whose publish event ends the simulation. A run that
    starts captured is not ended (the witness fires only on a crossing)."""

    def __init__(self, dp: DockingPlant, rule: CaptureRule):
        super().__init__()
        self.dp = dp
        self.rule = rule
        self.capture_distance = float(rule.axial)
        self._nq = dp.plant.num_positions()
        self._last = (None, None)           # (positions as bytes, their misalignment)
        # The two ring frames' poses from q in compiled code (`free_bodies.frame_poses`).
        frames = (dp.apds_frames["target_apds"], dp.apds_frames["chaser_apds"])
        bodies = [f.body() for f in frames]
        self._qs = np.array([b.floating_positions_start() for b in bodies], dtype=np.int64)
        self._fb = np.arange(2, dtype=np.int64)
        X = [f.GetFixedPoseInBodyFrame() for f in frames]
        self._R_BF = np.array([x.rotation().matrix() for x in X])
        self._p_BF = np.array([x.translation() for x in X])
        n = dp.plant.num_positions() + dp.plant.num_velocities()
        self._state = self.DeclareVectorInputPort("state", n)
        self.DeclareVectorOutputPort("ring_distance", 1,
                                     lambda c, o: o.SetFromVector([self.distance(c)]))
        self._witness = self.MakeWitnessFunction(
            "capture", WitnessFunctionDirection.kPositiveThenNonPositive,
            lambda c: self.to_go(c) - self.rule.axial,
            PublishEvent(lambda c, e: EventStatus.ReachedTermination(self, "capture")))

    def misalignment(self, context) -> tuple[float, float, float]:
        """Axial and lateral offset (m) and tilt (rad) of the chaser ring (`misalignment`); the
        axial offset is `axial_ring_distance`."""
        return self.misalignment_of(self._state.Eval(context)[:self._nq])

    def misalignment_of(self, q) -> tuple[float, float, float]:
        """`misalignment` at the plant's positions q."""
        key = q.tobytes()
        if key != self._last[0]:
            # Drake asks again at equal positions (the witness at a step's end, the monitor,
            # the ring distance output): the last answer is kept.
            R, o = np.empty((2, 3, 3)), np.empty((2, 3))
            frame_poses(self._qs, q, self._fb, self._R_BF, self._p_BF, R, o)
            self._last = (key, misalignment(R[0], o[0], R[1], o[1]))
        return self._last[1]

    def distance(self, context) -> float:
        """The axial ring-centre distance (m)."""
        return self.misalignment(context)[0]

    def to_go(self, context) -> float:
        """The distance to capture (m, `CaptureRule.to_go`); the axial distance itself when the
        rule tests nothing else."""
        return self.rule.to_go(*self.misalignment(context))

    def DoGetWitnessFunctions(self, context):
        return [self._witness]

    def witness_values(self, context) -> dict:
        return {"capture": self.to_go(context) - self.rule.axial}

    def witness_now(self, context) -> WitnessNow:
        """Its one witness for `WitnessApproach` (`drake_dock.systems.stepping`): one epoch, no
        known rate, no step-end target."""
        return WitnessNow(0, _LAYOUT, np.array([self.to_go(context) - self.rule.axial]),
                          _NO_RATE, math.inf)
