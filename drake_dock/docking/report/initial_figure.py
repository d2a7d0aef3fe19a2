"""The initial configuration of a run: the two APDS at t = 0 in the target APDS frame, seen
along y and along x to scale, with the chaser ring centre's offset and its docking axis's tilt
written above each view, and the closest couples of the pairs that close first."""
from __future__ import annotations

import numpy as np

from drake_dock.core.patches import posed
from drake_dock.docking.report.figure_kit import PALETTE, Sheet

# The two side views of the initial configuration: (horizontal, vertical) axes of the target
# APDS frame, and the axis the view looks along.
VIEWS = ((0, 2, "y"), (1, 2, "x"))


def _apds_lines(scene, R, p):
    """Polylines [(points [n, 3], kind)] of an APDS of the scene (a `DockingScene`: its
    geometry and patches) posed at (R, p): ring circles, guide sides and a wireframe of the
    guide surfaces."""
    g, P = scene.geometry, scene.patches
    lines = []
    for surf in P.surfaces.values():
        W = posed(surf, R, p)
        for z in np.linspace(0, g.H, 4):
            lines.append((W.position(np.stack([np.linspace(0, 1, 15), np.full(15, z)], -1)),
                          "surface"))
    for side in P.sides.values():
        W = posed(side, R, p)
        lines.append((W.position(np.linspace(side.lower[0], side.upper[0], 30)[:, None]),
                      "side"))
    th = np.linspace(0, 2 * np.pi, 200)[:, None]
    for r in (g.Rs, g.R):
        lines.append(((np.concatenate([r * np.cos(th), r * np.sin(th), 0 * th], 1)) @ R.T + p,
                      "ring"))
    return lines


STYLE = {"surface": dict(lw=0.4, alpha=0.5), "side": dict(lw=1.4), "ring": dict(lw=1.2)}


def initial_pose_offsets(poses) -> dict:
    """The chaser ring's centre and docking axis in the target APDS frame at t = 0: its offset
    (m) and the tilt of its axis (deg) in each view's plane (x-z: the tilt about y; y-z: about
    x)."""
    R_t, p_t = poses["target_apds"]
    R_c, p_c = poses["chaser_apds"]
    d = R_t.T @ (np.asarray(p_c) - p_t)
    a = R_t.T @ -np.asarray(R_c)[:, 2]      # the chaser's axis reversed: along z when aligned
    return {"offset_m": d, "axis": a,
            "tilt_xz_deg": float(np.degrees(np.arctan2(a[0], a[2]))),
            "tilt_yz_deg": float(np.degrees(np.arctan2(a[1], a[2])))}


def initial_configuration_figure(scene, poses, couples, out_dir,
                                 name="initial_configuration.png"):
    """The two APDSes of the run's ``scene`` (a `DockingScene`) at t = 0 in the target APDS frame
    (z: the docking axis), seen along y
    (the x offset and the tilt in the x-z plane) and along x (y offset, tilt in y-z), to scale;
    both docking axes dashed; the closest couples of the pairs that close first in black."""
    R0, p0 = poses["target_apds"]
    local = {n: (R0.T @ R, R0.T @ (p - p0)) for n, (R, p) in poses.items()}
    lines = {n: _apds_lines(scene, *local[n]) for n in local}
    geo = initial_pose_offsets(poses)
    d = geo["offset_m"]
    sh = Sheet(figsize=(13, 3.6))
    axs = sh.fig.subplots(1, 2)
    drawn = (("target_apds", PALETTE[0], "target APDS"), ("chaser_apds", PALETTE[1],
                                                           "chaser APDS"))
    for ax, (h, v, along) in zip(axs, VIEWS):
        for n, col, label in drawn:
            for pts, kind in lines[n]:
                ax.plot(pts[:, h], pts[:, v], color=col, **STYLE[kind])
            sh.add(ax, label, col)
        ax.plot([], [], color=PALETTE[0], label="target APDS")
        ax.plot([], [], color=PALETTE[1], label="chaser APDS")
        reach = 0.3 + d[2]
        ax.plot([0, 0], [-0.05, reach], "k--", lw=0.8, label="docking axes")
        a = geo["axis"]
        s = np.array([-0.05 - d[2], 0.3]) / max(a[2], 1e-9)
        ax.plot(d[h] + s * a[h], d[v] + s * a[v], "k--", lw=0.8)
        for cp in couples.values():
            q1, q2 = (R0.T @ (np.asarray(x) - p0) for x in (cp.p1, cp.p2))
            ax.plot([q1[h], q2[h]], [q1[v], q2[v]], "k-", lw=2)
            ax.plot(q1[h], q1[v], "ko", ms=4)
        if couples:
            ax.plot([], [], "ko-", ms=4, label="first couples")
        tilt = geo["tilt_xz_deg"] if along == "y" else geo["tilt_yz_deg"]
        axis_h = "xyz"[h]
        sh.note(ax, f"seen along {along}: chaser ring centre {axis_h} = "
                    f"{round(1e3 * d[h], 1) + 0.0:+.1f} mm, z = {1e3 * d[2]:.1f} mm;\n"
                    f"chaser docking axis tilted {round(tilt, 2) + 0.0:+.2f} deg in the "
                    f"{axis_h}-z plane")
        top = max(pts[:, 2].max() for n in local for pts, _ in lines[n])
        ax.set_xlim(-1.25 * scene.geometry.R, 1.25 * scene.geometry.R)
        ax.set_ylim(-0.08, top + 0.08)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel(f"{axis_h} [m] (target APDS frame)")
        ax.set_ylabel("z [m] (docking axis)")
    legend = axs[1].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8,
                           borderaxespad=0.0)
    sh.fig.suptitle("Initial configuration (t = 0), two side views to scale")
    return sh.save(out_dir, name, [(axs[1], legend)])
