"""Figures (matplotlib, Agg backend)."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drake_dock.core.patches import posed  # noqa: E402
from drake_dock.docking.apds import apds_patches  # noqa: E402
from drake_dock.docking.results import relative_text  # noqa: E402


def _draw_apds(ax, g, R, p, color, label):
    P = apds_patches(g)
    s = np.linspace(0, 1, 9)
    z = np.linspace(0, g.H, 7)
    for k, surf in P.surfaces.items():
        W = posed(surf, R, p)
        S, Z = np.meshgrid(s, z, indexing="ij")
        X = W.position(np.stack([S, Z], -1))
        ax.plot_wireframe(X[..., 0], X[..., 1], X[..., 2], color=color, lw=0.4, alpha=0.6)
    for i, side in P.sides.items():
        W = posed(side, R, p)
        u = np.linspace(side.lower[0], side.upper[0], 30)[:, None]
        X = W.position(u)
        ax.plot(X[:, 0], X[:, 1], X[:, 2], color=color, lw=1.5)
        ax.text(*X[-1], f"n{i}", color=color, fontsize=7)
    th = np.linspace(0, 2 * np.pi, 200)[:, None]
    for r in (g.Rs, g.R):
        X = (np.concatenate([r * np.cos(th), r * np.sin(th), 0 * th], 1)) @ R.T + p
        ax.plot(X[:, 0], X[:, 1], X[:, 2], color=color, lw=1.0,
                label=label if r == g.R else None)


def initial_configuration_figure(g, poses, couples, path):
    """Two APDSes in their initial poses with the closest couples of the closing pairs."""
    fig = plt.figure(figsize=(11, 5.2))
    for n, (elev, azim) in enumerate(((25, -60), (0, 0))):
        ax = fig.add_subplot(1, 2, n + 1, projection="3d")
        _draw_apds(ax, g, *poses["target_apds"], "tab:blue", "target APDS")
        _draw_apds(ax, g, *poses["chaser_apds"], "tab:orange", "chaser APDS")
        for name, cp in couples.items():
            seg = np.stack([cp.p1, cp.p2])
            ax.plot(seg[:, 0], seg[:, 1], seg[:, 2], "k-", lw=2)
            ax.scatter(*cp.p1, color="k", s=8)
        ax.view_init(elev=elev, azim=azim)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        ax.set_box_aspect((1, 1, 0.6))
        if n == 0:
            ax.legend(loc="upper left", fontsize=8)
    fig.suptitle("Initial configuration; black: couples of the pairs that close first")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# Run figures (the equivalents of the paper's Figs. 6-9) -------------------------------------
def _axis(ts):
    """The docking axis at t = 0 (target APDS e3), fixed in the world."""
    return ts["R_WA"][0, 0][:, 2]


def _impact_lines(ax, ts):
    for t in ts["impact_t"]:
        ax.axvline(t, color="0.8", lw=0.6, zorder=0)


def run_figures(ts, summary, momentum, out_dir, focus_couples=()):
    """Writes the PNG figures of a run into ``out_dir``; ``momentum`` = (P[N,3], L[N,3]).
    Returns the file names."""
    from pathlib import Path
    out = Path(out_dir)
    t = ts["t"]
    e3 = _axis(ts)
    names = ts["body_names"].tolist()
    files = []

    def save(fig, name):
        fig.tight_layout()
        fig.savefig(out / name, dpi=100)
        plt.close(fig)
        files.append(name)

    # Fig. 6: rotation rates about the docking axis, and transverse.
    fig, axs = plt.subplots(1, 2, figsize=(11, 4))
    for j, n in enumerate(names):
        w = ts["w_WB"][:, j]
        axs[0].plot(t, w @ e3, label=n)
        axs[1].plot(t, np.linalg.norm(w - np.outer(w @ e3, e3), axis=1), label=n)
    axs[0].set_ylabel("rotation rate about the docking axis [rad/s]")
    axs[1].set_ylabel("transverse rotation rate [rad/s]")
    for ax in axs:
        _impact_lines(ax, ts)
        ax.set_xlabel("t [s]")
        ax.legend(fontsize=8)
    fig.suptitle("Fig. 6 equivalent: rotation rates (grey lines: impacts)")
    save(fig, "fig6_rotation_rates.png")

    # Fig. 7: axial velocities.
    fig, ax = plt.subplots(figsize=(7, 4))
    for j, n in enumerate(names):
        ax.plot(t, ts["v_WB"][:, j] @ e3, label=n)
    _impact_lines(ax, ts)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("velocity along the docking axis [m/s]")
    ax.legend(fontsize=8)
    ax.set_title("Fig. 7 equivalent: axial velocities")
    save(fig, "fig7_axial_velocities.png")

    # Fig. 8: ring-centre distance and the contact force of the first couples.
    fig, axs = plt.subplots(1, 2, figsize=(11, 4))
    axs[0].plot(t, ts["ring_distance"] * 1e3)
    axs[0].axhline(summary["capture_distance_m"] * 1e3, color="k", ls="--", lw=0.8,
                   label="capture distance")
    if summary["captured"]:
        axs[0].axvline(summary["capture_time_s"], color="tab:red", lw=0.8, label="capture")
    axs[0].set_ylabel("axial ring-centre distance [mm]")
    axs[0].legend(fontsize=8)
    cn = ts["couple_names"].tolist()
    focus = list(focus_couples) or cn[:3]
    for c in focus:
        j = cn.index(c)
        axs[1].plot(t, ts["lambda_n"][:, j], label=f"{c} lambda_n")
        m = ts["impact_couples"][:, j]
        if m.any():
            axs[1].plot(ts["impact_t"][m], ts["impact_normal_impulse"][m, j] * 0, "v",
                        label=f"{c} impacts ({', '.join(f'{p:.3g}' for p in ts['impact_normal_impulse'][m, j][:3])} N s)")
    axs[1].set_ylabel("normal contact force [N]")
    axs[1].legend(fontsize=7)
    for ax in axs:
        _impact_lines(ax, ts)
        ax.set_xlabel("t [s]")
    fig.suptitle("Fig. 8 equivalent: ring-centre distance; contact force of the first couples")
    save(fig, "fig8_ring_distance_contact_force.png")

    # Fig. 9: momentum and angular momentum.
    fig, axs = plt.subplots(1, 2, figsize=(11, 4))
    P, L = momentum
    for k, c in enumerate("xyz"):
        axs[0].plot(t, P[:, k], label=f"P_{c}")
        axs[1].plot(t, L[:, k], label=f"L_{c}")
    axs[0].set_ylabel("total linear momentum [N s]")
    axs[1].set_ylabel("total angular momentum about the ring rim point [N m s]")
    for ax in axs:
        _impact_lines(ax, ts)
        ax.set_xlabel("t [s]")
        ax.legend(fontsize=8)
    d = summary["momentum_drift_relative"]
    fig.suptitle(f"Fig. 9 equivalent: momentum (relative drift "
                 f"{relative_text(d['linear'], '.1e')}, "
                 f"angular {relative_text(d['angular'], '.1e')})")
    save(fig, "fig9_momentum.png")

    # All couples' forces.
    n = len(cn)
    fig, axs = plt.subplots(int(np.ceil(n / 3)), 3, figsize=(12, 2.2 * np.ceil(n / 3)),
                            sharex=True, squeeze=False)
    for j, c in enumerate(cn):
        ax = axs.flat[j]
        ax.plot(t, ts["lambda_n"][:, j], label="lambda_n")
        ax.plot(t, np.linalg.norm(ts["lambda_t"][:, j], axis=1), label="|lambda_t|")
        act = ts["active"][:, j]
        ax.set_title(f"{c} (tracked {act.mean():.0%} of samples, "
                     f"{int(ts['impact_couples'][:, j].sum())} impacts)", fontsize=8)
        _impact_lines(ax, ts)
    axs.flat[0].legend(fontsize=7)
    for ax in axs[-1]:
        ax.set_xlabel("t [s]")
    fig.suptitle("Contact forces of all couples [N]")
    save(fig, "couple_forces.png")

    # Energy ledger.
    E = dict(zip(ts["energy_names"].tolist(), ts["energy"].T))
    terms = {"kinetic": E["kinetic"], "Stewart potential": E["potential"],
             "damper": -E["stewart_damper_work"], "friction": E["friction_loss"],
             "impacts": E["impact_loss"]}
    fig, axs = plt.subplots(1, 2, figsize=(11, 4))
    axs[0].stackplot(t, *terms.values(), labels=list(terms))
    axs[0].set_ylabel("energy [J]")
    axs[0].legend(fontsize=8, loc="lower left")
    total0 = E["kinetic"][0] + E["potential"][0]
    resid = sum(terms.values()) - E["input_work"] - total0
    axs[1].plot(t, resid / total0)
    axs[1].set_ylabel("ledger residual / initial energy")
    for ax in axs:
        ax.set_xlabel("t [s]")
    closure = summary["energy_ledger"]["closure_error_relative"]
    fig.suptitle(f"Energy ledger (closure {relative_text(closure, '.1e')})")
    save(fig, "energy_ledger.png")
    return files
