"""The working-conditions sweep (`drake-dock study conditions`): seeded random conditions inside
the International Docking System Standard's initial-contact box, and corners of it, each run to
its outcome and checked by the two independent interpenetration checks: the analytic one
(`drake_dock.docking.checks.penetration`) and the triangle-mesh one
(`drake_dock.docking.checks.mesh_check`).

The box (docs/model.md, "Initial conditions"): closing rate 0.05-0.10 m/s; lateral
misalignment |offset| <= 0.10 m; lateral rate |v| <= 0.04 m/s; pitch and yaw (the tilt's two
components) within 4 deg each; roll (the relative yaw about the axis) within 4 deg; angular
rates within 0.2 deg/s about each axis. Random conditions are uniform over the box (the disks
uniform by area); a corner puts every parameter at an extreme, with seeded signs and
directions. Every run has the plan's contact set (`complete` by default: the edges, faces and
corners off-axis approaches reach); the base scenario gives everything else.

One row per run: the inputs, the outcome (captured, rebound, jammed, timeout, or `error` with
the typed error's class and message), capture time, impacts, peak contact force, momentum drift,
the energy ledger's closure, the deepest interpenetration (the deeper of the two checks', each
also in a column of its own) with where and when it was found, and the wall time; a row also
holds the end time, the axial ring distance at the end and the impacts per couple
(`impacts_by_couple`), which `drake_dock.studies.examples` writes.
"""
from __future__ import annotations

import copy
import csv
import dataclasses
import io
import json
import math
import time as _time

import numpy as np

from drake_dock.docking.checks.mesh_check import deepest_penetration_mesh
from drake_dock.docking.checks.penetration import deepest_penetration
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.out_dir import atomic_directory
from drake_dock.docking.report.results import summary, timeseries
from drake_dock.docking.scenario.validation import validate
from drake_dock.errors import DrakeDockError

IDSS_BOX = {"chaser_speed": (0.05, 0.10), "lateral_offset": 0.10, "lateral_velocity": 0.04,
            "tilt_deg": 4.0, "target_yaw_deg": 4.0, "angular_velocity_deg_s": 0.2}
PENETRATION_LIMIT = 1e-4     # m: deeper is reported as a model failure


@dataclasses.dataclass
class ConditionsPlan:
    random: int = 60
    corners: int = 16
    seed: int = 2026
    pairs: str = "complete"      # the contact set of every run (contact.pairs)

    @classmethod
    def quick(cls):
        return cls(random=3, corners=1)

    @classmethod
    def full(cls):
        return cls()


def _disk(rng, radius):
    r, a = radius * math.sqrt(rng.uniform()), rng.uniform(0.0, 2 * math.pi)
    return [r * math.cos(a), r * math.sin(a)]


def random_condition(rng) -> dict:
    b = IDSS_BOX
    return {"chaser_speed": rng.uniform(*b["chaser_speed"]),
            "lateral_offset": _disk(rng, b["lateral_offset"]),
            "lateral_velocity": _disk(rng, b["lateral_velocity"]),
            "tilt_deg": rng.uniform(-b["tilt_deg"], b["tilt_deg"], 2).tolist(),
            "target_yaw_deg": rng.uniform(-b["target_yaw_deg"], b["target_yaw_deg"]),
            "angular_velocity_deg_s": (b["angular_velocity_deg_s"]
                                       * rng.uniform(-1, 1, 3)).tolist()}


def corner_condition(rng) -> dict:
    """Every parameter at an extreme: the speed at either end, the two disks' vectors at their
    full radius in a random direction, each tilt and rate component and the roll at +-max."""
    b = IDSS_BOX

    def on_circle(radius):
        a = rng.uniform(0.0, 2 * math.pi)
        return [radius * math.cos(a), radius * math.sin(a)]

    def sign(n):
        return rng.choice([-1.0, 1.0], n)

    return {"chaser_speed": float(rng.choice(b["chaser_speed"])),
            "lateral_offset": on_circle(b["lateral_offset"]),
            "lateral_velocity": on_circle(b["lateral_velocity"]),
            "tilt_deg": (b["tilt_deg"] * sign(2)).tolist(),
            "target_yaw_deg": float(b["target_yaw_deg"] * sign(1)[0]),
            "angular_velocity_deg_s": (b["angular_velocity_deg_s"] * sign(3)).tolist()}


def conditions(plan: ConditionsPlan) -> list:
    """[(name, condition)] in a fixed order, from the plan's seed."""
    rng = np.random.default_rng(plan.seed)
    out = [(f"random {k + 1}", random_condition(rng)) for k in range(plan.random)]
    out += [(f"corner {k + 1}", corner_condition(rng)) for k in range(plan.corners)]
    return out


def with_condition(scenario, condition: dict):
    s = copy.deepcopy(scenario)
    for name, value in condition.items():
        setattr(s.initial, name, value)
    return validate(s)


def penetrations(g, ts) -> dict:
    """The row's interpenetration columns from both checks over the timeseries ts: each check's
    depth, the deeper one's and its description (naming the check)."""
    args = (g, ts["t"], ts["R_WA"], ts["p_WA"], ts["apds_names"].tolist())
    found = {"analytic": deepest_penetration(*args), "mesh": deepest_penetration_mesh(*args)}
    which = max(found, key=lambda k: found[k].depth)        # the analytic one on a tie
    deep = found[which]
    return {"penetration_m": deep.depth,
            "penetration_analytic_m": found["analytic"].depth,
            "penetration_mesh_m": found["mesh"].depth,
            "penetration": deep.describe() + (f" ({which} check)" if deep.depth else "")}


def run_condition(scenario, name: str, condition: dict) -> dict:
    """One row: the run's outcome and checks, or the typed error that ended it."""
    row = {"name": name, **{k: json.dumps(v) if isinstance(v, list) else v
                            for k, v in condition.items()}}
    wall0 = _time.perf_counter()
    try:
        s = with_condition(scenario, condition)
        result = simulate(s, place(s))
        ts = timeseries(result)
        summ = summary(result, ts)
    except DrakeDockError as e:
        row.update(outcome="error", reason=f"{type(e).__name__}: {e}",
                   wall_time_s=_time.perf_counter() - wall0)
        return row
    wall = _time.perf_counter() - wall0          # the run and its outputs, not the checks
    pen = penetrations(s.geometry, ts)
    row.update(outcome=summ["outcome"], reason=summ["outcome_reason"],
               capture_time_s=summ["capture_time_s"], impacts=summ["number_of_impacts"],
               peak_contact_force_N=summ["loads"]["couple_normal_force_N"]["peak"],
               momentum_drift_linear=summ["momentum_drift_relative"]["linear"],
               momentum_drift_angular=summ["momentum_drift_relative"]["angular"],
               energy_closure=summ["energy_ledger"]["closure_error_relative"],
               **pen,
               final_lateral_m=summ["final_misalignment"]["lateral_m"],
               final_tilt_deg=summ["final_misalignment"]["tilt_deg"],
               final_axial_m=summ["final_misalignment"]["axial_m"],
               end_time_s=summ["end_time_s"], impacts_by_couple=impacts_by_couple(ts),
               wall_time_s=wall)
    return row


def impacts_by_couple(ts) -> str:
    """JSON {couple: the number of impacts it takes part in}, by the couples' order."""
    names, taken = ts["couple_names"].tolist(), np.asarray(ts["impact_couples"], bool)
    count = taken.sum(axis=0) if taken.size else np.zeros(len(names), int)
    return json.dumps({n: int(k) for n, k in zip(names, count) if k})


def run_rows(scenario, plan, todo, log=print) -> dict:
    """Runs the conditions ``todo`` [(name, condition)] on the scenario with the plan's contact
    set (``plan.pairs``), logging each outcome: {"plan", "rows"}."""
    scenario = copy.deepcopy(scenario)
    scenario.contact.pairs = plan.pairs
    return run_each(plan, [(scenario, name, cond) for name, cond in todo], log,
                    lambda r: f", deepest interpenetration {r['penetration_m'] * 1e3:.3g} mm")


def run_each(plan, todo, log, finished) -> dict:
    """Runs ``todo`` [(scenario, name, condition)] by `run_condition`, logging each outcome
    with ``finished(row)`` after it, or the reason of a typed error: {"plan", "rows"}."""
    rows = []
    for k, (scenario, name, cond) in enumerate(todo, 1):
        row = run_condition(scenario, name, cond)
        rows.append(row)
        log(f"[{k}/{len(todo)}] {name}: {row['outcome']}"
            + (finished(row) if "penetration_m" in row else f" ({row['reason']})"))
    return {"plan": dataclasses.asdict(plan), "rows": rows}


def run_conditions(scenario, plan: ConditionsPlan, log=print) -> dict:
    return run_rows(scenario, plan, conditions(plan), log)


def counts(rows) -> dict:
    out = {}
    for r in rows:
        out[r["outcome"]] = out.get(r["outcome"], 0) + 1
    return out


def summary_lines(result) -> list:
    rows = result["rows"]
    ran = [r for r in rows if "penetration_m" in r]
    deep = [r for r in ran if r["penetration_m"] > PENETRATION_LIMIT]
    lines = [f"{len(rows)} runs: " + ", ".join(f"{k} {v}"
                                               for k, v in sorted(counts(rows).items()))]
    if ran:
        each = [f"{k} check {max(r[f'penetration_{k}_m'] for r in ran) * 1e3:.3g} mm"
                for k in ("analytic", "mesh") if all(f"penetration_{k}_m" in r for r in ran)]
        lines.append(f"interpenetration deeper than {PENETRATION_LIMIT * 1e3:g} mm in "
                     f"{len(deep)} of {len(ran)} finished runs; deepest "
                     f"{max(r['penetration_m'] for r in ran) * 1e3:.3g} mm"
                     + (f" ({', '.join(each)})" if each else ""))
        lines.append(f"largest momentum drift {max(r['momentum_drift_linear'] for r in ran):.2e}"
                     f" (linear), {max(r['momentum_drift_angular'] for r in ran):.2e} "
                     f"(angular); largest energy-ledger closure error "
                     f"{max(abs(r['energy_closure']) for r in ran):.2e}")
    walls = [r["wall_time_s"] for r in rows if "wall_time_s" in r]
    if walls:
        lines.append(f"median wall time per run {np.median(walls):.3g} s (fastest "
                     f"{min(walls):.3g} s, slowest {max(walls):.3g} s; the run and its "
                     f"outputs, the interpenetration checks excluded)")
    errors = {}
    for r in rows:
        if r["outcome"] == "error":
            kind = r["reason"].split(":")[0]
            errors[kind] = errors.get(kind, 0) + 1
    if errors:
        lines.append("errors: " + ", ".join(f"{k} {v}" for k, v in sorted(errors.items())))
    return lines


FIELDS = ("name", "chaser_speed", "lateral_offset", "lateral_velocity", "tilt_deg",
          "target_yaw_deg", "angular_velocity_deg_s", "outcome", "reason", "capture_time_s",
          "impacts", "peak_contact_force_N", "momentum_drift_linear", "momentum_drift_angular",
          "energy_closure", "penetration_m", "penetration_analytic_m", "penetration_mesh_m",
          "penetration", "final_lateral_m",
          "final_tilt_deg", "wall_time_s")


def rows_csv(rows, fields=FIELDS) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fields, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: r.get(k, "") for k in fields})
    return buf.getvalue()


# Marker and colour of each outcome in the studies' figures.
OUTCOME_STYLE = {"captured": ("o", "tab:green"), "missed": ("^", "tab:gray"),
                 "rebound": ("s", "tab:blue"),
                 "jammed": ("D", "tab:orange"), "timeout": ("v", "tab:purple"),
                 "error": ("x", "tab:red")}


def outcome_figure(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
    for outcome, (marker, color) in OUTCOME_STYLE.items():
        sel = [r for r in rows if r["outcome"] == outcome]
        if not sel:
            continue
        off = [1e3 * math.hypot(*json.loads(r["lateral_offset"])) for r in sel]
        tilt = [math.hypot(*json.loads(r["tilt_deg"])) for r in sel]
        ax.scatter(off, tilt, marker=marker, color=color, label=f"{outcome} ({len(sel)})")
    deep = [r for r in rows if r.get("penetration_m", 0.0) > PENETRATION_LIMIT]
    if deep:
        ax.scatter([1e3 * math.hypot(*json.loads(r["lateral_offset"])) for r in deep],
                   [math.hypot(*json.loads(r["tilt_deg"])) for r in deep], s=160,
                   facecolors="none", edgecolors="k",
                   label=f"interpenetration > {PENETRATION_LIMIT * 1e3:g} mm ({len(deep)})")
    ax.set_xlabel("lateral offset at first contact |offset| [mm]")
    ax.set_ylabel("tilt |(pitch, yaw)| [deg]")
    ax.set_title("Outcomes over the IDSS initial-contact box")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write_rows(result, out_dir, stem, figure):
    """Writes ``stem``.csv (the rows), ``stem``.png (``figure(rows, path)``) and summary.json
    into out_dir, all at once."""
    rows = result["rows"]
    with atomic_directory(out_dir) as tmp:
        (tmp / f"{stem}.csv").write_text(rows_csv(rows))
        figure(rows, tmp / f"{stem}.png")
        (tmp / "summary.json").write_text(json.dumps(
            {"plan": result["plan"], "counts": counts(rows), "lines": summary_lines(result)},
            indent=2) + "\n")


def write_conditions(result, out_dir):
    write_rows(result, out_dir, "conditions", outcome_figure)
