"""The referee (`drake-dock study crosscheck`): conditions of the IDSS initial-contact box run
both ways, with the same geometry, post-contact thrust and initial state:

1. drake_dock's rigid model (`drake_dock.docking.model.simulate.simulate`);
2. Drake's compliant contact (`drake_dock.studies.compliant`: point contact between convex
   pieces of the same APDS, Hunt-Crossley dissipation matched to the scenario's restitution at
   the condition's closing speed, the discrete ``similar`` approximation), an engine that
   nobody here wrote.

The conditions are the scenario's own initial conditions (``own``, the row named
``scenario``) and the conditions sweep's (`drake_dock.studies.conditions.conditions` with the
sweep's seed): its first ``random`` random conditions and its first ``corners`` corners. The
quick plan runs the scenario's own conditions only. Each run ends at a named outcome by the
same rules (`drake_dock.docking.model.outcome`: captured, missed, rebound, jammed, timeout at
``simulation.duration``).

A compliant run *counts* where the refined run (stiffness x ``stiffness_factor``, step x
``step_factor``) ends with the same outcome: a stiffer spring approaches the rigid limit, and
the smaller step keeps the number of steps per contact oscillation (whose period scales with
1 / sqrt(k)) the same.

Per condition: both outcomes and their reasons, both capture times (and the refined run's), both
peak interface forces and the wall times (each run's build, simulation and measures). The peak
interface force is the largest \\|net contact force on the target APDS\\| over the run: rigid
from the couples' forces (`drake_dock.docking.report.loads.interface_loads`; impulses excluded),
compliant from the chaser's momentum change over each step less the thrust (contact acts only
between the chaser and the target APDS). A compliant impact's force peak grows with the square
root of the stiffness and a rigid one has none, so the two are also compared as the peak mean
over ``window`` seconds: the chaser's contact impulse over a window (its momentum change less
the thrust's impulse, impacts included), divided by the window, the largest over windows that
start or end at a sample.

How each run came to the capture box (`approach`): the first time it came within
``near_margin`` of it (the distance to capture, `CaptureRule.to_go`, within the margin of the
axial tolerance), the closest it came, and the rings' final misalignment. Where the rings
reach the box's edge with the rim of one ring on the other's face, a fraction of a millimetre
decides between capture and a bounce that the thrust has to bring back: the near-capture time
compares the models without that knife edge.

The summary gives the outcome agreement over the conditions whose compliant run counts (a
rigid run ended by a numerical error disagrees), the median of \\|t_c,compliant -
t_c,rigid\\| / t_c,rigid over the conditions captured by both with a compliant run that
counts, and the same of the near-capture times.
"""
from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import time as _time

import numpy as np

from drake_dock.docking.model.outcome import CaptureRule, misalignment
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.loads import interface_loads
from drake_dock.docking.report.out_dir import atomic_directory
from drake_dock.docking.report.results import thrust_impulses, timeseries
from drake_dock.errors import DrakeDockError, InputError
from drake_dock.studies.compliant import (CompliantConfig, build_compliant_diagram,
                                          hunt_crossley_dissipation, run_compliant)
from drake_dock.studies.conditions import (IDSS_BOX, OUTCOME_STYLE, ConditionsPlan,
                                           conditions, with_condition)

SWEEP = ConditionsPlan()          # the conditions sweep whose conditions are taken
CONDITION_KEYS = tuple(IDSS_BOX)      # the initial block's keys a condition sets


@dataclasses.dataclass
class CrosscheckPlan:
    own: bool = True               # the scenario's own initial conditions (row "scenario")
    random: int = 16               # the sweep's random conditions 1..random
    corners: int = 8               # and its corners 1..corners
    stiffness: float = 1e7         # N/m per piece (a pair of pieces: half)
    time_step: float = 5e-4        # s
    n_around: int = 12             # compliant petal cells across a petal
    n_ring: int = 144              # compliant ring sectors
    stiffness_factor: float = 4.0  # the refined run's stiffness ...
    step_factor: float = 0.5       # ... and step, relative to the run's
    window: float = 0.05           # s: the window of the peak mean interface force
    near_margin: float = 1e-3      # m: "near capture" is within it of the capture box
    target_agreement: float = 0.9
    target_capture_time: float = 0.1

    @classmethod
    def quick(cls):
        return cls(random=0, corners=0)

    @classmethod
    def full(cls):
        return cls()

    def validate(self) -> "CrosscheckPlan":
        for name, top in (("random", SWEEP.random), ("corners", SWEEP.corners)):
            v = getattr(self, name)
            if not (isinstance(v, int) and 0 <= v <= top):
                raise InputError(f"crosscheck.{name}", v,
                                 f"an integer from 0 to {top} (the conditions sweep's)")
        if not self.own and self.random + self.corners == 0:
            raise InputError("crosscheck.random", self.random,
                             ">= 1 when crosscheck.corners is 0 and crosscheck.own is false "
                             "(no condition to run)")
        for name in ("stiffness", "time_step", "window", "stiffness_factor", "near_margin"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"crosscheck.{name}", v, "> 0 and finite")
        if not (math.isfinite(self.step_factor) and 0 < self.step_factor <= 1):
            raise InputError("crosscheck.step_factor", self.step_factor, "0 < factor <= 1")
        self.compliant().validate()
        return self

    def compliant(self, dissipation: float | None = None) -> CompliantConfig:
        return CompliantConfig("point", self.stiffness, self.time_step,
                               dissipation=dissipation, n_around=self.n_around,
                               n_ring=self.n_ring, approximation="similar")


def plan_conditions(plan: CrosscheckPlan) -> list:
    """[(name, condition)]: the scenario's own ("scenario", no change) where plan.own, then
    the sweep's random 1..plan.random and its corners 1..corners."""
    sweep = dict(conditions(SWEEP))
    names = ([f"random {k}" for k in range(1, plan.random + 1)]
             + [f"corner {k}" for k in range(1, plan.corners + 1)])
    return [("scenario", {})] * plan.own + [(n, sweep[n]) for n in names]


# Forces --------------------------------------------------------------------------------------
def peak_mean_force(t, P, window: float) -> float:
    """The largest \\|P(b) - P(a)\\| / window over the windows [a, b] of length ``window``
    that start or end at a sample; P (N, 3), the contact momentum, is linear between the
    samples t (non-decreasing: a rigid impact's two samples share a time, so P(t_k) is the
    later one's value on the left of the window and the earlier one's on the right, the
    impulse inside the window either way). 0 where the run is shorter than the window."""
    t, P = np.asarray(t, float), np.asarray(P, float)
    if len(t) < 2 or t[-1] - t[0] < window:
        return 0.0

    def at(x, side):
        i = np.clip(np.searchsorted(t, x, side=side), 1, len(t) - 1)
        i0 = i - 1
        w = np.where(t[i] > t[i0], (x - t[i0]) / np.where(t[i] > t[i0], t[i] - t[i0], 1.0),
                     1.0)
        return P[i0] + np.clip(w, 0.0, 1.0)[:, None] * (P[i] - P[i0])

    ends = t[t >= t[0] + window]
    starts = t[t <= t[-1] - window]
    a = np.linalg.norm(P[np.searchsorted(t, ends, side="right") - 1]
                       - at(ends - window, "right"), axis=1)
    b = np.linalg.norm(at(starts + window, "left")
                       - P[np.searchsorted(t, starts, side="left")], axis=1)
    return float(max(a.max(initial=0.0), b.max(initial=0.0)) / window)


def approach(t, axial, lateral, tilt, rule: CaptureRule, margin: float) -> dict:
    """How the run came to the capture box, from the rings' misalignment at the samples t
    (`drake_dock.docking.model.outcome.misalignment`): ``near`` the first time the distance to
    capture (`CaptureRule.to_go`) is within ``margin`` of the capture tolerance (s, None if
    never), ``closest`` the least distance to capture less the tolerance (m, <= 0 once
    captured), and the final axial and lateral offset (m) and tilt (deg)."""
    to_go = np.array([rule.to_go(a, b, c) for a, b, c in zip(axial, lateral, tilt)])
    gap = to_go - rule.axial
    near = np.flatnonzero(gap <= margin)
    return {"near": float(t[near[0]]) if len(near) else None,
            "closest": float(gap.min()) if len(gap) else None,
            "final_axial": float(axial[-1]), "final_lateral": float(lateral[-1]),
            "final_tilt_deg": math.degrees(tilt[-1])}


def rigid_measures(result, plan: "CrosscheckPlan") -> dict:
    """The rigid run's peak interface force (N, impulses excluded), peak mean interface force
    over ``plan.window`` (N, impulses included) and `approach`."""
    ts = timeseries(result)
    F_A = interface_loads(ts, result.scene.pairs)["F_A"]
    j = ts["body_names"].tolist().index("chaser")
    J, _ = thrust_impulses(result, ts, np.zeros(3))
    P = result.scenario.bodies.chaser.mass * ts["v_WB"][:, j] - J
    names = ts["apds_names"].tolist()
    a, c = names.index("target_apds"), names.index("chaser_apds")
    mis = np.array([misalignment(ts["R_WA"][k, a], ts["p_WA"][k, a], ts["R_WA"][k, c],
                                 ts["p_WA"][k, c]) for k in range(len(ts["t"]))])
    rule = CaptureRule.of(result.scenario.simulation, result.scenario.geometry)
    return {"peak": float(np.linalg.norm(F_A, axis=1).max()) if len(F_A) else 0.0,
            "mean": peak_mean_force(ts["t"], P, plan.window),
            **approach(ts["t"], *mis.T, rule, plan.near_margin)}


def compliant_measures(run, scenario, plan: "CrosscheckPlan") -> dict:
    """The same of a `CompliantRun`: its chaser's momentum less the thrust's impulse."""
    if run.chaser_velocities is None or len(run.t) < 2:
        return {"peak": 0.0, "mean": 0.0}
    J = np.vstack([np.zeros(3), np.cumsum(run.thrust_force * np.diff(run.t)[:, None], axis=0)])
    P = scenario.bodies.chaser.mass * run.chaser_velocities - J
    rule = CaptureRule.of(scenario.simulation, scenario.geometry)
    return {"peak": run.peak_interface_force, "mean": peak_mean_force(run.t, P, plan.window),
            **approach(run.t, run.ring_distance, run.lateral, run.tilt, rule,
                       plan.near_margin)}


# One condition -------------------------------------------------------------------------------
def counts_as_converged(outcome: str, refined_outcome: str) -> bool:
    """A compliant run counts where its refined run ends with the same named outcome (neither
    ended by an error)."""
    return outcome == refined_outcome and outcome != "error"


def relative_difference(t_rigid, t_compliant) -> float | None:
    """(t_compliant - t_rigid) / t_rigid, None unless both are captured (times given)."""
    if t_rigid is None or t_compliant is None:
        return None
    return (t_compliant - t_rigid) / t_rigid


MEASURE_COLUMNS = {"peak": "peak_interface_force_N", "mean": "peak_mean_interface_force_N",
                   "near": "near_capture_time_s", "closest": "closest_to_capture_m",
                   "final_axial": "final_axial_m", "final_lateral": "final_lateral_m",
                   "final_tilt_deg": "final_tilt_deg"}


def _measure_columns(prefix, measures) -> dict:
    return {f"{prefix}_{MEASURE_COLUMNS[k]}": v for k, v in measures.items()}


def run_condition(scenario, name: str, condition: dict, plan: CrosscheckPlan) -> dict:
    """One row: the condition, the rigid run, the compliant run and its refined run."""
    s = with_condition(scenario, condition)
    row = {"name": name}
    for k in CONDITION_KEYS:
        v = getattr(s.initial, k)
        row[k] = json.dumps(list(v)) if isinstance(v, (list, tuple)) else v
    try:
        state = place(s)
    except DrakeDockError as e:
        row.update(rigid_outcome="error", rigid_reason=f"{type(e).__name__}: {e}",
                   compliant_outcome="error", compliant_reason="no initial state",
                   refined_outcome="error", counts=False)
        return row
    w0 = _time.perf_counter()
    try:
        r = simulate(s, state=state)
        row.update(rigid_outcome=r.outcome, rigid_reason=r.reason,
                   rigid_capture_time_s=r.capture_time, rigid_end_time_s=r.end_time,
                   rigid_impacts=len(r.impacts),
                   **_measure_columns("rigid", rigid_measures(r, plan)))
    except DrakeDockError as e:
        row.update(rigid_outcome="error", rigid_reason=f"{type(e).__name__}: {e}")
    row["rigid_wall_time_s"] = _time.perf_counter() - w0
    cfg = plan.compliant(hunt_crossley_dissipation(s.contact.restitution,
                                                   s.initial.chaser_speed))
    for prefix, c in (("compliant", cfg), ("refined", cfg.refined(plan.stiffness_factor,
                                                                    plan.step_factor))):
        w0 = _time.perf_counter()
        run = run_compliant(s, state, c, t_max=s.simulation.duration,
                            cd=build_compliant_diagram(s, c))
        row.update({f"{prefix}_outcome": run.outcome, f"{prefix}_reason": run.reason,
                    f"{prefix}_capture_time_s": run.capture_time,
                    f"{prefix}_end_time_s": float(run.t[-1]) if len(run.t) else 0.0,
                    f"{prefix}_first_contact_s": (run.first_contact_time if math.isfinite(
                        run.first_contact_time) else None),
                    **_measure_columns(prefix, compliant_measures(run, s, plan)),
                    f"{prefix}_wall_time_s": _time.perf_counter() - w0})
    row["counts"] = counts_as_converged(row["compliant_outcome"], row["refined_outcome"])
    row["agree"] = row["rigid_outcome"] == row["compliant_outcome"]
    row["capture_time_difference"] = relative_difference(row.get("rigid_capture_time_s"),
                                                         row.get("compliant_capture_time_s"))
    row["near_capture_time_difference"] = relative_difference(
        row.get("rigid_near_capture_time_s"), row.get("compliant_near_capture_time_s"))
    return row


def _fmt_run(row, prefix) -> str:
    out = row.get(f"{prefix}_outcome", "-")
    tc = row.get(f"{prefix}_capture_time_s")
    return f"{out}" + (f" {tc:.4g} s" if tc is not None else "")


def run_crosscheck(scenario, plan: CrosscheckPlan, log=print) -> dict:
    plan.validate()
    todo = plan_conditions(plan)
    rows = []
    for k, (name, cond) in enumerate(todo, 1):
        row = run_condition(scenario, name, cond, plan)
        rows.append(row)
        log(f"[{k}/{len(todo)}] {name}: rigid {_fmt_run(row, 'rigid')}, compliant "
            f"{_fmt_run(row, 'compliant')} (refined {_fmt_run(row, 'refined')}: "
            f"{'counts' if row['counts'] else 'does not count'})")
    return {"plan": dataclasses.asdict(plan), "rows": rows}


# Summary and outputs -------------------------------------------------------------------------
def agreement(rows) -> tuple[int, int]:
    """(K, M): the conditions whose compliant run counts (M) and among them those whose
    outcomes agree (K)."""
    counted = [r for r in rows if r.get("counts")]
    return sum(bool(r["agree"]) for r in counted), len(counted)


def capture_time_differences(rows) -> list:
    """The relative capture-time differences of the conditions captured by both whose
    compliant run counts."""
    return [r["capture_time_difference"] for r in rows
            if r.get("counts") and r.get("capture_time_difference") is not None]


def summary_lines(result) -> list:
    rows = result["rows"]
    plan = result["plan"]
    K, M = agreement(rows)
    diffs = capture_time_differences(rows)
    lines = [f"outcome agreement: {K}/{M}" + (f" ({K / M:.0%}; target "
                                              f"{plan['target_agreement']:.0%})" if M else "")]
    if diffs:
        a = np.abs(diffs)
        lines.append(f"median capture-time difference: {100 * np.median(a):.3g} % "
                     f"({len(a)} conditions captured by both; largest {100 * a.max():.3g} %, "
                     f"{int(np.sum(a <= plan['target_capture_time']))} within "
                     f"{100 * plan['target_capture_time']:g} %; signed median "
                     f"{100 * np.median(diffs):+.3g} %, compliant minus rigid)")
    else:
        lines.append("median capture-time difference: none (no condition captured by both "
                     "with a compliant run that counts)")
    near = [r["near_capture_time_difference"] for r in rows
            if r.get("counts") and r.get("near_capture_time_difference") is not None]
    if near:
        a = np.abs(near)
        lines.append(f"median near-capture-time difference: {100 * np.median(a):.3g} % (the "
                     f"first time within {1e3 * plan['near_margin']:g} mm of the capture box; "
                     f"{len(a)} conditions where both come near; largest {100 * a.max():.3g} %)")
    lines.append(f"compliant runs that count: {M}/{len(rows)} (the refined run, stiffness "
                 f"x{plan['stiffness_factor']:g} and step x{plan['step_factor']:g}, ends with "
                 f"the same outcome)")
    for r in rows:
        if r.get("counts") and not r["agree"]:
            lines.append(f"disagreement: {r['name']}: rigid {_fmt_run(r, 'rigid')}, compliant "
                         f"{_fmt_run(r, 'compliant')}")
        elif not r.get("counts"):
            lines.append(f"not counted: {r['name']}: compliant {_fmt_run(r, 'compliant')}, "
                         f"refined {_fmt_run(r, 'refined')} (rigid {_fmt_run(r, 'rigid')})")
    for who in ("rigid", "compliant", "refined"):
        walls = [r[f"{who}_wall_time_s"] for r in rows if f"{who}_wall_time_s" in r]
        if walls:
            lines.append(f"wall time {who}: median {np.median(walls):.3g} s per run, total "
                         f"{sum(walls):.4g} s")
    return lines


FIELDS = ("name", "chaser_speed", "lateral_offset", "lateral_velocity", "tilt_deg",
          "target_yaw_deg", "angular_velocity_deg_s",
          "rigid_outcome", "compliant_outcome", "refined_outcome", "counts", "agree",
          "rigid_capture_time_s", "compliant_capture_time_s", "refined_capture_time_s",
          "capture_time_difference",
          "rigid_peak_interface_force_N", "compliant_peak_interface_force_N",
          "refined_peak_interface_force_N",
          "rigid_peak_mean_interface_force_N", "compliant_peak_mean_interface_force_N",
          "refined_peak_mean_interface_force_N",
          "rigid_near_capture_time_s", "compliant_near_capture_time_s",
          "refined_near_capture_time_s", "near_capture_time_difference",
          "rigid_closest_to_capture_m", "compliant_closest_to_capture_m",
          "refined_closest_to_capture_m",
          "rigid_final_axial_m", "compliant_final_axial_m", "refined_final_axial_m",
          "rigid_final_lateral_m", "compliant_final_lateral_m", "refined_final_lateral_m",
          "rigid_final_tilt_deg", "compliant_final_tilt_deg", "refined_final_tilt_deg",
          "rigid_end_time_s", "compliant_end_time_s", "refined_end_time_s",
          "rigid_impacts", "compliant_first_contact_s", "refined_first_contact_s",
          "rigid_wall_time_s", "compliant_wall_time_s", "refined_wall_time_s",
          "rigid_reason", "compliant_reason", "refined_reason")


def rows_csv(rows) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, FIELDS, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if r.get(k) is None else r.get(k, "")) for k in FIELDS})
    return buf.getvalue()


def crosscheck_figure(rows, path, target: float = 0.1):
    """Left: capture time, compliant against rigid, for the conditions captured by both (the
    +-target band shaded; hollow where the compliant run does not count). Right: the outcome
    pairs, rigid (rows) against compliant (columns), counted conditions only."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11.0, 4.8), layout="constrained")
    both = [r for r in rows if r.get("rigid_capture_time_s") is not None
            and r.get("compliant_capture_time_s") is not None]
    tmax = max([r["rigid_capture_time_s"] for r in both]
               + [r["compliant_capture_time_s"] for r in both] + [1.0]) * 1.08
    x = np.array([0.0, tmax])
    ax.fill_between(x, (1 - target) * x, (1 + target) * x, color="0.9",
                    label=f"within {100 * target:g} %")
    ax.plot(x, x, color="0.5", lw=0.8)
    for kind, (marker, color) in (("scenario", ("*", "tab:purple")),
                                  ("random", ("o", "tab:green")),
                                  ("corner", ("D", "tab:blue"))):
        for counted in (True, False):
            sel = [r for r in both if r["name"].startswith(kind) and r["counts"] == counted]
            if sel:
                ax.scatter([r["rigid_capture_time_s"] for r in sel],
                           [r["compliant_capture_time_s"] for r in sel], marker=marker,
                           facecolors=color if counted else "none", edgecolors=color,
                           label=f"{kind}{'' if counted else ' (does not count)'} "
                                 f"({len(sel)})")
    for r in both:
        if abs(r["capture_time_difference"]) > target:
            ax.annotate(r["name"], (r["rigid_capture_time_s"], r["compliant_capture_time_s"]),
                        fontsize=7, xytext=(4, -8), textcoords="offset points")
    ax.set_xlim(0, tmax)
    ax.set_ylim(0, tmax)
    ax.set_xlabel("capture time, drake_dock rigid [s]")
    ax.set_ylabel("capture time, Drake compliant [s]")
    ax.set_title("Conditions captured by both")
    ax.legend(loc="upper left", fontsize=8)
    outcomes = list(OUTCOME_STYLE)
    counted = [r for r in rows if r.get("counts")]
    M = np.zeros((len(outcomes), len(outcomes)), int)
    for r in counted:
        M[outcomes.index(r["rigid_outcome"]), outcomes.index(r["compliant_outcome"])] += 1
    bx.imshow(M, cmap="Greens", vmin=0, vmax=max(int(M.max()), 1))
    for i in range(len(outcomes)):
        for j in range(len(outcomes)):
            if M[i, j]:
                dark = M[i, j] > 0.5 * M.max()
                bx.text(j, i, str(M[i, j]), ha="center", va="center", fontsize=11,
                        color=("w" if dark else "k") if i == j else "tab:red")
    bx.set_xticks(range(len(outcomes)), outcomes, rotation=30)
    bx.set_yticks(range(len(outcomes)), outcomes)
    bx.set_xlabel("Drake compliant")
    bx.set_ylabel("drake_dock rigid")
    K, n = agreement(rows)
    bx.set_title(f"Outcomes of the counted conditions: {K}/{n} agree")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write_crosscheck(result, out_dir):
    """crosscheck.csv, crosscheck.png and summary.json into out_dir, all at once."""
    rows = result["rows"]
    K, M = agreement(rows)
    diffs = capture_time_differences(rows)
    with atomic_directory(out_dir, kind="study crosscheck") as tmp:
        (tmp / "crosscheck.csv").write_text(rows_csv(rows))
        crosscheck_figure(rows, tmp / "crosscheck.png", result["plan"]["target_capture_time"])
        (tmp / "summary.json").write_text(json.dumps(
            {"plan": result["plan"], "agreement": {"agree": K, "counted": M,
                                                   "conditions": len(rows)},
             "median_capture_time_difference": (float(np.median(np.abs(diffs)))
                                                if diffs else None),
             "lines": summary_lines(result), "rows": rows}, indent=2, default=_json) + "\n")


def _json(x):
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, np.bool_):
        return bool(x)
    raise TypeError(type(x).__name__)
