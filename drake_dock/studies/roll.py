"""The relative-roll study (`drake-dock study roll`): the base scenario's coaxial approach over
the whole roll range the scenario allows (initial.target_yaw_deg, -60 < roll < 60 deg) with
the plan's contact set, each run to its outcome and checked by the two independent
interpenetration checks, as the conditions sweep checks its runs
(`drake_dock.studies.conditions`).

About the axis the petals of the two APDS pass between each other at a roll of 0, meet guide
surface on guide surface up to 2 theta_end (37.18 deg in the paper's geometry), and tip on tip
beyond it (docs/model.md, "Tip on tip"). The grid is symmetric, with the range's ends at
+-``edge_deg``.
"""
from __future__ import annotations

import copy
import dataclasses
import json

import numpy as np

from drake_dock.docking.output import atomic_directory
from drake_dock.studies.conditions import counts, rows_csv, run_condition, summary_lines


@dataclasses.dataclass
class RollPlan:
    step_deg: float = 2.5        # the grid's spacing
    edge_deg: float = 59.9       # the outermost rolls (the scenario excludes +-60 deg)
    pairs: str = "complete"      # the contact set of every run (contact.pairs)

    @classmethod
    def quick(cls):
        return cls(step_deg=60.0, edge_deg=20.0)

    @classmethod
    def full(cls):
        return cls()


def rolls(plan: RollPlan) -> list:
    """The grid's rolls (deg), ascending: the multiples of step_deg inside +-edge_deg, and
    +-edge_deg."""
    k = int(np.floor(plan.edge_deg / plan.step_deg))
    inner = [j * plan.step_deg for j in range(-k, k + 1)
             if abs(j * plan.step_deg) < plan.edge_deg]
    return [-plan.edge_deg] + [float(r) for r in inner] + [plan.edge_deg]


def run_rolls(scenario, plan: RollPlan, log=print) -> dict:
    scenario = copy.deepcopy(scenario)
    scenario.contact.pairs = plan.pairs
    rows = []
    todo = rolls(plan)
    for k, roll in enumerate(todo, 1):
        row = run_condition(scenario, f"roll {roll:g}", {"target_yaw_deg": roll})
        rows.append(row)
        log(f"[{k}/{len(todo)}] roll {roll:g} deg: {row['outcome']}"
            + (f", deepest interpenetration {row['penetration_m'] * 1e3:.3g} mm"
               if "penetration_m" in row else f" ({row['reason']})"))
    return {"plan": dataclasses.asdict(plan), "rows": rows}


def roll_figure(rows, path):
    """Capture time over the roll for the captured runs; the other outcomes on the axis."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    style = {"captured": ("o", "tab:green"), "rebound": ("s", "tab:blue"),
             "jammed": ("D", "tab:orange"), "timeout": ("v", "tab:purple"),
             "error": ("x", "tab:red")}
    fig, ax = plt.subplots(figsize=(6.4, 4.0), layout="constrained")
    for outcome, (marker, color) in style.items():
        sel = [r for r in rows if r["outcome"] == outcome]
        if sel:
            y = [r["capture_time_s"] if outcome == "captured" else 0.0 for r in sel]
            ax.scatter([r["target_yaw_deg"] for r in sel], y, marker=marker, color=color,
                       label=f"{outcome} ({len(sel)})")
    ax.set_xlabel("relative roll (initial.target_yaw_deg) [deg]")
    ax.set_ylabel("capture time [s] (other outcomes at 0)")
    ax.set_title("Coaxial approach over the roll range")
    ax.legend(loc="upper center", fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write_rolls(result, out_dir):
    rows = result["rows"]
    with atomic_directory(out_dir) as tmp:
        (tmp / "roll.csv").write_text(rows_csv(rows))
        roll_figure(rows, tmp / "roll.png")
        (tmp / "summary.json").write_text(json.dumps(
            {"plan": result["plan"], "counts": counts(rows), "lines": summary_lines(result)},
            indent=2) + "\n")
