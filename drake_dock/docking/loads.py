"""Interface loads: what the contact transmits to the target's APDS, and the Stewart stroke.

From the timeseries (`drake_dock.docking.results`): each couple in contact pushes its body 1
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
    (`drake_dock.docking.pairs.apds_pairs`), matched to the couples by name."""
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
