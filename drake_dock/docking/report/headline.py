"""A run's headline numbers as a Markdown table (docs/results.md states the paper example's):
one row per quantity, its value as the run gives it and the field that holds it, a field of
`summary.json` or an array of `timeseries.npz` where marked."""
from __future__ import annotations

import math

import numpy as np


def _and(items) -> str:
    items = list(items)
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _row(quantity: str, value: str, field: str) -> str:
    return f"| {quantity} | {value} | {field} |"


def _below(x: float) -> str:
    """'below 1e-k' for the least power of ten above ``x`` (0: 'exactly 0')."""
    return "exactly 0" if x == 0 else f"below 1e{math.floor(math.log10(x)) + 1}"


def headline_rows(summary: dict, impact_normal_impulse, impact_restitution) -> list[str]:
    """The rows of the table for a run's ``summary`` (summary.json) and its timeseries'
    per-impact normal impulses (impacts x couples) and restitutions."""
    s, L, E = summary, summary["loads"], summary["energy_ledger"]
    rows = [
        _row("first contact: ring-face distance", f"{s['first_contact_ring_distance_m']:.5f} m",
             "`first_contact_ring_distance_m`"),
        _row("first contact: couples", ", ".join(f"`{c}`" for c in s["first_closing_couples"]),
             "`first_closing_couples`")]
    if s["captured"]:
        rows.append(_row(
            f"capture (axial ring-centre distance {1e3 * s['capture_tolerances']['axial_m']:g} mm)",
            f"t = {s['capture_time_s']:.5f} s", "`capture_time_s`"))
    times = s["impact_times_s"]
    rows.append(_row("impacts", f"{len(times)}, at t = {_and(f'{t:.4f}' for t in times)} s"
                     if times else "0", "`number_of_impacts`, `impact_times_s`"))
    if times:
        per = np.max(np.asarray(impact_normal_impulse), axis=1)
        rows.append(_row("largest normal impulse of a couple, per impact",
                         f"{_and(f'{p:#.3g}' for p in per)} N s", "npz: `impact_normal_impulse`"))
        e = list(impact_restitution)
        guard = " (0: the Zeno guard, an approach slower than `zeno_speed`)" if 0.0 in e else ""
        rows.append(_row("restitution applied, per impact", _and(f"{x:g}" for x in e) + guard,
                         "npz: `impact_restitution`"))
    couple = L["couple_normal_force_N"]
    rows += [
        _row(f"normal force of a couple (peak, `{couple['couple']}`)", f"{couple['peak']:.1f} N",
             "`loads.couple_normal_force_N.peak`"),
        _row("total contact force (peak, the couples' forces, normal and friction)",
             f"{L['total_contact_force_N']['peak']:.1f} N", "`loads.total_contact_force_N.peak`"),
        _row("contact force at the target ring (peak)", f"{L['interface_force_N']['peak']:.1f} N",
             "`loads.interface_force_N.peak`"),
        _row("Stewart stroke (peak" + (", at capture" if s["captured"] and
                                       L["stewart_stroke_m"]["time_s"] == s["capture_time_s"]
                                       else "") + ")",
             f"{1e3 * L['stewart_stroke_m']['peak']:.1f} mm", "`loads.stewart_stroke_m.peak`"),
        _row("relative kinetic energy at contact (centre-of-mass frame: 1/2 mu v^2)",
             f"{s['relative_kinetic_energy_at_contact_J']:.1f} J",
             "`relative_kinetic_energy_at_contact_J`"),
        _row(f"energy at t = 0 (inertial frame; {E['initial_centre_of_mass_motion_J']:.1f} J of it "
             "the centre of mass's motion)", f"{E['initial_total_J']:.1f} J",
             "`energy_ledger.initial_total_J`"),
        _row("at the end: kinetic, Stewart potential",
             f"{E['kinetic_J']:.1f} J, {E['stewart_potential_J']:.1f} J",
             "`energy_ledger.kinetic_J`, `.stewart_potential_J`"),
        _row("dissipated by the damper, the impacts, friction",
             f"{E['dissipated_damper_J']:.1f} J, {E['dissipated_impacts_J']:.1f} J, "
             f"{E['dissipated_friction_J']:.1f} J", "`energy_ledger.dissipated_*_J`"),
        _row("energy ledger closure (relative)", _below(E["closure_error_relative"]),
             "`energy_ledger.closure_error_relative`"),
        _row("momentum drift (relative, linear and angular)",
             _below(max(s["momentum_drift_relative"].values())), "`momentum_drift_relative`")]
    return rows


def headline_table(summary: dict, impact_normal_impulse, impact_restitution) -> str:
    """`headline_rows` under the table's header."""
    return "\n".join(["| quantity | value | field |", "| --- | --- | --- |"]
                     + headline_rows(summary, impact_normal_impulse, impact_restitution))
