"""The run figures: the equivalents of the paper's Figs. 6-9 (this module), every couple that
came into contact, the energy ledger and the interface loads (`ledger_figures`). Grey vertical
lines mark the impacts. `run_figures` returns a `FigureRecord` per file (the series drawn in
each axes, `drake_dock.docking.figure_kit`)."""
from __future__ import annotations

import numpy as np

from drake_dock.docking.figure_kit import (PALETTE, Sheet, impact_lines, legend_beside,
                                           negligible, time_axes)
from drake_dock.docking.ledger_figures import (couple_forces_figure, energy_ledger_figure,
                                               interface_loads_figure)
from drake_dock.core.patches import posed
from drake_dock.docking.apds import apds_patches
from drake_dock.docking.results import relative_text

# The symmetric couples of Fig. 8 drawn over each other: wide light solid, dashed, thin dotted.
STYLES = (dict(lw=6.0, alpha=0.55, ls="-"), dict(lw=2.8, ls=(0, (5, 3))),
          dict(lw=1.3, ls=(0, (1, 1.5))))
MARKERS = (dict(marker="o", ms=12), dict(marker="s", ms=8), dict(marker="^", ms=5))


def _axis(ts):
    """The docking axis at t = 0 (target APDS e3), fixed in the world."""
    return ts["R_WA"][0, 0][:, 2]


def rotation_rates_figure(ts, out):
    """Fig. 6: each body's rotation rate about the docking axis and transverse to it."""
    t, e3 = ts["t"], _axis(ts)
    names = ts["body_names"].tolist()
    w = ts["w_WB"]
    axial = {n: w[:, j] @ e3 for j, n in enumerate(names)}
    transverse = {n: np.linalg.norm(w[:, j] - np.outer(axial[n], e3), axis=1)
                  for j, n in enumerate(names)}
    scale = float(np.abs(w).max(initial=0.0))
    sh = Sheet(figsize=(12, 4))
    axs = sh.fig.subplots(1, 2)
    sh.curves(axs[0], t, axial, "rad/s", scale)
    sh.curves(axs[1], t, transverse, "rad/s", scale)
    axs[0].set_ylabel("rate about the docking axis [rad/s]")
    axs[1].set_ylabel("transverse rate [rad/s]")
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


def ring_distance_force_figure(ts, summary, out, focus):
    """Fig. 8: the ring-centre distance; the normal force of the couples that close first,
    each in its own line style (the symmetric ones coincide); their impact impulses."""
    t = ts["t"]
    sh = Sheet(figsize=(13, 5.5))
    gs = sh.fig.add_gridspec(2, 2, width_ratios=(1, 1.25))
    a_d = sh.fig.add_subplot(gs[:, 0])
    a_f = sh.fig.add_subplot(gs[0, 1])
    a_p = sh.fig.add_subplot(gs[1, 1], sharex=a_f)
    sh.line(a_d, t, ts["ring_distance"] * 1e3, "ring-centre distance", PALETTE[0])
    a_d.axhline(summary["capture_tolerances"]["axial_m"] * 1e3, color="k", ls="--", lw=0.8,
                label="capture distance")
    if summary["captured"]:
        a_d.axvline(summary["capture_time_s"], color=PALETTE[3], lw=1.0, label="capture")
        sh.add(a_d, "capture", PALETTE[3])
    a_d.set_ylabel("axial ring-centre distance [mm]")
    a_d.legend(loc="lower left", bbox_to_anchor=(0.0, 1.01), ncol=3, fontsize=8,
               borderaxespad=0.0)
    cn = ts["couple_names"].tolist()
    idx = [cn.index(c) for c in focus]
    lam = ts["lambda_n"][:, idx]
    for k, (c, j) in enumerate(zip(focus, idx)):
        sh.line(a_f, t, lam[:, k], c, PALETTE[k % len(PALETTE)], **STYLES[k % len(STYLES)])
    if len(idx) > 1:
        spread = float(np.max(lam.max(1) - lam.min(1), initial=0.0))
        same = negligible(spread, np.abs(lam).max(initial=0.0)) or spread == 0.0
        sh.note(a_f, f"largest difference between them: {spread:.1e} N"
                     + (" (equal to round-off: drawn over each other)" if same else ""))
    a_f.set_ylabel("normal contact force [N]")
    legends = [(a_f, legend_beside(a_f, title="couples"))]
    legends.append((a_p, _impulses(sh, a_p, ts, focus, idx)))
    a_p.set_ylabel("impact impulse [N s]")
    for ax in (a_d, a_f, a_p):
        impact_lines(ax, ts)
    a_d.set_xlabel("t [s]")
    a_p.set_xlabel("t [s]")
    sh.fig.suptitle("Fig. 8 equivalent: ring-centre distance; contact force and impact impulses "
                    "of the couples that close first")
    return sh.save(out, "fig8_ring_distance_contact_force.png", legends)


def _impulses(sh, ax, ts, focus, idx):
    """Each couple's normal impulse at each impact, one marker shape per couple (nested sizes,
    so equal impulses stay visible); the value of each impact written beside it."""
    P = ts["impact_normal_impulse"][:, idx]
    hit = ts["impact_couples"][:, idx]
    for k, c in enumerate(focus):
        m = hit[:, k]
        if m.any():
            col = PALETTE[k % len(PALETTE)]
            ax.plot(ts["impact_t"][m], P[m, k], ls="none", color=col, mfc=col, mec="k",
                    mew=0.5, label=f"{c}", **MARKERS[k % len(MARKERS)])
            sh.add(ax, f"{c} impulse", col)
    for m, tm in enumerate(ts["impact_t"]):
        if hit[m].any():
            ax.annotate(f"{P[m][hit[m]].max():.3g}", (tm, P[m][hit[m]].max()),
                        textcoords="offset points", xytext=(6, 4), fontsize=7)
    if not hit.any():
        sh.note(ax, "no impact on these couples")
        return None
    positive = P[hit][P[hit] > 0]
    if positive.size:
        ax.set_yscale("log")
        ax.set_ylim(positive.min() / 3, positive.max() * 4)
    return legend_beside(ax, title="impulses")


def momentum_figure(ts, summary, momentum, out):
    """Fig. 9: total linear momentum and angular momentum about a fixed point (the target
    ring's rim at t = 0), with their drift."""
    t = ts["t"]
    P, L = momentum
    sh = Sheet(figsize=(12, 4))
    axs = sh.fig.subplots(1, 2)
    sh.note(axs[1], "about the target ring's rim point at t = 0")
    sh.curves(axs[0], t, {f"P_{c}": P[:, k] for k, c in enumerate("xyz")}, "N s")
    sh.curves(axs[1], t, {f"L_{c}": L[:, k] for k, c in enumerate("xyz")}, "N m s")
    axs[0].set_ylabel("linear momentum [N s]")
    axs[1].set_ylabel("angular momentum [N m s]")
    legends = time_axes(axs, ts)
    d = summary["momentum_drift_relative"]
    sh.fig.suptitle(f"Fig. 9 equivalent: momentum (largest drift relative to its scale: "
                    f"linear {relative_text(d['linear'], '.1e')}, "
                    f"angular {relative_text(d['angular'], '.1e')})")
    return sh.save(out, "fig9_momentum.png", legends)


def _draw_apds(sh, ax, g, R, p, color, label):
    P = apds_patches(g)
    s = np.linspace(0, 1, 9)
    z = np.linspace(0, g.H, 7)
    for surf in P.surfaces.values():
        W = posed(surf, R, p)
        S, Z = np.meshgrid(s, z, indexing="ij")
        X = W.position(np.stack([S, Z], -1))
        ax.plot_wireframe(X[..., 0], X[..., 1], X[..., 2], color=color, lw=0.4, alpha=0.6)
    for i, side in P.sides.items():
        W = posed(side, R, p)
        X = W.position(np.linspace(side.lower[0], side.upper[0], 30)[:, None])
        ax.plot(X[:, 0], X[:, 1], X[:, 2], color=color, lw=1.5)
        ax.text(*X[-1], f"n{i}", color=color, fontsize=7)
    th = np.linspace(0, 2 * np.pi, 200)[:, None]
    for r in (g.Rs, g.R):
        X = (np.concatenate([r * np.cos(th), r * np.sin(th), 0 * th], 1)) @ R.T + p
        ax.plot(X[:, 0], X[:, 1], X[:, 2], color=color, lw=1.0,
                label=label if r == g.R else None)
    sh.add(ax, label, color)


def initial_configuration_figure(g, poses, couples, out_dir, name="initial_configuration.png"):
    """The two APDSes in their initial poses with the closest couples of the closing pairs
    (black): a perspective view and an orthographic side view along the world x axis."""
    sh = Sheet(figsize=(12, 5.5))
    for n, (elev, azim) in enumerate(((25, -60), (0, 0))):
        ax = sh.fig.add_subplot(1, 2, n + 1, projection="3d",
                                proj_type="persp" if n == 0 else "ortho")
        _draw_apds(sh, ax, g, *poses["target_apds"], PALETTE[0], "target APDS")
        _draw_apds(sh, ax, g, *poses["chaser_apds"], PALETTE[1], "chaser APDS")
        for cp in couples.values():
            seg = np.stack([cp.p1, cp.p2])
            ax.plot(seg[:, 0], seg[:, 1], seg[:, 2], "k-", lw=2)
            ax.scatter(*cp.p1, color="k", s=8)
        ax.view_init(elev=elev, azim=azim)
        ax.set_box_aspect((1, 1, 0.6))
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        if n == 0:
            ax.set_xlabel("x [m]")
            sh.fig.legend(loc="upper left", fontsize=8)
        else:           # x points at the viewer: its ticks would fall on one spot
            ax.set_xticks([])
            sh.note(ax, "side view (along x)")
    sh.fig.suptitle("Initial configuration; black: couples of the pairs that close first")
    return sh.save(out_dir, name)


def run_figures(ts, summary, momentum, out_dir, focus_couples=(), pairs=()) -> list:
    """Writes the PNG figures of a run into ``out_dir``; ``momentum`` = (P[N,3], L[N,3]);
    ``pairs``: the pair specs (for the interface loads). Returns their `FigureRecord`s."""
    focus = list(focus_couples) or ts["couple_names"].tolist()[:3]
    return [rotation_rates_figure(ts, out_dir), axial_velocities_figure(ts, out_dir),
            ring_distance_force_figure(ts, summary, out_dir, focus),
            momentum_figure(ts, summary, momentum, out_dir),
            couple_forces_figure(ts, out_dir), energy_ledger_figure(ts, summary, out_dir),
            interface_loads_figure(ts, pairs, out_dir)]
