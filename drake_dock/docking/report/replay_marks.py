"""What the replay shows besides the bodies: at each couple in contact a point and an arrow of
the contact force on the chaser APDS (length proportional to the force, `ARROW_MAX` at the
run's peak), a flash at the couples of each impact, and a readout of the simulation time and
of the contact state (an HTML overlay that follows the animation's clock).

The marks are animated in the meshcat recording, frame k showing the state at simulation time
t0 + k / (fps slow_motion). Only the couples in contact at some frame, or flashed by an impact,
get marks; a visibility is written when it changes, a pose or scale only while visible (the
recording stays small: a few megabytes for a run of seconds). The readout holds the last
frame's time when the animation has ended.
"""
from __future__ import annotations

import json

import numpy as np
from pydrake.geometry import Cylinder, MeshcatCone, Rgba, Sphere
from pydrake.math import RigidTransform, RollPitchYaw

from drake_dock.docking.report.loads import couple_forces_W
from drake_dock.docking.report.results import IN_CONTACT

ROOT = "/contact"
ARROW_MAX = 0.25                 # m: the arrow of the run's largest contact force
ARROW_MIN = 0.04                 # m: the shortest arrow drawn
ARROW_RGBA = Rgba(0.1, 0.85, 0.1, 1.0)
POINT_RGBA = Rgba(1.0, 0.9, 0.0, 1.0)
FLASH_RGBA = Rgba(1.0, 0.0, 1.0, 0.6)
FLASH_SECONDS = 0.25             # animation seconds an impact stays flashed
CHASER = "chaser_apds"


def frame_samples(t, t_frame):
    """For each frame time, the index of the sample shown (the latest at or before it)."""
    return np.clip(np.searchsorted(np.asarray(t), t_frame, side="right") - 1, 0, len(t) - 1)


def _along(f):
    """A pose whose z axis is along the unit vector f."""
    z = f / np.linalg.norm(f)
    pitch = np.arccos(np.clip(z[2], -1.0, 1.0))
    yaw = np.arctan2(z[1], z[0])
    # R = Rz(yaw) Ry(pitch) takes e_z to (cos yaw sin pitch, sin yaw sin pitch, cos pitch).
    return RollPitchYaw(0.0, pitch, yaw)


def chaser_forces(ts, pairs) -> np.ndarray:
    """Each couple's contact force on the chaser APDS [N, n_couples, 3] (world frame)."""
    body1 = {p.name: p.body1 == CHASER for p in pairs}
    sign = np.array([1.0 if body1[c] else -1.0 for c in ts["couple_names"].tolist()])
    return couple_forces_W(ts) * sign[None, :, None]


def add_marks(meshcat, ts, pairs, t_frame, fps, slow_motion):
    """Declares the marks and animates them in ``meshcat``'s current recording; returns the
    per-frame readout lines."""
    anim = meshcat.get_mutable_recording()
    names = ts["couple_names"].tolist()
    k_of = frame_samples(ts["t"], t_frame)
    status = ts["status"][k_of]
    f = chaser_forces(ts, pairs)[k_of]
    mag = np.linalg.norm(f, axis=-1)
    peak = float(mag.max(initial=0.0)) or 1.0
    points = ts["p1_W"][k_of]       # the couple's point on body 1 (= on body 2 in contact)
    flash = _flash_frames(ts, t_frame, fps, slow_motion)
    touching = status >= IN_CONTACT
    pushing = touching & (mag > 0.0)
    for j in np.flatnonzero(touching.any(0) | flash.any(0)):
        c = names[j]
        base = f"{ROOT}/{c}"
        meshcat.SetObject(f"{base}/point", Sphere(0.012), POINT_RGBA)
        meshcat.SetObject(f"{base}/arrow/shaft", Cylinder(0.006, 0.8), ARROW_RGBA)
        meshcat.SetTransform(f"{base}/arrow/shaft", RigidTransform([0, 0, 0.4]))
        meshcat.SetObject(f"{base}/arrow/head", MeshcatCone(0.2, 0.03, 0.03), ARROW_RGBA)
        meshcat.SetTransform(f"{base}/arrow/head",
                             RigidTransform(RollPitchYaw(np.pi, 0, 0), [0, 0, 1.0]))
        meshcat.SetObject(f"{base}/flash", Sphere(0.05), FLASH_RGBA)
        for name, shown in (("point", touching[:, j]), ("flash", flash[:, j]),
                            ("arrow", pushing[:, j])):
            path = f"{base}/{name}"
            for k in range(len(t_frame)):
                if k == 0 or shown[k] != shown[k - 1]:
                    anim.SetProperty(k, path, "visible", bool(shown[k]))
                if not shown[k]:
                    continue
                if name != "arrow":
                    anim.SetTransform(k, path, RigidTransform(points[k, j]))
                    continue
                length = ARROW_MIN + (ARROW_MAX - ARROW_MIN) * mag[k, j] / peak
                anim.SetTransform(k, path, RigidTransform(_along(f[k, j]), points[k, j]))
                anim.SetProperty(k, path, "scale", [1.0, 1.0, float(length)])
    return _readout_lines(ts, status, mag, flash, names)


def _flash_frames(ts, t_frame, fps, slow_motion):
    """flash[frame, couple]: the couple took part in an impact less than FLASH_SECONDS of
    animation time before the frame."""
    flash = np.zeros((len(t_frame), len(ts["couple_names"])), bool)
    window = FLASH_SECONDS / slow_motion
    for tm, who in zip(ts["impact_t"], ts["impact_couples"]):
        on = (t_frame >= tm - 0.5 / (fps * slow_motion)) & (t_frame < tm + window)
        flash[np.ix_(on, who)] = True
    return flash


def marked_couples(ts, t_frame, fps, slow_motion) -> list:
    """The couples that get marks: in contact at some frame or flashed by an impact."""
    status = ts["status"][frame_samples(ts["t"], t_frame)]
    flash = _flash_frames(ts, t_frame, fps, slow_motion)
    names = ts["couple_names"].tolist()
    return [names[j] for j in np.flatnonzero((status >= IN_CONTACT).any(0) | flash.any(0))]


def _readout_lines(ts, status, mag, flash, names):
    lines = []
    for k in range(len(status)):
        touching = np.flatnonzero(status[k] >= IN_CONTACT)
        sliding = int((status[k] == IN_CONTACT).sum())
        text = (f"in contact: {len(touching)} couple{'s' if len(touching) != 1 else ''}"
                + (f" ({sliding} sliding), total force {mag[k].sum():.4g} N" if len(touching)
                   else ""))
        if flash[k].any():
            text += " | IMPACT at " + ", ".join(names[j] for j in np.flatnonzero(flash[k]))
        lines.append(text)
    return lines


def overlay_html(t0, fps, slow_motion, lines) -> str:
    """The time readout: a fixed box over the viewer showing the simulation time of the frame
    on screen (from the animation actions' clock) and the contact state of that frame."""
    data = json.dumps({"t0": t0, "fps": fps, "slow": slow_motion, "lines": lines})
    return f"""
<div id="time-readout" data-slow="{slow_motion:g}" style="position:fixed; left:12px;
  bottom:12px; z-index:10; font:14px monospace; background:rgba(255,255,255,0.85);
  padding:6px 10px; border-radius:4px; color:#111">t = -</div>
<script>
(function() {{
  const R = {data};
  const box = document.getElementById("time-readout");
  function tick() {{
    const a = (typeof viewer !== "undefined" && viewer.animator) ? viewer.animator : null;
    let ta = 0.0;
    if (a && a.actions.length) ta = Math.max(...a.actions.map(x => x.time));
    // At the end meshcat rewinds the actions but leaves the last frame on screen and its
    // time on the animator's scrubber (a.time): hold it.
    if (a && ta === 0.0 && !a.playing && a.time > 0) ta = a.time;
    const k = Math.min(R.lines.length - 1, Math.max(0, Math.round(ta * R.fps)));
    const t = R.t0 + ta / R.slow;
    box.textContent = "t = " + t.toFixed(4) + " s (" + (R.slow === 1 ? "real time" : "1/" +
      R.slow + " speed") + ")  " + R.lines[k];
    box.dataset.time = t.toString();
    requestAnimationFrame(tick);
  }}
  requestAnimationFrame(tick);
}})();
</script>
"""
