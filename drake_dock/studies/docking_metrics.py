"""The docking metrics of the speed-accuracy study, for a drake_dock run and a compliant run
alike, and each metric's error measured against the contact's effect on it.

Metrics, all up to capture (the axial ring-centre distance reaching ``capture_distance``, at
t_c); e3 is the docking axis, the target APDS's z at t = 0:

- ``capture_time`` t_c [s];
- ``apds_spin_rate``: the target APDS's angular velocity about e3 at capture [rad/s];
- ``chaser_axial_velocity``: the chaser's velocity along e3 at capture [m/s];
- ``peak_contact_force``: the peak magnitude of the net contact force on the chaser over the
  sliding phase, the window [t_c / 2, t_c] (the scenes' impacts end before t_c / 2): an
  impulsive rigid impact has no peak force to compare with [N]. Rigid: from the couples'
  lambda_n, lambda_t and frames at the samples, the window's start interpolated; compliant:
  the chaser's momentum change over each step (its only force is contact);
- ``peak_stewart_stroke``: the peak over [0, t_c] of \\|x\\|, the translational deflection of
  the target APDS on its Stewart element (`drake_dock.docking.model.plant.stewart_deflection`); the
  largest sample is refined by the parabola through it and its two neighbours [m];
- ``chaser_impulse``: \\|m_c (v_c(t_c) - v_c(0))\\|, the impulse the contact delivers to the
  chaser up to capture, impacts included (its only force is contact) [N s].

The error of a metric m against the reference m_ref is \\|m - m_ref\\| / E, with E the
metric's *contact effect* in the reference run:

- ``capture_time``: t_c - t_free, t_free = (d0 - capture_distance) / chaser_speed the capture
  time without contact (the chaser's ring centre closing at its initial axial rate, the target
  at rest; the chaser's rotation over the approach is neglected);
- ``apds_spin_rate``, ``chaser_axial_velocity``: \\|m(t_c) - m(0)\\|;
- ``peak_contact_force``, ``peak_stewart_stroke``, ``chaser_impulse`` (zero without contact):
  \\|m_ref\\|.

An error of 1e-3 is then a thousandth of what contact does to the metric. Relative to the
metric's value it would not be: the paper example's chaser loses 1.4 % of its axial velocity
up to capture, so 1e-3 of that velocity is 7 % of the contact's effect.
"""
import dataclasses

import numpy as np

from drake_dock.docking.model.plant import stewart_history
from drake_dock.docking.report.results import rigid_chaser_force

METRICS = ("capture_time", "apds_spin_rate", "chaser_axial_velocity", "peak_contact_force",
           "peak_stewart_stroke", "chaser_impulse")
ZERO_WITHOUT_CONTACT = ("peak_contact_force", "peak_stewart_stroke", "chaser_impulse")
UNITS = {"capture_time": "s", "apds_spin_rate": "rad/s", "chaser_axial_velocity": "m/s",
         "peak_contact_force": "N", "peak_stewart_stroke": "m", "chaser_impulse": "N s"}


@dataclasses.dataclass(frozen=True)
class SceneStart:
    """What the metrics and their contact effects need of a scene at t = 0."""
    e3: np.ndarray          # the docking axis
    spin0: float            # the target APDS's angular velocity about e3
    v0: np.ndarray          # the chaser's velocity
    chaser_mass: float
    free_capture_time: float   # t_free (module docstring)


def scene_start(scenario, state) -> SceneStart:
    """The `SceneStart` of a scenario and its initial state (`InitialState`)."""
    e3 = state.X_WB["target_apds"][0][:, 2].copy()
    cap = scenario.simulation.capture_distance
    return SceneStart(e3, float(np.asarray(state.V_WB["target_apds"][0]) @ e3),
                      np.asarray(state.V_WB["chaser"][1], float).copy(),
                      float(scenario.bodies.chaser.mass),
                      (state.d0 - cap) / scenario.initial.chaser_speed)


def contact_effect(ref: dict, start: SceneStart) -> dict:
    """{metric: E}, each metric's contact effect in the reference metrics ``ref``."""
    eff = {"capture_time": abs(ref["capture_time"] - start.free_capture_time),
           "apds_spin_rate": abs(ref["apds_spin_rate"] - start.spin0),
           "chaser_axial_velocity": abs(ref["chaser_axial_velocity"] - start.v0 @ start.e3)}
    eff.update({k: abs(ref[k]) for k in ZERO_WITHOUT_CONTACT})
    return eff


def errors(m: dict, ref: dict, effect: dict) -> dict:
    """{metric: \\|m - m_ref\\| / E, or None where ``m`` has no value (no capture)}."""
    return {k: (abs(m[k] - ref[k]) / effect[k] if m.get(k) is not None else None)
            for k in METRICS}


def sampled_peak(t, y) -> float:
    """The peak of a smooth y(t) from its samples (t increasing): the largest sample, refined
    by the vertex of the parabola through it and its two neighbours when it is inside."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    i = int(np.argmax(y))
    if i == 0 or i == len(y) - 1:
        return float(y[i])
    (t0, t1, t2), (y0, y1, y2) = t[i - 1:i + 2], y[i - 1:i + 2]
    s0, s1 = (y1 - y0) / (t1 - t0), (y2 - y1) / (t2 - t1)
    c = (s1 - s0) / (t2 - t0)                 # the parabola's second divided difference
    if c >= 0:
        return float(y1)
    b = s0 - c * (t0 + t1)                    # y = y0 + s0 (t - t0) + c (t - t0)(t - t1)
    tv = -b / (2 * c)
    return float(y0 + s0 * (tv - t0) + c * (tv - t0) * (tv - t1))


def _distinct(t):
    """Keeps the last of samples that share a time (pre- and post-impact samples)."""
    return np.r_[np.diff(t) > 0, True]


def sliding_peak_force(t, Fn, t_c) -> float:
    """The peak of \\|F\\| sampled at t over [t_c / 2, t_c]; the window's start falls between
    samples and is interpolated linearly (a start that depends on the step sequence would make
    the peak depend on it)."""
    keep = _distinct(t)
    start = float(np.interp(0.5 * t_c, t[keep], Fn[keep]))
    win = (t >= 0.5 * t_c) & (t <= t_c)
    return max(start, float(Fn[win].max())) if win.any() else start


def at_capture(t_c, spin, v_c, start: SceneStart) -> dict:
    """The metrics read from the state at capture."""
    v_c = np.asarray(v_c, float)
    return {"capture_time": float(t_c), "apds_spin_rate": float(spin),
            "chaser_axial_velocity": float(v_c @ start.e3),
            "chaser_impulse": float(start.chaser_mass * np.linalg.norm(v_c - start.v0))}


def rigid_metrics(result, start: SceneStart) -> dict:
    """The metrics of a drake_dock `RunResult` (its record ends at capture)."""
    if not result.captured:
        return dict.fromkeys(METRICS)
    rec = result.record
    dp = result.dd.dp
    pc = dp.plant.CreateDefaultContext()
    dp.plant.SetPositionsAndVelocities(pc, rec.x[-1])
    v_c = dp.plant.EvalBodySpatialVelocityInWorld(pc, dp.bodies["chaser"]).translational()
    w_a = dp.plant.EvalBodySpatialVelocityInWorld(pc, dp.bodies["target_apds"]).rotational()
    t, F = rigid_chaser_force(result)
    keep = _distinct(t)
    stroke = stewart_history(dp, np.asarray(rec.x)[keep])[0]
    m = at_capture(result.capture_time, w_a @ start.e3, v_c, start)
    m["peak_contact_force"] = sliding_peak_force(t, np.linalg.norm(F, axis=1), m["capture_time"])
    m["peak_stewart_stroke"] = sampled_peak(t[keep], stroke)
    return m


def compliant_metrics(run, start: SceneStart) -> dict:
    """The metrics of a `drake_dock.studies.compliant.CompliantRun`."""
    if not run.captured:
        return dict.fromkeys(METRICS)
    t_c = run.capture_time
    m = at_capture(t_c, run.apds_spin_rate, run.chaser_velocity, start)
    before = run.t < t_c
    m["peak_contact_force"] = run.peak_force
    m["peak_stewart_stroke"] = sampled_peak(np.r_[run.t[before], t_c],
                                            np.r_[run.stroke[before], run.stroke_at_capture])
    return m
