"""Meshcat replay of a recorded run: one self-contained HTML page.

The replay is drawn after the simulation from the recorded samples (so a visualiser's publish
events never cut the simulation's steps): a display-only Diagram (plant, SceneGraph,
MeshcatVisualizer) is posed at frame times spaced 1/fps apart in animation time, positions
interpolated linearly between samples (quaternions renormalised). Animation time is simulation
time times ``slow_motion``: the capture phase lasts a fraction of a second.
"""
from __future__ import annotations

import numpy as np
from pydrake.geometry import Meshcat, MeshcatParams, MeshcatVisualizer
from pydrake.systems.framework import DiagramBuilder

from drake_dock.docking.plant import add_docking_plant


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


def replay_html(scenario, t, Q, *, fps=30.0, slow_motion=10.0, meshcat=None) -> str:
    """The HTML page replaying positions Q[N, nq] (the plant's layout) sampled at t[N]."""
    meshcat = meshcat or make_meshcat()
    builder = DiagramBuilder()
    dp = add_docking_plant(builder, scenario)
    MeshcatVisualizer.AddToBuilder(builder, dp.scene_graph, meshcat)
    diagram = builder.Build()
    ctx = diagram.CreateDefaultContext()
    pc = dp.plant.GetMyMutableContextFromRoot(ctx)
    quats = [dp.plant.get_joint(j).position_start() for j in dp.plant.GetJointIndices()
             if dp.plant.get_joint(j).num_positions() == 7]
    t = np.asarray(t, float)
    n = int(np.floor((t[-1] - t[0]) * slow_motion * fps)) + 1
    t_anim = np.arange(n) / fps
    Qf = interpolate_positions(t, np.asarray(Q), t[0] + t_anim / slow_motion, quats)
    # Look at the two rings from the side, close enough to see the petals slide.
    X = dp.plant.CreateDefaultContext()
    dp.plant.SetPositions(X, Qf[0])
    centre = 0.5 * sum(f.CalcPoseInWorld(X).translation() for f in dp.apds_frames.values())
    meshcat.SetCameraPose(centre + np.array([1.3, -1.3, 0.5]), centre)
    meshcat.StartRecording(frames_per_second=fps)
    for ta, q in zip(t_anim, Qf):
        ctx.SetTime(float(ta))
        dp.plant.SetPositions(pc, q)
        diagram.ForcedPublish(ctx)
    meshcat.StopRecording()
    meshcat.PublishRecording()
    return meshcat.StaticHtml()
