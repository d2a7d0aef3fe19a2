"""The APDS's display mesh: Drake's visual geometry of an APDS (`drake_dock.docking.model.plant`),
made from the same equations as its contact patches (`drake_dock.docking.geometry.apds`)."""
from __future__ import annotations

import numpy as np

from drake_dock.docking.geometry.apds import guide_surface
from drake_dock.docking.scenario.dimensions import ApdsGeometry


def apds_mesh(g: ApdsGeometry, *, n_s=12, n_z=8, n_ring=96, plate=0.01, ring_depth=0.04):
    """Triangle mesh (vertices (V, 3), faces (F, 3)) of an APDS, made from the same equations as
    the contact patches: each petal is the guide surface given a thickness ``plate`` along the
    inward cone normal; the ring is the annulus Rs <= rho <= R of depth ``ring_depth`` below
    zeta = 0."""
    verts, faces = [], []

    def add_grid(P, flip):
        base = len(verts)
        n0, n1 = P.shape[0], P.shape[1]
        verts.extend(P.reshape(-1, 3))
        for a in range(n0 - 1):
            for b in range(n1 - 1):
                i00, i01 = base + a * n1 + b, base + a * n1 + b + 1
                i10, i11 = i00 + n1, i01 + n1
                tris = [(i00, i10, i11), (i00, i11, i01)]
                faces.extend([(t[0], t[2], t[1]) if flip else t for t in tris])

    s = np.linspace(0, 1, n_s)
    z = np.linspace(0, g.H, n_z)
    S, Z = np.meshgrid(s, z, indexing="ij")
    for k in (1, 2, 3):
        P = guide_surface(g, k)
        u = np.stack([S, Z], axis=-1)
        X = P.position(u)
        T = P.first(u)
        nrm = np.cross(T[..., 0], T[..., 1])
        nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
        # Outward (away from the axis) normal; the inner face is offset inwards.
        sign = np.sign(np.einsum("...x,...x->...", nrm[..., :2], X[..., :2]))[..., None]
        nrm = nrm * sign
        inner = X - plate * nrm
        add_grid(X, flip=False)
        add_grid(inner, flip=True)
        # Edges: close the plate along its four borders.
        for Xa, Xb in ((X[0, :], inner[0, :]), (X[-1, :], inner[-1, :]),
                       (X[:, 0], inner[:, 0]), (X[:, -1], inner[:, -1])):
            add_grid(np.stack([Xa, Xb], axis=1), flip=False)
            add_grid(np.stack([Xa, Xb], axis=1), flip=True)
    th = np.linspace(0, 2 * np.pi, n_ring + 1)
    c, sn = np.cos(th), np.sin(th)
    for zz in (0.0, -ring_depth):
        ann = np.stack([np.stack([g.Rs * c, g.Rs * sn, np.full_like(th, zz)], -1),
                        np.stack([g.R * c, g.R * sn, np.full_like(th, zz)], -1)], axis=1)
        add_grid(ann, flip=(zz == 0.0))
    for rr in (g.Rs, g.R):
        wall = np.stack([np.stack([rr * c, rr * sn, np.zeros_like(th)], -1),
                         np.stack([rr * c, rr * sn, np.full_like(th, -ring_depth)], -1)], axis=1)
        add_grid(wall, flip=(rr == g.Rs))
    return np.asarray(verts), np.asarray(faces, dtype=int)


def mesh_to_obj(verts, faces) -> str:
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in verts]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    return "\n".join(lines) + "\n"
