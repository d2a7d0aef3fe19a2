"""The speed-accuracy study (`drake-dock study speed-accuracy`): drake_dock's rigid model at
several accuracies against Drake's compliant contact (`studies/compliant.py`) on the same scene.

Metrics (all at capture, the axial ring-centre distance reaching ``capture_distance``):

- ``capture_time`` [s];
- ``apds_spin_rate``: the target APDS's angular velocity about the docking axis (the target
  APDS's e3 at t = 0) [rad/s];
- ``chaser_axial_velocity``: the chaser's velocity along that axis [m/s];
- ``peak_contact_force``: the peak magnitude of the net contact force on the chaser over the
  sliding phase, taken as the window [t_c / 2, t_c] (the example's impacts end before
  0.06 s, capture is at 0.155 s): an impulsive rigid impact has no peak force to compare with.
  Rigid: from the couples' lambda_n, lambda_t and frames at the samples; compliant: the
  chaser's momentum change over each step (its only force is contact).

The reference is drake_dock at ``reference_accuracy``; its self-convergence is shown by the run
at 10x that accuracy, whose difference from the reference is reported per metric. Each point's
error is |m - m_ref| / |m_ref|. Wall time covers Simulator.Initialize + AdvanceTo (build and the
shared initial state excluded), for both models, all measured in this run.

The speed-up for a metric is the fastest compliant configuration whose error is within
``tolerance`` divided by the fastest drake_dock run within it. When no compliant configuration
reaches the tolerance the line says so and gives the best compliant error reached.

A run that is within the tolerance by chance counts there. So the study also gives the
*converged* speed-up, the usual reading of a work-precision chart: a run counts only if every
finer run of its family is within the tolerance too. A family is one method with fixed model
and stiffness, ordered by step (SAP) or by accuracy (continuous RK3, and drake_dock at one step
cap). And it gives each metric's *contact effect*, its change from t = 0 to capture relative to
its value at capture: a tolerance that is a large share of it does not tell contact models
apart (a run without contact would come close).
"""
import copy
import csv
import dataclasses
import io
import math
from pathlib import Path

import numpy as np

from drake_dock.studies.compliant import (CompliantConfig, build_compliant_diagram,
                                          hunt_crossley_dissipation, run_compliant)
from drake_dock.docking.results import rigid_chaser_force
from drake_dock.docking.simulate import simulate
from drake_dock.docking.scene import initial_state
from drake_dock.errors import DrakeDockError

METRICS = ("capture_time", "apds_spin_rate", "chaser_axial_velocity", "peak_contact_force")


@dataclasses.dataclass
class StudyPlan:
    rigid_accuracies: tuple
    reference_accuracy: float
    compliant: list                  # CompliantConfig (dissipation filled in by the study)
    tolerance: float = 1e-3
    wall_limit: float = 120.0        # per compliant run: stopped beyond it (reported)
    t_max_factor: float = 2.0        # compliant runs end at this x the reference capture time
    # drake_dock's step cap is the output spacing (scenario.simulator_config.max_step_size);
    # each accuracy is also run with these caps (error control then sets the steps; the
    # samples are sparser)
    rigid_max_steps: tuple = ()

    @staticmethod
    def quick():
        c = [CompliantConfig("point", 1e7, h) for h in (1e-3, 1e-4)]
        c += [CompliantConfig("hydroelastic", 1e8, 1e-3)]
        return StudyPlan((1e-3, 1e-6), 1e-8, c, wall_limit=60.0)

    @staticmethod
    def full():
        c = []
        for model, ks in (("hydroelastic", (1e7, 1e8, 1e9)), ("point", (1e6, 1e7, 1e8))):
            for k in ks:
                c += [CompliantConfig(model, k, h)
                      for h in (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5)]
        c += [CompliantConfig("point", 1e7, 0.0, accuracy=a) for a in (1e-2, 1e-3)]
        c += [CompliantConfig("hydroelastic", 1e8, 0.0, accuracy=1e-2)]
        return StudyPlan((1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8), 1e-10, c, wall_limit=90.0,
                         rigid_max_steps=(0.01, 0.02))


def rigid_metrics(result, e3) -> dict:
    """The four metrics of a drake_dock `RunResult` (module docstring)."""
    if not result.captured:
        return {m: None for m in METRICS}
    rec = result.record
    plant = result.dd.dp.plant
    pc = plant.CreateDefaultContext()
    plant.SetPositionsAndVelocities(pc, rec.x[-1])
    b = result.dd.dp.bodies
    v_c = plant.EvalBodySpatialVelocityInWorld(pc, b["chaser"]).translational()
    w_a = plant.EvalBodySpatialVelocityInWorld(pc, b["target_apds"]).rotational()
    t, F = rigid_chaser_force(result)
    t_c = result.capture_time
    # The window's start falls between samples: the force there is interpolated linearly
    # (a sample-dependent start would make the peak depend on the step sequence).
    Fn = np.linalg.norm(F, axis=1)
    keep = np.r_[np.diff(t) > 0, True]            # pre-impact samples share a time
    start = float(np.interp(0.5 * t_c, t[keep], Fn[keep]))
    win = (t >= 0.5 * t_c) & (t <= t_c)
    return {"capture_time": t_c, "apds_spin_rate": float(w_a @ e3),
            "chaser_axial_velocity": float(v_c @ e3),
            "peak_contact_force": max(start, float(Fn[win].max()))}


def _errors(m, ref):
    return {k: (abs(m[k] - ref[k]) / abs(ref[k]) if m.get(k) is not None else None)
            for k in METRICS}


@dataclasses.dataclass
class Point:
    method: str          # "drake_dock" | "compliant"
    role: str            # "reference" | "self-convergence" | "point"
    label: str
    model: str
    stiffness: float
    step: float          # compliant time step (0 = continuous), or drake_dock's step cap
    accuracy: float      # drake_dock or continuous compliant accuracy, or NaN
    wall_time: float
    captured: bool
    metrics: dict
    errors: dict
    note: str = ""


def run_study(scenario, plan: StudyPlan, log=print) -> dict:
    """Runs the plan; returns {"points": [Point], "reference": metrics, "speedups": {...}}."""
    state = initial_state(scenario)
    e3 = state.X_WB["target_apds"][0][:, 2].copy()

    def rigid(acc, max_step=None):
        sc = copy.deepcopy(scenario)
        sc.simulator_config.accuracy = acc
        if max_step is not None:
            sc.simulator_config.max_step_size = max_step
        try:
            r = simulate(sc, state=state)
        except DrakeDockError as exc:
            return None, str(exc).splitlines()[0], math.nan
        return rigid_metrics(r, e3), "" if r.captured else "no capture", r.wall_time

    log(f"reference: drake_dock at accuracy {plan.reference_accuracy:g}")
    ref, note, wall = rigid(plan.reference_accuracy)
    if ref is None or ref["capture_time"] is None:
        raise DrakeDockError(f"the reference run failed: {note or 'no capture'}")
    cap = scenario.simulator_config.max_step_size
    points = [Point("drake_dock", "reference", f"drake_dock acc={plan.reference_accuracy:.0e}",
                    "rigid", math.nan, cap, plan.reference_accuracy, wall, True, ref,
                    _errors(ref, ref))]
    runs = [(10 * plan.reference_accuracy, None)] + [(a, None) for a in plan.rigid_accuracies]
    runs += [(a, h) for h in plan.rigid_max_steps for a in plan.rigid_accuracies]
    for i, (acc, h) in enumerate(runs):
        m, note, wall = rigid(acc, h)
        m = m or {k: None for k in METRICS}
        role = "self-convergence" if i == 0 else "point"
        label = f"drake_dock acc={acc:.0e}" + (f" step<={h:g}" if h is not None else "")
        p = Point("drake_dock", role, label, "rigid", math.nan, cap if h is None else h,
                  acc, wall, m["capture_time"] is not None, m, _errors(m, ref), note)
        points.append(p)
        log(_fmt(p))
    # Hunt-Crossley dissipation matched to the restitution at the first impact's approach
    # speed (the chaser's speed along the couples' normal is unknown before the run: the
    # approach speed along the axis is used).
    d_hc = hunt_crossley_dissipation(scenario.contact.restitution,
                                     scenario.initial.chaser_speed)
    t_max = plan.t_max_factor * ref["capture_time"]
    for cfg in plan.compliant:
        cfg = dataclasses.replace(cfg, dissipation=d_hc if cfg.dissipation is None
                                  else cfg.dissipation)
        cd = build_compliant_diagram(scenario, cfg)
        r = run_compliant(scenario, state, cfg, t_max=t_max, cd=cd, wall_limit=plan.wall_limit)
        m = {"capture_time": r.capture_time, "apds_spin_rate": r.apds_spin_rate,
             "chaser_axial_velocity": r.chaser_axial_velocity,
             "peak_contact_force": r.peak_force}
        note = r.error or ("" if r.captured else "no capture by "
                           f"{r.t[-1]:.3f} s" + (" (wall limit)" if r.stopped else ""))
        p = Point("compliant", "point", cfg.label(), cfg.model, cfg.stiffness, cfg.time_step,
                  cfg.accuracy if cfg.time_step == 0 else math.nan, r.wall_time, r.captured,
                  m, _errors(m, ref), note)
        points.append(p)
        log(_fmt(p))
    # Contact effect: the metric's change from t = 0 to capture, relative to its capture value.
    w0 = np.asarray(state.V_WB["target_apds"][0]) @ e3
    v0 = np.asarray(state.V_WB["chaser"][1]) @ e3
    effect = {"apds_spin_rate": abs(ref["apds_spin_rate"] - w0) / abs(ref["apds_spin_rate"]),
              "chaser_axial_velocity": abs(ref["chaser_axial_velocity"] - v0)
              / abs(ref["chaser_axial_velocity"])}
    return {"points": points, "reference": ref,
            "speedups": speedups(points, plan.tolerance), "tolerance": plan.tolerance,
            "dissipation": d_hc, "contact_effect": effect}


def _fmt(p: Point) -> str:
    errs = " ".join(f"{k}={p.errors[k]:.1e}" if p.errors[k] is not None else f"{k}=-"
                    for k in METRICS)
    return f"  {p.label:<40s} wall {p.wall_time:8.3f} s  {errs} {p.note}"


def speedups(points, tol) -> dict:
    """{metric: (ratio or None, t_dd, t_compliant, best compliant error)}."""
    out = {}
    for k in METRICS:
        dd = [p.wall_time for p in points if p.method == "drake_dock" and p.role == "point"
              and p.errors[k] is not None and p.errors[k] <= tol]
        cc = [p.wall_time for p in points if p.method == "compliant"
              and p.errors[k] is not None and p.errors[k] <= tol]
        best = min((p.errors[k] for p in points if p.method == "compliant"
                    and p.errors[k] is not None), default=None)
        t_dd = min(dd) if dd else None
        t_cc = min(cc) if cc else None
        out[k] = (t_cc / t_dd if (t_dd and t_cc) else None, t_dd, t_cc, best)
    return out


def _family(p: Point):
    """(family key, fineness): runs of one method, model and stiffness (and drake_dock's step
    cap), ordered so that a larger fineness is a finer run."""
    if p.method == "drake_dock":
        return ("drake_dock", p.step), -math.log10(p.accuracy)
    if p.step > 0:
        return ("compliant", p.model, p.stiffness, "SAP"), -math.log10(p.step)
    return ("compliant", p.model, p.stiffness, "RK3"), -math.log10(p.accuracy)


def converged_points(points, k, tol) -> list:
    """The points (reference excluded) within ``tol`` on metric ``k`` whose finer runs of the
    same family are all within it too (a run that does not capture is not)."""
    pts = [p for p in points if p.role == "point"]
    fam = {}
    for p in pts:
        key, fine = _family(p)
        fam.setdefault(key, []).append((fine, p))

    def ok(p):
        return p.errors[k] is not None and p.errors[k] <= tol
    out = []
    for p in pts:
        key, fine = _family(p)
        if ok(p) and all(ok(q) for f, q in fam[key] if f > fine):
            out.append(p)
    return out


def converged_speedups(points, tol) -> dict:
    """{metric: (ratio or None, t_dd, t_compliant)} over `converged_points`."""
    out = {}
    for k in METRICS:
        conv = converged_points(points, k, tol)
        dd = [p.wall_time for p in conv if p.method == "drake_dock"]
        cc = [p.wall_time for p in conv if p.method == "compliant"]
        t_dd = min(dd) if dd else None
        t_cc = min(cc) if cc else None
        out[k] = (t_cc / t_dd if (t_dd and t_cc) else None, t_dd, t_cc)
    return out


def speedup_lines(result) -> list:
    tol = result["tolerance"]
    lines = []
    for k, (ratio, t_dd, t_cc, best) in result["speedups"].items():
        if ratio is not None:
            lines.append(f"speed-up {k}: {ratio:.3g}x (drake_dock {t_dd:.3f} s, compliant "
                         f"{t_cc:.3f} s, both within {tol:g})")
        elif t_dd is None:
            lines.append(f"speed-up {k}: none (no drake_dock run within {tol:g})")
        else:
            b = "none captured" if best is None else f"best compliant error {best:.1e}"
            lines.append(f"speed-up {k}: unbounded (no compliant configuration within {tol:g}; "
                         f"{b}; drake_dock {t_dd:.3f} s)")
    lines.append("converged (every finer run of the same family also within the tolerance):")
    for k, (ratio, t_dd, t_cc) in converged_speedups(result["points"], tol).items():
        if ratio is not None:
            lines.append(f"  {k}: {ratio:.3g}x (drake_dock {t_dd:.3f} s, compliant {t_cc:.3f} s)")
        elif t_dd is None:
            lines.append(f"  {k}: none (no converged drake_dock run)")
        else:
            lines.append(f"  {k}: unbounded (no converged compliant run; drake_dock {t_dd:.3f} s)")
    for k, eff in result.get("contact_effect", {}).items():
        lines.append(f"contact effect on {k}: {eff:.3g} (the tolerance is {tol / eff:.3g} of it)")
    return lines


CSV_FIELDS = ("method", "role", "label", "model", "stiffness", "step", "accuracy", "wall_time",
              "captured", *METRICS, *(f"error_{k}" for k in METRICS), "note")


def points_csv(points) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_FIELDS)
    for p in points:
        w.writerow([p.method, p.role, p.label, p.model, f"{p.stiffness:.6g}", f"{p.step:.6g}",
                    f"{p.accuracy:.6g}", f"{p.wall_time:.6f}", int(p.captured),
                    *("" if p.metrics[k] is None else repr(p.metrics[k]) for k in METRICS),
                    *("" if p.errors[k] is None else f"{p.errors[k]:.6e}" for k in METRICS),
                    p.note])
    return buf.getvalue()


def work_precision_figure(result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pts = result["points"]
    tol = result["tolerance"]
    fig, axs = plt.subplots(2, 2, figsize=(11, 8.5))
    floor = 1e-16

    def group(p):
        if p.method == "drake_dock":
            return f"drake_dock (rigid, LZB), step <= {p.step:g} s"
        if p.step > 0:
            return f"SAP {p.model} k={p.stiffness:.0e}"
        return f"continuous RK3 {p.model} k={p.stiffness:.0e}"
    # One colour per compliant family in every panel.
    fams = list(dict.fromkeys(group(p) for p in pts if p.method == "compliant"))
    colour = {g: plt.cm.tab10(i % 10) for i, g in enumerate(fams)}
    for ax, k in zip(axs.ravel(), METRICS):
        conv = {id(p) for p in converged_points(pts, k, tol)}
        groups = {}
        for p in pts:
            if p.role == "reference" or p.errors[k] is None:
                continue
            groups.setdefault(group(p), []).append(
                (p.wall_time, max(p.errors[k], floor), p.role != "point" or id(p) in conv))
        for key, xyc in groups.items():
            xyc.sort()
            x, y, c = zip(*xyc)
            if key.startswith("drake_dock"):
                # The finest step cap solid black, coarser caps dashed in lighter greys.
                dd = sorted((g for g in groups if g.startswith("drake_dock")),
                            key=lambda g: float(g.split("<= ")[1].split()[0]))
                rank = dd.index(key)
                style = dict(lw=2.2, marker="o", color=("k", "0.4", "0.65", "0.8")[min(rank, 3)],
                             ls="--" if rank else "-")
            else:
                style = dict(lw=1, marker="s" if "SAP" in key else "^", ms=4,
                             color=colour[key])
            line, = ax.loglog(x, y, label=key, **style)
            # Runs within the tolerance by chance (a finer run of the family is not): hollow.
            lucky = [(xi, yi) for xi, yi, ci in zip(x, y, c) if yi <= tol and not ci]
            if lucky:
                ax.loglog(*zip(*lucky), ls="none", marker=style["marker"], ms=9, mfc="w",
                          mec=line.get_color(), mew=1.5)
        ax.axhline(tol, color="r", ls="--", lw=0.8)
        ax.set_title(k.replace("_", " "))
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("relative error vs reference")
    axs[0, 0].legend(fontsize=7)
    fig.suptitle(f"Work-precision: error against wall time (red: tolerance {tol:g}; hollow: "
                 "within it by chance, a finer run of the same family is not)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def write_study(result, out_dir):
    """chart, CSV and the printed lines, atomically."""
    from drake_dock.docking.output import atomic_directory
    with atomic_directory(out_dir, kind="study speed-accuracy") as tmp:
        (tmp / "points.csv").write_text(points_csv(result["points"]))
        work_precision_figure(result, tmp / "work_precision.png")
        (tmp / "speedups.txt").write_text("\n".join(speedup_lines(result)) + "\n")
    return Path(out_dir)
