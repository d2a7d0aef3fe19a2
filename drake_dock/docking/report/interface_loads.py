"""Interface loads: what the contact transmits to the target's APDS, and the Stewart stroke.

From the timeseries (`drake_dock.docking.report.results`): each couple in contact pushes its body 1
with f = lambda_n n + lambda_t[0] ta + lambda_t[1] tb at p1 and its body 2 with -f at p2
(`drake_dock.core.couple`: n from body 2 to body 1). The loads on the target APDS are the sum of
its share, as a force and a moment about the target ring's centre, both expressed in the
target APDS frame (z: the docking axis). Impulses are not in these forces (they are in the
impact arrays).
"""
from __future__ import annotations

import numpy as np

TARGET = "target_apds"


def couple_forces_W(ts: dict) -> np.ndarray:
    """f[N, n_couples, 3]: each couple's force on its body 1, world frame."""
    F = ts["frame_W"]
    lam = np.concatenate([ts["lambda_t"], ts["lambda_n"][..., None]], axis=-1)
    return np.einsum("nkij,nkj->nki", F, lam)


def interface_loads(ts: dict, pairs) -> dict:
    """Force F_A[N,3] (N) and moment M_A[N,3] (N m, about the ring centre) of the contact on
    the target APDS, in the target APDS frame; ``pairs``: the pair specs
    (`drake_dock.docking.geometry.pairs.apds_pairs`), matched to the couples by name."""
    by_name = {p.name: p for p in pairs}
    names = ts["couple_names"].tolist()
    sign = np.array([1.0 if by_name[c].body1 == TARGET else
                     -1.0 if by_name[c].body2 == TARGET else 0.0 for c in names])
    point = np.where((sign > 0)[None, :, None], ts["p1_W"], ts["p2_W"])
    f = couple_forces_W(ts) * sign[None, :, None]
    j = ts["apds_names"].tolist().index(TARGET)
    R, c = ts["R_WA"][:, j], ts["p_WA"][:, j]
    F_W = f.sum(1)
    M_W = np.cross(point - c[:, None, :], f).sum(1)
    return {"F_A": np.einsum("nji,nj->ni", R, F_W), "M_A": np.einsum("nji,nj->ni", R, M_W)}


def _peak(t, values) -> dict:
    """{"peak": the largest of ``values`` (0 for none), "time_s": its first sample's time (None
    when the peak is 0)}."""
    values = np.asarray(values, float)
    if not values.size or not values.max() > 0:
        return {"peak": 0.0, "time_s": None}
    k = int(np.argmax(values))
    return {"peak": float(values[k]), "time_s": float(t[k])}


def couple_force_magnitudes(ts: dict) -> np.ndarray:
    """|f|[N, n_couples]: each couple's contact force (normal and friction), N."""
    return np.linalg.norm(couple_forces_W(ts), axis=-1)


TIE_RTOL = 1e-9     # couples' forces this close count as one peak (symmetry, round-off)


def peak_loads(ts: dict, pairs) -> dict:
    """The peaks a docking engineer reads, each with the time of its first sample: the contact
    force and moment at the target's ring (magnitude; axial and lateral force; bending moment and
    torque about the docking axis; `interface_loads`), the Stewart element's stroke
    (translation, rotation) and force, the total contact force (the sum of the magnitudes of
    the couples' forces, normal and friction) and the largest normal force of one couple.
    Impulses are not forces: they are in the impacts."""
    t = ts["t"]
    loads = interface_loads(ts, pairs)
    F, M = loads["F_A"], loads["M_A"]
    lam = ts["lambda_n"]
    couple = _peak(t, lam.max(1, initial=0.0))
    names = ts["couple_names"].tolist()
    if couple["time_s"] is not None:
        k = int(np.argmax(lam.max(1)))
        # Symmetric couples carry equal forces to round-off: the first of those within
        # TIE_RTOL of the peak, in pair order, whatever the last bits on this machine.
        tied = np.flatnonzero(lam[k] >= (1.0 - TIE_RTOL) * lam[k].max())
        couple["couple"] = names[int(tied[0])]
    else:
        couple["couple"] = None
    return {
        "interface_force_N": {**_peak(t, np.linalg.norm(F, axis=1)),
                              "axial_peak": _peak(t, np.abs(F[:, 2]))["peak"],
                              "lateral_peak": _peak(t, np.hypot(F[:, 0], F[:, 1]))["peak"]},
        "interface_moment_Nm": {**_peak(t, np.linalg.norm(M, axis=1)),
                                "bending_peak": _peak(t, np.hypot(M[:, 0], M[:, 1]))["peak"],
                                "torque_about_axis_peak": _peak(t, np.abs(M[:, 2]))["peak"]},
        "stewart_stroke_m": {**_peak(t, np.linalg.norm(ts["stewart_x"], axis=1)),
                             "axial_peak": _peak(t, np.abs(ts["stewart_x"][:, 2]))["peak"],
                             "rotation_peak_deg": float(np.degrees(_peak(
                                 t, np.linalg.norm(ts["stewart_rpy"], axis=1))["peak"]))},
        "stewart_force_N": _peak(t, np.linalg.norm(ts["stewart_force_W"], axis=1)),
        "total_contact_force_N": _peak(t, couple_force_magnitudes(ts).sum(1)),
        "couple_normal_force_N": couple,
    }
