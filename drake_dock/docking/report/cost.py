"""What a run cost the solver (cost.json): its wall time, evaluations and mode changes, the
time shares, and the cost of each pair type, a family of pairs (`cost_by_pair_type`)."""
from __future__ import annotations


def cost_by_pair_type(time_shares: dict, scene) -> dict:
    """{pair type: pairs declared, seeks, screenings, wall time of both (s), evaluations with a
    pair tracked} from a run's time shares (`drake_dock.systems.profiling.Timing.shares`); a
    pair's type is its family (`PairSpec.family`), read from the run's ``scene``
    (`DockingScene.pair`: a name the scene does not declare is an `InputError`)."""
    out = {}
    for name, seeks in time_shares["seeks_per_pair"].items():
        row = out.setdefault(scene.pair(name).family, {
            "pairs": 0, "seeks": 0, "screens": 0, "seek_time_s": 0.0, "tracked_evaluations": 0})
        row["pairs"] += 1
        row["seeks"] += seeks
        row["screens"] += time_shares["screens_per_pair"][name]
        row["seek_time_s"] += time_shares["seek_time_per_pair"][name]
        row["tracked_evaluations"] += time_shares["tracked_evaluations_per_pair"][name]
    return out


def run_cost(result, ts: dict) -> dict:
    """What the run cost the solver (cost.json): the wall time of the simulation (compilation
    and output writing excluded), the derivative evaluations, samples and mode changes, the
    time shares and the cost per pair type (`cost_by_pair_type`). Wall times vary from run to
    run."""
    return {
        "wall_time_s": result.wall_time,
        "simulated_s": result.end_time,
        "derivative_evaluations": result.evaluations,
        "samples": int(len(ts["t"])),
        "mode_changes": result.mode_changes,
        "time_shares": result.timing,
        "cost_by_pair_type": cost_by_pair_type(result.timing, result.scene),
    }
