"""Runs a docking scenario end to end and writes its outputs atomically into a directory:
``summary.json`` (the numbers of the run), ``cost.json`` (what it cost the solver),
``timeseries.npz``, the figures (PNG), ``replay.html`` and ``drake.log``: the lines Drake logged
during the run, which are kept off the terminal, but for the replay's Meshcat start-up line
(`QUIET`); without other lines no drake.log is written.

A failed run (bad input, numerical failure) leaves no directory, or the previous complete one
untouched (`drake_dock.docking.report.out_dir.atomic_directory`). The destination is checked before
anything is simulated (`drake_dock.docking.report.out_dir.check_destination`): only a new path, an
empty directory or a previous drake_dock output is replaced.
"""
from __future__ import annotations

import contextlib
import json
import logging
from types import SimpleNamespace

import numpy as np

from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import PlacementCache, place
from drake_dock.docking.report.cost import run_cost
from drake_dock.docking.report.initial_figure import initial_configuration_figure
from drake_dock.docking.report.out_dir import atomic_directory, check_destination, npz_bytes
from drake_dock.docking.report.replay import replay_html
from drake_dock.docking.report.results import (momenta, momentum_reference_point, near_timeseries,
                                               non_finite_key, relative_text, summary,
                                               thrust_impulses, timeseries)
from drake_dock.docking.report.run_figures import run_figures
from drake_dock.errors import NumericalError


# Lines Drake logs that say nothing about the run: the address of the Meshcat server that
# draws the replay, which is closed when the run ends.
QUIET = ("Meshcat listening for connections",)


def log_worth_keeping(lines) -> list:
    """Drake's log lines but the `QUIET` ones."""
    return [line for line in lines if not any(q in line for q in QUIET)]


@contextlib.contextmanager
def drake_log():
    """Collects the records of Drake's logger ("drake", where pydrake sends Drake's log lines)
    into a list of lines instead of letting them reach the terminal; restored after."""
    logger = logging.getLogger("drake")
    lines = []
    handler = logging.Handler()
    handler.emit = lambda record: lines.append(f"{record.levelname}: {record.getMessage()}")
    saved = logger.propagate
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield lines
    finally:
        logger.removeHandler(handler)
        logger.propagate = saved


def run(scenario, out_dir, *, progress=None, state=None, dd=None, full=False, name=None):
    """Simulates ``scenario`` and writes everything into ``out_dir``; returns the summary, or
    with ``full`` a namespace (summary, cost, timeseries, result: the `RunResult`, figures: the
    `FigureRecord`s). ``name``: the scenario's name in the outputs (its file name without
    extension, say; default "scenario"). ``dd``: a docking Diagram built by the caller (with a
    controller on ``chaser_wrench``, say; `drake_dock.docking.model.control`); ``state``: an
    initial state (by default the scenario's, `drake_dock.docking.placement.place.place`).
    The scene is made once (`DockingScene`, or the one of ``dd``) and serves the placement,
    the Diagram and the report. Raises `InputError` for a destination that may not be
    replaced, before simulating, and `NumericalError` for a failed simulation or a non-finite
    summary value (nothing written)."""
    check_destination(out_dir)
    with drake_log() as log:
        return _run(scenario, out_dir, progress, state, dd, full, log, name or "scenario")


def _run(scenario, out_dir, progress, state, dd, full, log, name):
    scene = DockingScene.of(scenario) if dd is None else dd.scene
    state = state or place(scenario, PlacementCache(scene))
    dd = dd or build_docking_diagram(DiagramSpec.of(scenario, scene=scene))
    result = simulate(scenario, state, dd=dd, progress=progress)
    if hasattr(progress, "note"):
        progress.note(f"{result.outcome} at t = {result.end_time:.4f} s; writing the outputs "
                      f"(arrays, figures, replay)")
    ts = timeseries(result)
    summ = {"scenario_name": name, **summary(result, ts)}
    cost = run_cost(result, ts)
    bad = non_finite_key(summ)
    if bad is not None:
        raise NumericalError(f"the run's summary value {bad} is not finite (an overflow of "
                             f"extreme inputs)", time=result.end_time)
    params = [getattr(scenario.bodies, n) for n in ts["body_names"]]
    about = momentum_reference_point(scenario, ts)
    P, L, sP, sL = momenta(ts, [p.mass for p in params], [p.inertia for p in params], about)
    J, H = thrust_impulses(result, ts, about)       # conserved: momentum less the impulse
    momentum = (P - J, L - H, sP, sL)
    nq = result.dd.dp.plant.num_positions()
    html = replay_html(dd.spec, ts["t"], np.asarray(result.record.x)[:, :nq], ts=ts, title=name)
    with atomic_directory(out_dir) as tmp:
        (tmp / "timeseries.npz").write_bytes(npz_bytes(near_timeseries(ts)))
        records = run_figures(ts, summ, momentum, tmp, pairs=scene.pairs)
        poses = {n: (ts["R_WA"][0, j], ts["p_WA"][0, j])
                 for j, n in enumerate(ts["apds_names"].tolist())}
        cn = ts["couple_names"].tolist()
        first = {c: SimpleNamespace(p1=ts["p1_W"][0, cn.index(c)], p2=ts["p2_W"][0, cn.index(c)])
                 for c in result.initial.closing_pairs}
        records.append(initial_configuration_figure(scene, poses, first, tmp))
        summ = {**{k: v for k, v in summ.items() if k != "scenario"},
                "figures": [r.name for r in records], "scenario": summ["scenario"]}
        (tmp / "replay.html").write_text(html)
        (tmp / "summary.json").write_text(json.dumps(summ, indent=2, allow_nan=False) + "\n")
        (tmp / "cost.json").write_text(json.dumps(cost, indent=2) + "\n")
        kept = log_worth_keeping(log)
        if kept:
            (tmp / "drake.log").write_text("".join(line + "\n" for line in kept))
    if full:
        return SimpleNamespace(summary=summ, cost=cost, timeseries=ts, result=result,
                               figures=records)
    return summ


def _at(peak: dict) -> str:
    return "" if peak["time_s"] is None else f" at {peak['time_s']:.3f} s"


def format_summary(s, cost=None) -> str:
    """The printed summary of a run: outcome, misalignment, loads, energy, conservation and
    (with ``cost``) the simulation's wall time."""
    fm = s["final_misalignment"]
    led = s["energy_ledger"]
    md = s["momentum_drift_relative"]
    lo = s["loads"]
    fi, mi = lo["interface_force_N"], lo["interface_moment_Nm"]
    st, sf = lo["stewart_stroke_m"], lo["stewart_force_N"]
    pc = lo["couple_normal_force_N"]
    rel = s["relative_kinetic_energy_at_contact_J"]
    lines = [
        f"{s['outcome']} at t = {s['end_time_s']:.6f} s ({s['outcome_reason']})",
        f"final misalignment: axial {1e3 * fm['axial_m']:.4g} mm, lateral "
        f"{1e3 * fm['lateral_m']:.3g} mm, tilt {fm['tilt_deg']:.3g} deg",
        f"interface loads at the target ring: force {fi['peak']:.4g} N{_at(fi)} (axial "
        f"{fi['axial_peak']:.4g} N, lateral {fi['lateral_peak']:.4g} N), moment "
        f"{mi['peak']:.4g} N m{_at(mi)}",
        f"Stewart element: stroke {1e3 * st['peak']:.4g} mm{_at(st)}, force "
        f"{sf['peak']:.4g} N{_at(sf)}",
        f"contact: peak total force {lo['total_contact_force_N']['peak']:.4g} N; peak "
        f"couple normal force {pc['peak']:.4g} N"
        + (f" ({pc['couple']}: {s['couples'][pc['couple']]['description']})" if pc["couple"]
           else "")
        + f"; {s['number_of_impacts']} impacts, largest impulse "
        f"{s['largest_impulse_Ns']:.4g} N s",
        f"energy: relative kinetic energy at contact "
        + ("none (no contact)" if rel is None else f"{rel:.4g} J")
        + f" (centre-of-mass frame); in the inertial frame: initial {led['initial_total_J']:.4g}"
        f" J, dissipated by the damper {led['dissipated_damper_J']:.4g} J, friction "
        f"{led['dissipated_friction_J']:.4g} J, impacts {led['dissipated_impacts_J']:.4g} J,"
        f" input work {led['input_work_J']:.4g} J; ledger closure "
        f"{relative_text(led['closure_error_relative'])}",
        f"momentum drift (relative): linear {relative_text(md['linear'])}, angular "
        f"{relative_text(md['angular'])}"]
    if cost is not None:
        lines.append(f"solver: {cost['derivative_evaluations']} derivative evaluations for "
                     f"{cost['simulated_s']:.4f} s simulated in {cost['wall_time_s']:.2f} s "
                     f"(more in cost.json)")
    return "\n".join(lines)


def time_shares_line(ts) -> str:
    """One line: the share of wall time spent seeking, in contact dynamics, in impacts and
    elsewhere, and the pairs searched (declared pairs, seeks, and far pairs the broad phase kept
    from a seek)."""
    sh = ts["shares"]
    seeks = ts["seeks_per_pair"]
    return (f"time shares: seeking {sh['seeking']:.0%}, contact dynamics "
            f"{sh['contact_dynamics']:.0%}, impacts {sh['impacts']:.0%}, other {sh['other']:.0%};"
            f" pairs searched {sum(1 for n in seeks.values() if n)}/{ts['pairs_declared']} "
            f"declared, {sum(seeks.values())} seeks, "
            f"{sum(ts.get('screens_per_pair', {}).values())} screened by the broad phase")
