"""The run figures: the equivalents of the paper's Figs. 6-9 (this module), every couple that
came into contact, the energy ledger and the interface loads (`ledger_figures`); the initial
configuration is `initial_figure`'s. Grey vertical lines mark the impacts. Every panel shows data: a panel
whose curves are all round-off is not drawn (a note names them). `run_figures` returns a
`FigureRecord` per file (the series drawn in each axes, `drake_dock.docking.report.figure_kit`)."""
from __future__ import annotations

import numpy as np

from drake_dock.docking.report.figure_kit import (PALETTE, ROUND_OFF, Sheet, impact_lines, largest,
                                                  legend_beside, negligible, time_axes, with_data)
from drake_dock.docking.report.ledger_figures import (couple_forces_figure, energy_ledger_figure,
                                                      interface_loads_figure)
from drake_dock.docking.report.results import ROUND_OFF, drift_text

# The symmetric couples of Fig. 8 drawn over each other: wide light solid, dashed, thin dotted.
STYLES = (dict(lw=6.0, alpha=0.55, ls="-"), dict(lw=2.8, ls=(0, (5, 3))),
          dict(lw=1.3, ls=(0, (1, 1.5))))
MARKERS = (dict(marker="o", ms=12), dict(marker="s", ms=8), dict(marker="^", ms=5))


def _axis(ts):
    """The docking axis at t = 0 (target APDS e3), fixed in the world."""
    return ts["R_WA"][0, 0][:, 2]


def _not_plotted(names, top, unit, scale, what="") -> str:
    """The note of curves left out as round-off."""
    return (f"{what}{names}: zero throughout" if top == 0.0 else
            f"{what}{names} not plotted, zero at this scale:\n|.| <= {top:.1e} {unit}, below "
            f"{ROUND_OFF:g} of the scale {scale:.3g} {unit}")


def rotation_rates_figure(ts, out):
    """Fig. 6: each body's rotation rate about the docking axis and transverse to it; a panel
    whose rates are all round-off (the transverse rates of a coaxial run) is not drawn and
    is named in a note."""
    t, e3 = ts["t"], _axis(ts)
    names = ts["body_names"].tolist()
    w = ts["w_WB"]
    axial = {n: w[:, j] @ e3 for j, n in enumerate(names)}
    transverse = {n: np.linalg.norm(w[:, j] - np.outer(axial[n], e3), axis=1)
                  for j, n in enumerate(names)}
    scale = float(np.abs(w).max(initial=0.0))
    panels = [(axial, "rate about the docking axis [rad/s]", "about the axis: "),
              (transverse, "transverse rate [rad/s]", "transverse rates: ")]
    kept = with_data(panels, scale)
    if not kept:
        return None
    sh = Sheet(figsize=(8 + 4 * (len(kept) - 1), 4))
    axs = np.atleast_1d(sh.fig.subplots(1, len(kept)))
    for ax, (curves, label, what) in zip(axs, kept):
        sh.curves(ax, t, curves, "rad/s", scale, what=what)
        ax.set_ylabel(label)
    for curves, _, what in panels:
        if all(curves is not k[0] for k in kept):
            sh.note(axs[0], _not_plotted(", ".join(curves), largest(curves), "rad/s", scale,
                                         what))
    legends = time_axes(axs, ts)
    sh.fig.suptitle("Fig. 6 equivalent: rotation rates (grey lines: impacts)")
    return sh.save(out, "fig6_rotation_rates.png", legends)


def axial_velocities_figure(ts, out):
    """Fig. 7: each body's velocity along the docking axis."""
    e3 = _axis(ts)
    sh = Sheet(figsize=(8, 4))
    ax = sh.fig.subplots()
    sh.curves(ax, ts["t"], {n: ts["v_WB"][:, j] @ e3
                            for j, n in enumerate(ts["body_names"].tolist())}, "m/s")
    impact_lines(ax, ts)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("velocity along the docking axis [m/s]")
    sh.fig.suptitle("Fig. 7 equivalent: axial velocities (grey lines: impacts)")
    return sh.save(out, "fig7_axial_velocities.png", [(ax, legend_beside(ax))])


FOCUS = 3                   # couples in Fig. 8
# Impulses below this fraction of the run's largest are within the LZB solver's accuracy
# (1e-8 relative at most, `drake_dock.systems.simulator.tolerances`): not plotted.
IMPULSE_FLOOR = 1e-9
MAX_IMPULSE_LABELS = 8


def strongest_couples(ts, n=FOCUS) -> list:
    """The (up to) ``n`` couples with the largest peak normal force, in the couples' order;
    none for a run without contact force."""
    peak = ts["lambda_n"].max(0, initial=0.0)
    order = [j for j in np.argsort(-peak, kind="stable")[:n] if peak[j] > 0]
    names = ts["couple_names"].tolist()
    return [names[j] for j in sorted(order)]


def ring_distance_force_figure(ts, summary, out, focus):
    """Fig. 8: the ring-centre distance; the normal force of the couples ``focus`` (those with
    the largest forces), each in its own line style (symmetric ones coincide); their impact
    impulses above round-off. Panels without data are not drawn."""
    t = ts["t"]
    cn = ts["couple_names"].tolist()
    idx = [cn.index(c) for c in focus]
    P = ts["impact_normal_impulse"]
    floor = IMPULSE_FLOOR * float(P.max(initial=0.0))
    hit = ts["impact_couples"][:, idx] & (P[:, idx] > floor)
    sh = Sheet(figsize=(13 if idx else 7, 5.5))
    gs = sh.fig.add_gridspec(2, 2 if idx else 1, width_ratios=(1, 1.25) if idx else None)
    a_d = sh.fig.add_subplot(gs[:, 0])
    sh.line(a_d, t, ts["ring_distance"] * 1e3, "ring-centre distance", PALETTE[0])
    a_d.axhline(summary["capture_tolerances"]["axial_m"] * 1e3, color="k", ls="--", lw=0.8,
                label="capture distance")
    if summary["captured"]:
        a_d.axvline(summary["capture_time_s"], color=PALETTE[3], lw=1.0, label="capture")
        sh.add(a_d, "capture", PALETTE[3])
    a_d.set_ylabel("axial ring-centre distance [mm]")
    a_d.set_xlabel("t [s]")
    a_d.legend(loc="lower left", bbox_to_anchor=(0.0, 1.01), ncol=3, fontsize=8,
               borderaxespad=0.0)
    axes, legends = [a_d], []
    if idx:
        a_f = sh.fig.add_subplot(gs[0, 1] if hit.any() else gs[:, 1])
        lam = ts["lambda_n"][:, idx]
        for k, c in enumerate(focus):
            sh.line(a_f, t, lam[:, k], c, PALETTE[k % len(PALETTE)], **STYLES[k % len(STYLES)])
        if len(idx) > 1:
            spread = float(np.max(lam.max(1) - lam.min(1), initial=0.0))
            if negligible(spread, np.abs(lam).max(initial=0.0)):
                sh.note(a_f, f"largest difference between them: {spread:.1e} N (round-off: "
                             f"drawn over each other)")
        a_f.set_ylabel("normal contact force [N]")
        legends.append((a_f, legend_beside(a_f, title="couples")))
        axes.append(a_f)
        if hit.any():
            a_p = sh.fig.add_subplot(gs[1, 1], sharex=a_f)
            legends.append((a_p, _impulses(sh, a_p, ts, focus, idx, hit, floor)))
            a_p.set_ylabel("impact impulse [N s]")
            a_p.set_xlabel("t [s]")
            axes.append(a_p)
        else:
            a_f.set_xlabel("t [s]")
    for ax in axes:
        impact_lines(ax, ts)
    sh.fig.suptitle("Fig. 8 equivalent: ring-centre distance"
                    + ("; contact force and impact impulses of the couples with the largest "
                       "forces" if idx else " (no contact force)"))
    return sh.save(out, "fig8_ring_distance_contact_force.png", legends)


def _impulses(sh, ax, ts, focus, idx, hit, floor):
    """Each couple's normal impulse at each impact above ``floor``, one marker shape per
    couple (nested sizes, so equal impulses stay visible); the largest impulses written beside
    their markers where the labels do not crowd each other."""
    P = ts["impact_normal_impulse"][:, idx]
    t_imp = ts["impact_t"]
    for k, c in enumerate(focus):
        m = hit[:, k]
        if m.any():
            col = PALETTE[k % len(PALETTE)]
            ax.plot(t_imp[m], P[m, k], ls="none", color=col, mfc=col, mec="k",
                    mew=0.5, label=f"{c}", **MARKERS[k % len(MARKERS)])
            sh.add(ax, f"{c} impulse", col)
    ax.set_yscale("log")
    shown = P[hit]
    ax.set_ylim(shown.min() / 3, shown.max() * 4)
    span = max(float(ts["t"][-1] - ts["t"][0]), 1e-12)
    labelled = []
    for m in np.argsort(-np.where(hit, P, 0.0).max(1), kind="stable"):
        if not hit[m].any() or len(labelled) == MAX_IMPULSE_LABELS:
            continue
        value = float(P[m][hit[m]].max())
        crowded = any(abs(t_imp[m] - tl) < 0.06 * span and abs(np.log10(value / vl)) < 0.5
                      for tl, vl in labelled)
        if not crowded:
            ax.annotate(f"{value:.3g}", (t_imp[m], value), textcoords="offset points",
                        xytext=(6, 4), fontsize=7)
            labelled.append((t_imp[m], value))
    dropped = int((ts["impact_couples"][:, idx] & ~hit).sum())
    if dropped:
        sh.note(ax, f"{dropped} impulses below {IMPULSE_FLOOR:g} of the largest not plotted "
                    f"(round-off)")
    return legend_beside(ax, title="impulses")


# A momentum drift below this fraction of its scale is round-off: not plotted.
DRIFT_FLOOR = ROUND_OFF


def momentum_figure(ts, summary, momentum, out):
    """Fig. 9: total linear momentum and angular momentum about a fixed point (the target
    ring's rim at t = 0), each axis showing at least 10 % of its scale (no round-off drawn as
    data); their drift relative to its scale where it exceeds `DRIFT_FLOOR`."""
    t = ts["t"]
    P, L = momentum[:2]
    scales = momentum[2:] if len(momentum) > 2 else (np.abs(P).max(), np.abs(L).max())
    drift = {"linear": np.linalg.norm(P - P[0], axis=1) / scales[0] if scales[0] > 0 else 0 * t,
             "angular": np.linalg.norm(L - L[0], axis=1) / scales[1] if scales[1] > 0 else 0 * t}
    visible = {k: v for k, v in drift.items() if v.max(initial=0.0) > DRIFT_FLOOR}
    sh = Sheet(figsize=(12 + 5 * bool(visible), 4))
    axs = sh.fig.subplots(1, 2 + bool(visible))
    sh.note(axs[1], "about the target ring's rim point at t = 0")
    for ax, (curves, unit, label) in zip(axs, (
            ({f"P_{c}": P[:, k] for k, c in enumerate("xyz")}, "N s", "linear momentum [N s]"),
            ({f"L_{c}": L[:, k] for k, c in enumerate("xyz")}, "N m s",
             "angular momentum [N m s]"))):
        sh.curves(ax, t, curves, unit)
        lo, hi = ax.get_ylim()
        pad = max(0.05 * largest(curves) - 0.5 * (hi - lo), 0.0)
        ax.set_ylim(lo - pad, hi + pad)
        ax.ticklabel_format(axis="y", useOffset=False)
        ax.set_ylabel(label)
    if visible:
        a_d = axs[2]
        for k, (name, v) in enumerate(drift.items()):
            if name in visible:
                shown = np.where(v > DRIFT_FLOOR, v, np.nan)
                sh.line(a_d, t, shown, name, PALETTE[k], marker=".", ms=2, lw=0.8)
        a_d.set_yscale("log")
        a_d.set_ylabel("drift relative to its scale")
    legends = time_axes(axs, ts)
    d = summary["momentum_drift_relative"]
    sh.fig.suptitle(f"Fig. 9 equivalent: momentum (largest drift relative to its scale: "
                    f"linear {drift_text(d['linear'])}, "
                    f"angular {drift_text(d['angular'])})")
    return sh.save(out, "fig9_momentum.png", legends)


def run_figures(ts, summary, momentum, out_dir, pairs=()) -> list:
    """Writes the PNG figures of a run into ``out_dir``; ``momentum`` = (P[N,3], L[N,3], and
    optionally their scales); ``pairs``: the pair specs (for the couples' words and the
    interface loads). Returns the `FigureRecord`s of the figures written: a figure with no
    data (the couples' forces of a run without contact) is not written."""
    focus = strongest_couples(ts)
    records = [rotation_rates_figure(ts, out_dir), axial_velocities_figure(ts, out_dir),
               ring_distance_force_figure(ts, summary, out_dir, focus),
               momentum_figure(ts, summary, momentum, out_dir),
               couple_forces_figure(ts, out_dir, pairs),
               energy_ledger_figure(ts, summary, out_dir),
               interface_loads_figure(ts, pairs, out_dir)]
    return [r for r in records if r is not None]
