"""Figures (matplotlib, Agg backend)."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drake_dock.core.patches import posed  # noqa: E402
from drake_dock.docking.apds import apds_patches  # noqa: E402


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
