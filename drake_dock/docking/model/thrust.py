"""Post-contact thrust (docs/model.md, "Post-contact thrust"): the chaser's jets push it along
its docking axis, towards the target, from the first contact, as Soyuz and the Shuttle fired
theirs at the contact signal to guarantee capture.

The scenario's ``thrust`` section gives the force (N) and when it acts, in seconds after the
first contact: from ``delay`` for ``duration`` (open: until the run ends), or the listed
``pulses`` [start, end]. `ThrustSystem` drives the contact system's ``chaser_thrust`` input:
the force F e3 on the chaser at its mass centre (e3 its APDS frame's docking axis, towards the
target; no torque), switched by the contact system's ``first_contact_time`` output. A witness
at each switch ends an integration step there, so the step does not straddle the jump.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from pydrake.systems.framework import (BasicVector, EventStatus, LeafSystem, PublishEvent,
                                       WitnessFunctionDirection)


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
    """Input ``state`` (the plant's [q, v]) and ``first_contact_time`` (s, +inf before it);
    output ``chaser_thrust``, the wrench [torque, force] (world frame) on the chaser at its
    mass centre: F times the chaser APDS's docking axis while the `ThrustSchedule` acts."""

    def __init__(self, dp, schedule: ThrustSchedule):
        super().__init__()
        self.dp, self.schedule = dp, schedule
        self._nq = dp.plant.num_positions()
        # The chaser APDS frame's docking axis e3 from the chaser's quaternion: R_WB R_BF e3.
        frame = dp.apds_frames["chaser_apds"]
        self._q0 = int(frame.body().floating_positions_start())
        self._e3_B = tuple(float(c) for c in frame.GetFixedPoseInBodyFrame().rotation().col(2))
        self._zero = np.zeros(WRENCH_SIZE)
        n = self._nq + dp.plant.num_velocities()
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

    def acting(self, context) -> bool:
        tc = float(self._contact.Eval(context)[0])
        return math.isfinite(tc) and self.schedule.on(context.get_time() - tc)

    def axis(self, q) -> tuple:
        """The chaser APDS frame's docking axis (world) at the positions q: the chaser's
        rotation (its quaternion, normalised as Drake does) applied to the frame's e3 in the
        body (plain float arithmetic: it runs at every evaluation while the thrust acts)."""
        w, x, y, z = (float(c) for c in q[self._q0:self._q0 + 4])
        s = 2.0 / (w * w + x * x + y * y + z * z)
        a, b, c = self._e3_B
        return ((1.0 - s * (y * y + z * z)) * a + s * (x * y - w * z) * b + s * (x * z + w * y) * c,
                s * (x * y + w * z) * a + (1.0 - s * (x * x + z * z)) * b + s * (y * z - w * x) * c,
                s * (x * z - w * y) * a + s * (y * z + w * x) * b + (1.0 - s * (x * x + y * y)) * c)

    def _out(self, context, out):
        if not self.acting(context):
            out.SetFromVector(self._zero)
            return
        f = self.schedule.force
        e0, e1, e2 = self.axis(self._state.Eval(context))
        out.SetFromVector([0.0, 0.0, 0.0, f * e0, f * e1, f * e2])

    def DoGetWitnessFunctions(self, context):
        return self._witnesses
