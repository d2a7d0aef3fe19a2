"""The funnel study (`drake-dock study funnel`): the capture range of an APDS geometry, the
largest lateral offset at first contact that still captures, over the clearance between the
petal tips and the other ring's inside circle, and over a few thrust levels.

The clearance is c = Rs - (Rp - H cot(alpha1)): how far off the axis a petal tip can meet the
other APDS and still land inside its ring's passage rather than on its ring (Rp the petals'
root radius, `drake_dock.docking.scenario.dimensions.ApdsGeometry.Rp`). The geometries:

- the paper's (Rs = 0.4 m, petals on the outside circle R = 0.6 m, H = 0.2 m): c = 0;
- petals on the outside circle with a wider passage (``rim_passages``): c > 0, but the other
  ring rides down the petals and stops (Rp - Rs) tan(alpha1) short of the ring face, beyond
  the latches' reach;
- the funnel family (``funnel_heights``): the petals on the ring's inside circle (Rp = Rs =
  ``funnel_passage``) with petal height H, c = H cot(alpha1); the rings meet face to face.

Every other input is the base scenario's. Each point's probe approach closes at
``closing_speed`` with the relative roll ``roll_deg``, no tilt and no rates, offset at first
contact along each of ``directions_deg`` (in the target APDS frame: 30 deg is the middle of a
target petal, 90 deg the middle of the gap between two); the capture range is the smaller of
the directions' ranges. Each direction's range is found by bisection on the offset, between 0
(which must capture, else the range is 0) and c + ``beyond`` (which must not, else the range
is at least that), in ``steps`` halvings; the outcome is assumed to change once in between.
Every run is checked by the two independent interpenetration checks
(`drake_dock.studies.conditions.penetrations`).
"""
from __future__ import annotations

import copy
import csv
import dataclasses
import io
import json
import math
import time as _time

from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.out_dir import atomic_directory
from drake_dock.docking.report.results import summary, timeseries
from drake_dock.docking.scenario.schema import ThrustParams
from drake_dock.docking.scenario.validation import validate
from drake_dock.errors import DrakeDockError
from drake_dock.studies.conditions import PENETRATION_LIMIT, penetrations


@dataclasses.dataclass
class FunnelPlan:
    thrusts: tuple = (0.0, 300.0)            # N, from the first contact for thrust_duration s
    thrust_duration: float = 3.0
    paper: bool = True                       # the paper's geometry (c = 0)
    rim_passages: tuple = (0.5,)             # Rs with the petals on the outside circle
    funnel_passage: float = 0.55             # Rs = Rp of the funnel family
    funnel_heights: tuple = (0.05, 0.1, 0.15)   # H of the funnel family (m)
    directions_deg: tuple = (30.0, 90.0)
    closing_speed: float = 0.1               # m/s (the IDSS box's fastest)
    roll_deg: float = 2.0
    beyond: float = 0.05                     # m past the clearance: the bisection's upper end
    steps: int = 5
    checks: bool = True                      # both interpenetration checks on every run

    @classmethod
    def quick(cls):
        return cls(thrusts=(300.0,), paper=False, rim_passages=(), funnel_heights=(0.15,),
                   directions_deg=(90.0,), steps=1, checks=True)

    @classmethod
    def full(cls):
        return cls()

    @classmethod
    def shipped(cls):
        """The paper's geometry and the shipped funnel (the scenario's own, H 0.15 m) only,
        in 4 halvings: docs/results.md's table and figure."""
        return cls(rim_passages=(), funnel_heights=(0.15,), steps=4)


def clearance(g) -> float:
    """c = Rs - (Rp - H cot(alpha1)) (m): the tip arcs' clearance inside the other ring's
    inside circle, coaxially."""
    return g.Rs - g.tip_radius


def geometries(base, plan: FunnelPlan) -> list:
    """[(label, geometry)]: the plan's geometries on the base scenario's R, alpha1, alpha2."""
    out = []

    def add(label, **kw):
        g = dataclasses.replace(base, **kw)
        out.append((label, g.validate("geometry")))
    if plan.paper:
        add("paper (Rs 0.4, petals on R)", Rs=0.4, H=0.2, petal_root_radius=None,
            petal_inset_deg=0.0)
    for rs in plan.rim_passages:
        add(f"petals on R, Rs {rs:g}", Rs=rs, H=0.2, petal_root_radius=None,
            petal_inset_deg=0.0)
    for h in plan.funnel_heights:
        add(f"funnel Rs = Rp {plan.funnel_passage:g}, H {h:g}", Rs=plan.funnel_passage, H=h,
            petal_root_radius=plan.funnel_passage)      # the base's petal inset
    return out


def probe(base, g, thrust: float, plan: FunnelPlan, offset: float, direction_deg: float):
    """The base scenario with geometry g, the thrust and the probe approach at ``offset``."""
    s = copy.deepcopy(base)
    s.geometry = copy.deepcopy(g)
    s.thrust = (ThrustParams(force=thrust, duration=plan.thrust_duration) if thrust > 0
                else None)
    a = math.radians(direction_deg)
    ic = s.initial
    ic.chaser_speed, ic.target_yaw_deg = plan.closing_speed, plan.roll_deg
    ic.lateral_offset = [offset * math.cos(a), offset * math.sin(a)]
    ic.tilt_deg, ic.lateral_velocity = [0.0, 0.0], [0.0, 0.0]
    ic.angular_velocity_deg_s = [0.0, 0.0, 0.0]
    return validate(s)


def run_probe(s, checks: bool) -> dict:
    """One run: its outcome (or the typed error), capture time, the peak force at the target
    ring and, with ``checks``, the interpenetration columns."""
    w0 = _time.perf_counter()
    try:
        result = simulate(s, place(s))
        ts = timeseries(result)
        summ = summary(result, ts)
    except DrakeDockError as e:
        return {"outcome": "error", "reason": f"{type(e).__name__}: {e}",
                "wall_time_s": _time.perf_counter() - w0}
    row = {"outcome": summ["outcome"], "reason": summ["outcome_reason"],
           "capture_time_s": summ["capture_time_s"],
           "peak_interface_force_N": summ["loads"]["interface_force_N"]["peak"],
           "wall_time_s": _time.perf_counter() - w0}
    if checks:
        row.update(penetrations(s.geometry, ts))
    return row


def capture_range(run, hi: float, steps: int) -> tuple:
    """(range, runs) of a monotone test ``run(offset) -> captured`` on [0, hi]: 0 where 0 does
    not capture, hi where hi does, else the bracket's lower end after ``steps`` halvings."""
    tried = []

    def captured(e):
        ok = run(e)
        tried.append((e, ok))
        return ok
    if not captured(0.0):
        return 0.0, tried
    if captured(hi):
        return hi, tried
    lo = 0.0
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        if captured(mid):
            lo = mid
        else:
            hi = mid
    return lo, tried


def run_funnel(scenario, plan: FunnelPlan, log=print) -> dict:
    """Every geometry and thrust of the plan: {"plan", "points", "runs"}."""
    points, runs = [], []
    for label, g in geometries(scenario.geometry, plan):
        c = clearance(g)
        for thrust in plan.thrusts:
            ranges = []
            for direction in plan.directions_deg:
                def one(e, direction=direction):
                    row = {"geometry": label, "Rs": g.Rs, "Rp": g.Rp, "H": g.H,
                           "clearance_m": c, "thrust_N": thrust, "direction_deg": direction,
                           "offset_m": e,
                           **run_probe(probe(scenario, g, thrust, plan, e, direction),
                                       plan.checks)}
                    runs.append(row)
                    log(f"{label}, thrust {thrust:g} N, direction {direction:g} deg, offset "
                        f"{1e3 * e:.1f} mm: {row['outcome']}"
                        + (f", deepest interpenetration {1e3 * row['penetration_m']:.3g} mm"
                           if "penetration_m" in row else ""))
                    return row["outcome"] == "captured"
                r, _ = capture_range(one, c + plan.beyond, plan.steps)
                ranges.append(r)
            points.append({"geometry": label, "Rs": g.Rs, "Rp": g.Rp, "H": g.H,
                           "alpha1_deg": g.alpha1_deg, "clearance_m": c, "thrust_N": thrust,
                           "capture_range_m": min(ranges),
                           "at_least": min(ranges) >= c + plan.beyond,
                           "ranges_by_direction_m": ranges})
    return {"plan": dataclasses.asdict(plan), "points": points, "runs": runs}


def summary_lines(result) -> list:
    lines = []
    for p in result["points"]:
        lines.append(f"{p['geometry']}: clearance {1e3 * p['clearance_m']:.0f} mm, thrust "
                     f"{p['thrust_N']:g} N: capture range "
                     f"{'>= ' if p['at_least'] else ''}{1e3 * p['capture_range_m']:.0f} mm")
    runs = result["runs"]
    checked = [r for r in runs if "penetration_m" in r]
    if checked:
        deep = [r for r in checked if r["penetration_m"] > PENETRATION_LIMIT]
        lines.append(f"interpenetration deeper than {PENETRATION_LIMIT * 1e3:g} mm in "
                     f"{len(deep)} of {len(checked)} checked runs; deepest "
                     f"{1e3 * max(r['penetration_m'] for r in checked):.3g} mm")
    errors = [r for r in runs if r["outcome"] == "error"]
    lines.append(f"{len(runs)} runs, {len(errors)} numerical errors")
    return lines


POINT_FIELDS = ("geometry", "Rs", "Rp", "H", "alpha1_deg", "clearance_m", "thrust_N",
                "capture_range_m", "at_least", "ranges_by_direction_m")
RUN_FIELDS = ("geometry", "Rs", "Rp", "H", "clearance_m", "thrust_N", "direction_deg",
              "offset_m", "outcome", "reason", "capture_time_s", "peak_interface_force_N",
              "penetration_m", "penetration_analytic_m", "penetration_mesh_m", "penetration",
              "wall_time_s")


def _csv(rows, fields) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fields, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: json.dumps(r[k]) if isinstance(r.get(k), list) else r.get(k, "")
                    for k in fields})
    return buf.getvalue()


def funnel_figure(points, path):
    """Capture range over the clearance, a line per thrust; the IDSS box's 0.1 m and the
    line range = clearance for reference."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
    top = max([1e3 * p["clearance_m"] for p in points] + [100.0]) * 1.15
    ax.plot([0, top], [0, top], color="0.8", lw=1, label="range = clearance")
    ax.axhline(100.0, color="tab:red", ls="--", lw=1, label="IDSS box: 0.1 m offset")
    for k, thrust in enumerate(sorted({p["thrust_N"] for p in points})):
        sel = sorted((p for p in points if p["thrust_N"] == thrust),
                     key=lambda p: p["clearance_m"])
        fam = [p for p in sel if p["geometry"].startswith("funnel")]
        color = f"C{k}"
        if fam:
            ax.plot([1e3 * p["clearance_m"] for p in fam],
                    [1e3 * p["capture_range_m"] for p in fam], "o-", color=color,
                    label=f"funnel family, thrust {thrust:g} N")
        for p in sel:
            if not p["geometry"].startswith("funnel"):
                ax.scatter([1e3 * p["clearance_m"]], [1e3 * p["capture_range_m"]],
                           marker="s" if p["geometry"].startswith("paper") else "D",
                           color=color, edgecolors="k", zorder=3,
                           label=f"{p['geometry']}, {thrust:g} N")
        for p in sel:
            if p["at_least"]:
                ax.annotate("", (1e3 * p["clearance_m"], 1e3 * p["capture_range_m"] + 0.06 * top),
                            (1e3 * p["clearance_m"], 1e3 * p["capture_range_m"]),
                            arrowprops={"arrowstyle": "->", "color": color})
    ax.set_xlim(-0.03 * top, top)
    ax.set_ylim(-0.03 * top, top)
    ax.set_xlabel("clearance of the petal tips inside the other ring, c [mm]")
    ax.set_ylabel("capture range: largest lateral offset captured [mm]")
    ax.set_title("The funnel: capture range over clearance and thrust")
    ax.legend(loc="upper left", fontsize=7)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write_funnel(result, out_dir):
    with atomic_directory(out_dir) as tmp:
        (tmp / "funnel.csv").write_text(_csv(result["points"], POINT_FIELDS))
        (tmp / "funnel_runs.csv").write_text(_csv(result["runs"], RUN_FIELDS))
        funnel_figure(result["points"], tmp / "funnel.png")
        (tmp / "summary.json").write_text(json.dumps(
            {"plan": result["plan"], "points": result["points"],
             "lines": summary_lines(result)}, indent=2) + "\n")


def main(argv=None) -> int:
    """``python -m drake_dock.studies.funnel --shipped DIR``: the shipped plan
    (`FunnelPlan.shipped`) on models/apds_funnel.yaml, written into DIR."""
    import argparse
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.docking.scenario.models_dir import MODELS_DIR
    parser = argparse.ArgumentParser(prog="python -m drake_dock.studies.funnel")
    parser.add_argument("--shipped", metavar="DIR", required=True,
                        help="run the shipped plan and write its files into DIR")
    args = parser.parse_args(argv)
    try:
        write_funnel(run_funnel(load_scenario(MODELS_DIR / "apds_funnel.yaml"),
                                FunnelPlan.shipped()), args.shipped)
    except DrakeDockError as e:
        print(f"error: {e}")
        return 2
    print(f"wrote {args.shipped}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
