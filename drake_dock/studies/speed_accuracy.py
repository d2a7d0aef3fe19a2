"""The speed-accuracy study (`drake-dock study speed-accuracy`): drake_dock's rigid model at
several accuracies against Drake's compliant contact (`studies/compliant.py`), on two scenes:

- ``paper_example``: the example of Sect. 8.2 (models/paper_example.yaml);
- ``idss_slow_roll``: the same spacecraft in the International Docking System Standard's
  initial-contact box, closing at 0.1 m/s with a 4 deg roll, coaxial (`OFF_NOMINAL`). Off the
  axis, the runs reach contacts the paper's 12 pairs lack (docs/results.md, "Working
  conditions"): the two models would differ in what touches, not in accuracy.

Metrics and their errors: `drake_dock.studies.docking_metrics` (each error relative to the
contact's effect on the metric). The reference is drake_dock at ``reference_accuracy``; its
self-convergence is shown by the run at 10x that accuracy, whose error is reported per metric.
Wall time covers Simulator.Initialize + AdvanceTo (build and the shared initial state
excluded), for both models, all measured in the same run of the study.

drake_dock runs with the scenario's integration scheme and with ``rigid_schemes`` (by
default Bogacki-Shampine beside the default RK5), one family per scheme and step cap.

The headline is the converged speed-up per metric and scene (`drake_dock.studies.work_precision`):
the fastest compliant configuration converged within ``tolerance`` over the fastest converged
drake_dock run. Where no compliant run is converged the line says so and gives the best
compliant error reached.
"""
import copy
import dataclasses
import math
from pathlib import Path

from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.errors import DrakeDockError
from drake_dock.studies.compliant import (CompliantConfig, build_compliant_diagram,
                                          hunt_crossley_dissipation, run_compliant)
from drake_dock.studies.conditions import with_condition
from drake_dock.studies.docking_metrics import (METRICS, UNITS, compliant_metrics,
                                                contact_effect, errors, rigid_metrics,
                                                scene_start)
from drake_dock.studies.work_precision import (SCHEME_NAMES, Point, any_run_speedups,
                                               converged_speedups, points_csv,
                                               work_precision_figure)

OFF_NOMINAL = {"chaser_speed": 0.1, "target_yaw_deg": 4.0}


def study_scenes(path=None) -> list:
    """[(name, scenario)]: the scenario file's alone (named after the file), or by default the
    paper example and the off-nominal condition."""
    if path is not None:
        return [(Path(path).stem, load_scenario(path))]
    paper = load_scenario(PAPER_EXAMPLE)
    return [("paper_example", paper), ("idss_slow_roll", with_condition(paper, OFF_NOMINAL))]


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
    # drake_dock's runs are repeated with these integration schemes besides the scenario's
    # (one family each; the reference keeps the scenario's)
    rigid_schemes: tuple = ("bogacki_shampine3",)

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



def _rigid_run(scenario, state, start, acc, max_step=None, scheme=None):
    """(metrics, note, wall time) of drake_dock at accuracy ``acc`` (and step cap, and
    integration scheme)."""
    sc = copy.deepcopy(scenario)
    sc.simulator_config.accuracy = acc
    if scheme is not None:
        sc.simulator_config.integration_scheme = scheme
    if max_step is not None:
        sc.simulator_config.max_step_size = max_step
    try:
        r = simulate(sc, state=state)
    except DrakeDockError as exc:
        return dict.fromkeys(METRICS), str(exc).splitlines()[0], math.nan
    return rigid_metrics(r, start), "" if r.captured else "no capture", r.wall_time


def run_scene(name, scenario, plan: StudyPlan, log=print) -> dict:
    """One scene's runs: {"scene", "points", "reference", "effect", "dissipation"}."""
    state = place(scenario)
    start = scene_start(scenario, state)
    log(f"{name}: reference drake_dock at accuracy {plan.reference_accuracy:g}")
    ref, note, wall = _rigid_run(scenario, state, start, plan.reference_accuracy)
    if ref["capture_time"] is None:
        raise DrakeDockError(f"{name}: the reference run failed: {note}")
    effect = contact_effect(ref, start)
    cap = scenario.simulator_config.max_step_size
    own = scenario.simulator_config.integration_scheme
    points = [Point("drake_dock", "reference", f"drake_dock {SCHEME_NAMES.get(own, own)} "
                    f"acc={plan.reference_accuracy:.0e}", "rigid", math.nan, cap,
                    plan.reference_accuracy, wall, True, ref, errors(ref, ref, effect),
                    scene=name, scheme=own)]
    runs = [(own, 10 * plan.reference_accuracy, None)]
    for scheme in dict.fromkeys((own, *plan.rigid_schemes)):
        runs += [(scheme, a, None) for a in plan.rigid_accuracies]
        runs += [(scheme, a, h) for h in plan.rigid_max_steps for a in plan.rigid_accuracies]
    for i, (scheme, acc, h) in enumerate(runs):
        m, note, wall = _rigid_run(scenario, state, start, acc, h, scheme)
        label = (f"drake_dock {SCHEME_NAMES.get(scheme, scheme)} acc={acc:.0e}"
                 + (f" step<={h:g}" if h is not None else ""))
        points.append(Point("drake_dock", "self-convergence" if i == 0 else "point", label,
                            "rigid", math.nan, cap if h is None else h, acc, wall,
                            m["capture_time"] is not None, m, errors(m, ref, effect), note,
                            name, scheme))
        log(_fmt(points[-1]))
    # Hunt-Crossley dissipation matched to the restitution at the first impact's approach
    # speed (the chaser's speed along the couples' normal is unknown before the run: the
    # approach speed along the axis is used).
    d_hc = hunt_crossley_dissipation(scenario.contact.restitution,
                                     scenario.initial.chaser_speed)
    for cfg in plan.compliant:
        cfg = dataclasses.replace(cfg, dissipation=d_hc if cfg.dissipation is None
                                  else cfg.dissipation)
        cd = build_compliant_diagram(scenario, cfg)
        r = run_compliant(scenario, state, cfg, t_max=plan.t_max_factor * ref["capture_time"],
                          cd=cd, wall_limit=plan.wall_limit)
        m = compliant_metrics(r, start)
        note = r.error or ("" if r.captured else "no capture by "
                           f"{r.t[-1]:.3f} s" + (" (wall limit)" if r.stopped else ""))
        points.append(Point("compliant", "point", cfg.label(), cfg.model, cfg.stiffness,
                            cfg.time_step, cfg.accuracy if cfg.time_step == 0 else math.nan,
                            r.wall_time, r.captured, m, errors(m, ref, effect), note, name))
        log(_fmt(points[-1]))
    return {"scene": name, "points": points, "reference": ref, "effect": effect,
            "dissipation": d_hc}


def run_study(scenes, plan: StudyPlan, log=print) -> dict:
    """Runs the plan on each (name, scenario) of ``scenes``."""
    return {"scenes": [run_scene(n, s, plan, log) for n, s in scenes],
            "tolerance": plan.tolerance}


def _fmt(p: Point) -> str:
    errs = " ".join(f"{k}={p.errors[k]:.1e}" if p.errors[k] is not None else f"{k}=-"
                    for k in METRICS)
    return f"  {p.label:<40s} wall {p.wall_time:8.3f} s  {errs} {p.note}"


def _runs(r) -> str:
    return (f"{r.drake_dock.label} {r.drake_dock.wall_time:.3f} s; "
            f"compliant {r.compliant.label} {r.compliant.wall_time:.3f} s")


def _line(prefix, k, r) -> str:
    if r.ratio is not None:
        return f"{prefix}{k}: {r.ratio:.3g}x ({_runs(r)})"
    if r.drake_dock is None:
        return f"{prefix}{k}: none: no converged drake_dock run"
    best = ("no compliant run captured" if r.best is None
            else f"best compliant error {r.best:.1e}")
    return (f"{prefix}{k}: none: no converged compliant configuration ({best}; drake_dock "
            f"{r.drake_dock.wall_time:.3f} s)")


def scene_lines(scene: dict, tol: float) -> list:
    """The scene's printed lines: the converged speed-ups first."""
    ref = scene["reference"]
    lines = [f"scene {scene['scene']}: capture at {ref['capture_time']:.6f} s (reference); "
             f"errors relative to each metric's contact effect, tolerance {tol:g}"]
    pts = scene["points"]
    lines += [_line("converged speed-up ", k, r)
              for k, r in converged_speedups(pts, tol).items()]
    for k, r in any_run_speedups(pts, tol).items():
        if r.ratio is not None:
            lines.append(f"  any run within the tolerance, {k}: {r.ratio:.3g}x ({_runs(r)})")
    for k in METRICS:
        lines.append(f"  contact effect on {k}: {scene['effect'][k]:.4g} {UNITS[k]} "
                     f"(reference value {ref[k]:.6g})")
    return lines


def speedup_lines(result) -> list:
    return [ln for scene in result["scenes"] for ln in scene_lines(scene, result["tolerance"])]


def write_study(result, out_dir):
    """points.csv, one chart per scene and the printed lines, atomically."""
    from drake_dock.docking.report.out_dir import atomic_directory
    with atomic_directory(out_dir, kind="study speed-accuracy") as tmp:
        (tmp / "points.csv").write_text(
            points_csv([p for scene in result["scenes"] for p in scene["points"]]))
        for scene in result["scenes"]:
            work_precision_figure(scene, result["tolerance"],
                                  tmp / f"work_precision_{scene['scene']}.png")
        (tmp / "speedups.txt").write_text("\n".join(speedup_lines(result)) + "\n")
    return Path(out_dir)
