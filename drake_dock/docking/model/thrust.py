"""Post-contact thrust (docs/model.md, "Post-contact thrust"): the chaser's jets push it along
its docking axis, towards the target, from the first contact, as Soyuz and the Shuttle fired
theirs at the contact signal to guarantee capture.

The scenario's ``thrust`` section gives the force (N) and when it acts, in seconds after the
first contact: from ``delay`` for ``duration`` (open: until the run ends), or the listed
``pulses`` [start, end]. The contact system applies it (`follower_of`: a
`drake_dock.systems.follower.FollowerForce`): the force F e3 on the chaser at its origin, its
mass centre (e3 its APDS frame's docking axis, towards the target; no torque), counted from
the first contact. `ThrustSystem` holds a witness at each switch, which ends an integration
step there so that the step does not straddle the jump.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from pydrake.systems.framework import (BasicVector, EventStatus, LeafSystem, PublishEvent,
                                       WitnessFunctionDirection)

from drake_dock.systems.follower import FollowerForce


WRENCH_SIZE = 6


@dataclasses.dataclass(frozen=True)
class ThrustSchedule:
    """The force (N) and the windows (start, end) in s after the first contact in which it
    acts (end inf: until the run ends); sorted and disjoint."""

    force: float
    windows: tuple

    @classmethod
    def of(cls, thrust) -> "ThrustSchedule | None":
        """The schedule of a scenario's ``thrust`` section (validated), None without one."""
        if thrust is None:
            return None
        if thrust.pulses:
            windows = tuple((float(a), float(b)) for a, b in thrust.pulses)
        else:
            end = math.inf if thrust.duration is None else thrust.delay + thrust.duration
            windows = ((float(thrust.delay), float(end)),)
        return cls(float(thrust.force), windows)

    def on(self, since_contact: float) -> bool:
        """Whether the thrust acts ``since_contact`` s after the first contact (the windows
        closed at the start, open at the end)."""
        return any(a <= since_contact < b for a, b in self.windows)

    def still_to_act(self, since_contact: float) -> bool:
        """Whether the thrust acts now or later (before the first contact: True)."""
        return self.force > 0 and any(since_contact < b for _, b in self.windows)

    def switches(self) -> tuple:
        """The switching times after the first contact, finite and > 0 (a switch at 0 falls
        on the first impact's event, which already ends a step)."""
        return tuple(sorted({s for w in self.windows for s in w if 0 < s < math.inf}))


class ThrustSystem(LeafSystem):
    """The thrust's switching times as witnesses (a step ends at each), and its wrench as the
    output ``chaser_thrust`` ([torque, force], world frame, on the chaser at its origin) for
    a viewer. Input ``state`` (the plant's [q, v]) and ``first_contact_time`` (s, +inf before
    it). The contact system applies the thrust itself, as the `FollowerForce` ``follower``
    (F along the chaser APDS's docking axis while the `ThrustSchedule` acts)."""

    def __init__(self, dp, schedule: ThrustSchedule):
        super().__init__()
        self.dp, self.schedule = dp, schedule
        self.follower = follower_of(dp, schedule)
        n = dp.plant.num_positions() + dp.plant.num_velocities()
        self._state = self.DeclareVectorInputPort("state", n)
        self._contact = self.DeclareVectorInputPort("first_contact_time", 1)
        self.DeclareVectorOutputPort("chaser_thrust", BasicVector(WRENCH_SIZE), self._out)
        self._witnesses = [
            self.MakeWitnessFunction(
                f"thrust switch {s:g} s after contact",
                WitnessFunctionDirection.kNegativeThenNonNegative,
                lambda c, s=s: self._since_contact(c) - s,
                PublishEvent(lambda c, e: EventStatus.Succeeded()))
            for s in schedule.switches()]

    def _since_contact(self, context) -> float:
        """Seconds since the first contact; -1 before it (a witness's value must be finite)."""
        tc = float(self._contact.Eval(context)[0])
        return context.get_time() - tc if math.isfinite(tc) else -1.0

    def _out(self, context, out):
        tc = float(self._contact.Eval(context)[0])
        w = self.follower.wrench(self._state.Eval(context),
                                 context.get_time() - tc if math.isfinite(tc) else -math.inf)
        out.SetFromVector(np.zeros(WRENCH_SIZE) if w is None else w)

    def DoGetWitnessFunctions(self, context):
        return self._witnesses


def follower_of(dp, schedule: ThrustSchedule) -> FollowerForce:
    """The thrust as a `FollowerForce` on the chaser: along the chaser APDS frame's docking
    axis e3 (R_BF e3 in the chaser's body frame)."""
    frame = dp.apds_frames["chaser_apds"]
    body = frame.body()
    return FollowerForce(schedule.force,
                         tuple(float(c) for c in frame.GetFixedPoseInBodyFrame().rotation().col(2)),
                         int(body.floating_positions_start()),
                         int(body.floating_velocities_start_in_v()), schedule.windows)
