"""How a docking run ends: the named outcomes and their rules (pure functions of the rings'
relative pose over time and of whether post-contact thrust still acts).

- ``captured``: the latches can engage: the axial ring-centre distance within
  ``simulation.capture_distance``, the lateral offset within ``simulation.capture_lateral`` and
  the tilt between the docking axes within ``simulation.capture_tilt_deg`` (`CaptureRule`;
  `drake_dock.docking.model.capture.CaptureMonitor` locates it with a witness).
- ``missed``: the chaser passes beside the target (the rings' centres more than 2 R apart
  across the axis: their disks no longer overlap) or beyond its ring plane: the chaser's ring
  centre more than ``simulation.capture_distance`` behind the target's ring face while off the
  axis by more than ``simulation.capture_lateral`` (its ring went round or through the
  target's, whose ring is modelled as its face and circles: the latches cannot engage from
  there), or more than a petal height H behind it anywhere.
- ``rebound``: the rings separate: their distance above its start and growing, with no thrust
  still to act (a couple may still graze).
- ``jammed``: the distance to capture (`CaptureRule.to_go`) has not fallen by ``JAM_DISTANCE``
  for ``simulation.jam_time`` seconds with no thrust still to act (the thrust restarts the
  clock while it drives the chaser). The run's result names the couples that hold the rings
  (`drake_dock.docking.model.simulate`).
- ``timeout``: ``simulation.duration`` reached first.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np


OUTCOMES = ("captured", "missed", "rebound", "jammed", "timeout")
JAM_DISTANCE = 1e-3     # m: the progress that resets the jam clock


def _floats(a) -> list:
    """An array's entries as (nested lists of) Python floats."""
    return np.asarray(a, dtype=float).tolist()


def misalignment(R_t, p_t, R_c, p_c) -> tuple[float, float, float]:
    """The chaser ring's pose in the target ring's frame (rotation R_t, centre p_t; R_c, p_c the
    chaser's; the two docking axes face each other): the axial and the lateral offset of its
    centre (m) and the tilt between the axes (rad, atan2 of |z_t x -z_c| and z_t . -z_c).
    Plain float arithmetic on the arrays' entries as floats (it runs at every witness
    evaluation of a run)."""
    (x0, y0, z0), (x1, y1, z1), (x2, y2, z2) = _floats(R_t)
    (t0, t1, t2), (c0, c1, c2) = _floats(p_t), _floats(p_c)
    d0, d1, d2 = c0 - t0, c1 - t1, c2 - t2
    (_, _, a0), (_, _, a1), (_, _, a2) = _floats(R_c)
    a0, a1, a2 = -a0, -a1, -a2                                 # z_c: the chaser's axis reversed
    cx, cy, cz = z1 * a2 - z2 * a1, z2 * a0 - z0 * a2, z0 * a1 - z1 * a0     # z_t x z_c
    tilt = math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), z0 * a0 + z1 * a1 + z2 * a2)
    return (z0 * d0 + z1 * d1 + z2 * d2,
            math.hypot(x0 * d0 + x1 * d1 + x2 * d2, y0 * d0 + y1 * d1 + y2 * d2), tilt)


@dataclasses.dataclass(frozen=True)
class CaptureRule:
    """The latches' tolerances (docs/model.md, "Capture"): ``axial`` (m, the ring-centre
    distance along the target's axis), ``lateral`` (m) and ``tilt_deg`` (deg); None leaves a
    tolerance out of the test. ``ring_radius`` (m) turns a tilt into the rim's displacement."""

    axial: float
    lateral: float | None
    tilt_deg: float | None
    ring_radius: float

    @classmethod
    def of(cls, simulation, geometry) -> "CaptureRule":
        return cls(simulation.capture_distance, simulation.capture_lateral,
                   simulation.capture_tilt_deg, geometry.R)

    def to_go(self, axial: float, lateral: float, tilt: float) -> float:
        """The distance to capture (m): the axial distance, or where the lateral offset or the
        tilt (rad; as the rim's displacement R tilt) exceeds its tolerance by more, the axial
        tolerance plus that excess. Captured iff to_go <= ``axial``; continuous, so that a
        witness can locate it. With no lateral or tilt tolerance it is the axial distance."""
        d = axial
        if self.lateral is not None:
            d = max(d, self.axial + (lateral - self.lateral))
        if self.tilt_deg is not None:
            d = max(d, self.axial + self.ring_radius * (tilt - math.radians(self.tilt_deg)))
        return d

    def describe(self) -> str:
        parts = [f"axial ring-centre distance <= {self.axial:g} m"]
        if self.lateral is not None:
            parts.append(f"lateral offset <= {self.lateral:g} m")
        if self.tilt_deg is not None:
            parts.append(f"tilt <= {self.tilt_deg:g} deg")
        return ", ".join(parts)


@dataclasses.dataclass
class OutcomeWatch:
    """Fed the rings' pose (`misalignment`) and the distance to capture (`CaptureRule.to_go`)
    at each step; ``update`` returns (outcome, reason) once a rule other than capture holds,
    else None. ``beside`` (m, 2 R), ``beyond`` (m, H) and ``past`` (m, the capture distance,
    off the axis by more than ``off_axis``, the capture's lateral tolerance) are the `missed`
    rule's bounds."""

    d_start: float
    jam_time: float
    beside: float = math.inf
    beyond: float = math.inf
    past: float = math.inf
    off_axis: float = 0.0
    t_best: float = 0.0
    d_best: float = float("inf")
    d_last: float = float("inf")

    @classmethod
    def of(cls, d_start: float, simulation, geometry) -> "OutcomeWatch":
        """The watch of a scenario's ``simulation`` and ``geometry`` sections."""
        return cls(d_start, simulation.jam_time, beside=2.0 * geometry.R, beyond=geometry.H,
                   past=simulation.capture_distance, off_axis=simulation.capture_lateral or 0.0)

    def update(self, t: float, d: float, lateral: float = 0.0, to_go: float | None = None,
               driven: bool = False):
        """``d``: the axial ring-centre distance (m), ``lateral`` the lateral offset (m),
        ``driven``: post-contact thrust acts now or later."""
        to_go = d if to_go is None else to_go
        if driven or to_go <= self.d_best - JAM_DISTANCE or self.d_best == float("inf"):
            self.d_best, self.t_best = min(to_go, self.d_best), t
        growing, self.d_last = d > self.d_last, d
        if lateral > self.beside:
            return "missed", (f"the chaser passes beside the target: the ring centres "
                              f"{lateral:.4g} m apart across the axis (> 2 R = "
                              f"{self.beside:g} m)")
        if d < -self.beyond:
            return "missed", (f"the chaser passes beyond the target's ring plane: its ring "
                              f"centre {-d:.4g} m behind it (> H = {self.beyond:g} m), "
                              f"{lateral:.4g} m off the axis")
        if d < -self.past and lateral > self.off_axis:
            return "missed", (f"the chaser passes beyond the target's ring plane off the axis: "
                              f"its ring centre {-d:.4g} m behind it (> {self.past:g} m), "
                              f"{lateral:.4g} m off the axis (> {self.off_axis:g} m)")
        if not driven and growing and d > self.d_start:
            return "rebound", (f"the rings separate: ring distance {d:.6g} m, above its start "
                               f"{self.d_start:.6g} m and growing")
        if t - self.t_best >= self.jam_time:
            return "jammed", (f"the distance to capture has not fallen by {JAM_DISTANCE:g} m "
                              f"in {self.jam_time:g} s (at {to_go:.6g} m; ring distance "
                              f"{d:.6g} m)")
        return None


def progress_fraction(t: float, t_end: float, d: float, d_start: float, d_capture: float):
    """How far the run is: the way of d (the distance to capture, `CaptureRule.to_go`) from
    d_start towards d_capture, or the time towards the timeout, whichever is further."""
    way = (d_start - d) / (d_start - d_capture) if d_start > d_capture else 0.0
    return min(max(way, t / t_end, 0.0), 1.0)
