"""How a docking run ends besides capture: the named outcomes and their rules (pure functions
of the ring distance over time and of whether a couple is in contact).

- ``captured``: the axial ring-centre distance reaches ``simulation.capture_distance``
  (`drake_dock.docking.diagram.CaptureMonitor`, a witness).
- ``rebound``: no couple in contact, the ring distance above its start and growing.
- ``jammed``: the ring distance has not fallen by ``JAM_DISTANCE`` for
  ``simulation.jam_time`` seconds.
- ``timeout``: ``simulation.duration`` reached first.
"""
from __future__ import annotations

import dataclasses

OUTCOMES = ("captured", "rebound", "jammed", "timeout")
JAM_DISTANCE = 1e-3     # m: the progress that resets the jam clock


@dataclasses.dataclass
class OutcomeWatch:
    """Fed the ring distance at each step; ``update`` returns (outcome, reason) once a rule
    other than capture holds, else None."""

    d_start: float
    jam_time: float
    t_best: float = 0.0
    d_best: float = float("inf")
    d_last: float = float("inf")

    def update(self, t: float, d: float, in_contact: bool):
        if d <= self.d_best - JAM_DISTANCE or self.d_best == float("inf"):
            self.d_best, self.t_best = d, t
        growing, self.d_last = d > self.d_last, d
        if not in_contact and growing and d > self.d_start:
            return "rebound", (f"separating with no couple in contact: ring distance {d:.6g} m "
                               f"above its start {self.d_start:.6g} m")
        if t - self.t_best >= self.jam_time:
            return "jammed", (f"the ring distance has not fallen by {JAM_DISTANCE:g} m in "
                              f"{self.jam_time:g} s (at {d:.6g} m)")
        return None


def progress_fraction(t: float, t_end: float, d: float, d_start: float, d_capture: float):
    """How far the run is: the ring distance's way towards capture, or the time towards the
    timeout, whichever is further."""
    way = (d_start - d) / (d_start - d_capture) if d_start > d_capture else 0.0
    return min(max(way, t / t_end, 0.0), 1.0)
