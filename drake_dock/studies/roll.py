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

import dataclasses

import numpy as np

from drake_dock.studies.conditions import (OUTCOME_STYLE, run_rows,  # noqa: F401
                                           summary_lines, write_rows)


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
    return run_rows(scenario, plan,
                    [(f"roll {r:g}", {"target_yaw_deg": r}) for r in rolls(plan)], log)


def roll_figure(rows, path):
    """Capture time over the roll for the captured runs; the other outcomes on the axis."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.0), layout="constrained")
    for outcome, (marker, color) in OUTCOME_STYLE.items():
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
    write_rows(result, out_dir, "roll", roll_figure)
