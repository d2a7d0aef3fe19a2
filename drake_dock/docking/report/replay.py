"""Meshcat replay of a recorded run: one self-contained HTML page.

The replay is drawn after the simulation from the recorded samples (so a visualiser's publish
events never cut the simulation's steps): a display-only Diagram (plant, SceneGraph,
MeshcatVisualizer) is posed at frame times spaced 1/fps apart in animation time, positions
interpolated linearly between samples (quaternions renormalised): one frame per display frame,
whatever the samples. Animation time is simulation time times ``slow_motion``, by default the
smallest of 1, 2, 5, 10, 20, 50, ... that makes the run last at least `MIN_SCREEN_SECONDS` on
screen (`playback_slowdown`): the capture phase of the paper's example lasts 0.15 s. The page is
titled after the scenario.

The camera looks at the two APDS from the side, from outside the spacecraft hulls with a narrow
field of view, so that the rings fill the view; the hulls are drawn translucent. Given the
run's timeseries, the contact points, force arrows, impact flashes and the time readout of
`drake_dock.docking.report.replay_marks` are added.
"""
from __future__ import annotations

import html
import math

import numpy as np
from pydrake.geometry import Meshcat, MeshcatParams, MeshcatVisualizer
from pydrake.systems.framework import DiagramBuilder

from drake_dock.docking.model.plant import add_docking_plant
from drake_dock.docking.report.replay_marks import add_marks, overlay_html

CAMERA_DISTANCE = 2.8     # m from the rings' midpoint, outside the hulls (radius 1.2 m)
CAMERA_FOV = 26.0         # deg, vertical
HULL_OPACITY = 0.3
FPS = 30.0                # display frames per second of animation time
MIN_SCREEN_SECONDS = 10.0


def playback_slowdown(duration: float, least: float = MIN_SCREEN_SECONDS) -> float:
    """The smallest of 1, 2, 5, 10, 20, 50, ... with ``duration`` times it at least ``least``
    seconds (a run of 0.155 s plays at 1/100 speed, one of 5.2 s at 1/2)."""
    if duration <= 0:
        return 1.0
    decade = 10.0 ** max(0, math.floor(math.log10(max(least / duration, 1.0))))
    for step in (1.0, 2.0, 5.0, 10.0):
        if duration * decade * step >= least:
            return decade * step
    return 10.0 * decade


def make_meshcat() -> Meshcat:
    params = MeshcatParams()
    params.host = "localhost"
    params.port = 0  # any free port; nothing is served beyond this machine
    return Meshcat(params)


def interpolate_positions(t, Q, t_frame, quaternion_starts=()):
    """Q[N, nq] sampled at t[N] (non-decreasing; repeated times allowed: the later sample wins
    from that time on) at the times t_frame; unit quaternions renormalised."""
    t = np.asarray(t)
    out = np.empty((len(t_frame), Q.shape[1]))
    for k, tf in enumerate(t_frame):
        j = int(np.searchsorted(t, tf, side="right"))
        if j <= 0:
            out[k] = Q[0]
            continue
        if j >= len(t):
            out[k] = Q[-1]
            continue
        a, b = j - 1, j
        s = 0.0 if t[b] == t[a] else (tf - t[a]) / (t[b] - t[a])
        out[k] = (1 - s) * Q[a] + s * Q[b]
    for i in quaternion_starts:
        out[:, i:i + 4] /= np.linalg.norm(out[:, i:i + 4], axis=1, keepdims=True)
    return out


def _frame_camera(meshcat, dp, q0, radius):
    """Camera on the midpoint of the two ring centres, from the side of the docking axis,
    raised by 10 degrees, at the distance where the rings (``radius``) fill the view."""
    X = dp.plant.CreateDefaultContext()
    dp.plant.SetPositions(X, q0)
    poses = [f.CalcPoseInWorld(X) for f in dp.apds_frames.values()]
    centre = 0.5 * sum(p.translation() for p in poses)
    axis = poses[0].rotation().matrix()[:, 2]
    side = np.cross(axis, [0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else \
        np.cross(axis, [1.0, -1.0, 0.0])
    side /= np.linalg.norm(side)
    distance = max(CAMERA_DISTANCE, 2.4 * radius / np.tan(np.radians(CAMERA_FOV / 2)) / 2)
    el = np.radians(10.0)
    eye = centre + distance * (np.cos(el) * side + np.sin(el) * axis)
    meshcat.SetCamera(Meshcat.PerspectiveCamera(fov=CAMERA_FOV, near=0.05, far=100.0))
    meshcat.SetCameraPose(eye, centre)
    for body in ("target", "chaser"):
        meshcat.SetProperty(f"/drake/visualizer/{body}/{body}_hull", "modulated_opacity",
                            HULL_OPACITY)


def replay_html(spec, t, Q, *, fps=FPS, slow_motion=None, meshcat=None, ts=None,
                title="scenario") -> str:
    """The HTML page replaying positions Q[N, nq] (the plant's layout) sampled at t[N] on the
    plant and scene of ``spec`` (the run's `DiagramSpec`); with the run's timeseries ``ts``
    (same samples), the contact marks and the time readout.
    ``slow_motion``: animation seconds per simulated second (default `playback_slowdown`);
    ``title``: the scenario's name, the page's title."""
    meshcat = meshcat or make_meshcat()
    builder = DiagramBuilder()
    dp = add_docking_plant(builder, spec.plant)
    MeshcatVisualizer.AddToBuilder(builder, dp.scene_graph, meshcat)
    diagram = builder.Build()
    ctx = diagram.CreateDefaultContext()
    pc = dp.plant.GetMyMutableContextFromRoot(ctx)
    quats = [dp.plant.get_joint(j).position_start() for j in dp.plant.GetJointIndices()
             if dp.plant.get_joint(j).num_positions() == 7]
    t = np.asarray(t, float)
    if slow_motion is None:
        slow_motion = playback_slowdown(float(t[-1] - t[0]))
    n = int(np.floor((t[-1] - t[0]) * slow_motion * fps)) + 1
    t_anim = np.arange(n) / fps
    t_frame = t[0] + t_anim / slow_motion
    Qf = interpolate_positions(t, np.asarray(Q), t_frame, quats)
    meshcat.StartRecording(frames_per_second=fps)
    for ta, q in zip(t_anim, Qf):
        ctx.SetTime(float(ta))
        dp.plant.SetPositions(pc, q)
        diagram.ForcedPublish(ctx)
    _frame_camera(meshcat, dp, Qf[0], spec.scene.geometry.R)
    overlay = ""
    if ts is not None:
        lines = add_marks(meshcat, ts, spec.scene.pairs, t_frame, fps, slow_motion)
        overlay = overlay_html(float(t[0]), fps, slow_motion, lines)
    meshcat.StopRecording()
    meshcat.PublishRecording()
    page = meshcat.StaticHtml()
    page = page.replace("<title>Drake MeshCat</title>",
                        f"<title>{html.escape(title)}: drake_dock replay</title>", 1)
    at = page.rfind("</body>")
    return page[:at] + overlay + page[at:] if at >= 0 else page + overlay
