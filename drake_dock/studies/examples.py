"""The named examples (`drake-dock study examples`): the off-axis scenarios shipped in models/
(`idss_box_corner`, `idss_lateral`, `idss_tilted`, each with its own contact set) and the base
scenario in free drift at slow closing rates, each run to its outcome and checked by the two
independent interpenetration checks, as the conditions sweep checks its runs
(`drake_dock.studies.conditions`).

One row per run, with the conditions sweep's columns (its `wall_time_s` the run's measured
wall time), the end time and the axial ring-centre distance at the end, which say how far a
jammed run stopped from capture, and the number of impacts each couple took part in:
`examples.csv`; the printed lines in `summary.json`.
"""
from __future__ import annotations

import dataclasses
import json

from drake_dock.docking.report.out_dir import atomic_directory
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import MODELS_DIR
from drake_dock.studies.conditions import FIELDS, IDSS_BOX, counts, rows_csv, run_each

assert FIELDS[-1] == "wall_time_s"
EXAMPLE_FIELDS = FIELDS[:-1] + ("end_time_s", "final_axial_m", "impacts_by_couple",
                                "wall_time_s")


@dataclasses.dataclass
class ExamplesPlan:
    # scenario files of models/ run as they are, by stem
    files: tuple = ("idss_box_corner", "idss_lateral", "idss_tilted")
    # the base scenario with these initial fields, by name: the IDSS box's slowest closing
    # rate at the paper's roll and at 1 deg, and a rate between
    drifts: tuple = (("slow 0.05 m/s", (("chaser_speed", 0.05),)),
                     ("slow 0.05 m/s, roll 1 deg", (("chaser_speed", 0.05),
                                                    ("target_yaw_deg", 1.0))),
                     ("slow 0.08 m/s", (("chaser_speed", 0.08),)))

    @classmethod
    def quick(cls):
        return cls(files=("idss_lateral",), drifts=())

    @classmethod
    def full(cls):
        return cls()


def run_examples(scenario, plan: ExamplesPlan, log=print) -> dict:
    """Runs the plan's files and the base ``scenario``'s drifts, logging each outcome:
    {"plan", "rows"}."""
    todo = [(stem, load_scenario(MODELS_DIR / f"{stem}.yaml"), ()) for stem in plan.files]
    todo += [(name, scenario, fields) for name, fields in plan.drifts]
    # each row's inputs: the box's fields as its scenario gives them, with a drift's own
    return run_each(plan, [(base, name, {f: _plain(getattr(base.initial, f)) for f in IDSS_BOX}
                            | dict(fields)) for name, base, fields in todo], log,
                    lambda r: f" at {r['end_time_s']:.3g} s after {r['impacts']} impacts")


def _plain(value):
    return list(value) if isinstance(value, (list, tuple)) else value


def summary_lines(result) -> list:
    return [f"{r['name']}: {r['outcome']}"
            + (f" at {r['end_time_s']:.4g} s, {r['impacts']} impacts, axial ring distance "
               f"{r['final_axial_m']:.3g} m, deepest interpenetration "
               f"{r['penetration_m'] * 1e3:.3g} mm" if "end_time_s" in r else
               f" ({r['reason']})") for r in result["rows"]]


def write_examples(result, out_dir):
    """examples.csv and summary.json, into out_dir at once."""
    with atomic_directory(out_dir) as tmp:
        (tmp / "examples.csv").write_text(rows_csv(result["rows"], EXAMPLE_FIELDS))
        (tmp / "summary.json").write_text(json.dumps(
            {"plan": result["plan"], "counts": counts(result["rows"]),
             "lines": summary_lines(result)}, indent=2) + "\n")
