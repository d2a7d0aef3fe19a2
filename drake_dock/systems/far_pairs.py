"""The far pairs' travel bound (Sect. 5.1): a conservative bound of the travel of patch 1
relative to frame 2 since the pair's last seek, compared with its clearance; and the broad
phase: the least gap of the pair's bounding-sphere covers (`drake_dock.core.covers`), a lower
bound of its distance that needs no seek."""
from __future__ import annotations

import math

import numpy as np

from drake_dock.core.kernels import cover as compiled_cover

# Covers of the broad phase: cells per parameter and per block, by patch dimension.
BROAD_CELLS = {0: (1, 1), 1: (256, 16), 2: (32, 8)}


def bounding_sphere(patch, n=41):
    """(c, r): a sphere, in the patch's frame, that holds the patch."""
    pts = patch.position(patch.grid(n))
    c = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    r = float(np.linalg.norm(pts - c, axis=1).max())
    return c, 1.02 * r + 1e-9


def relative_pose(pose1, pose2):
    """X21 = (R2^T R1, R2^T (p1 - p2)): the pose of frame 1 in frame 2."""
    (R1, p1), (R2, p2) = pose1, pose2
    return R2.T @ R1, R2.T @ (p1 - p2)


def travel_bounds(R21, p21, R0, p0, centres, radii):
    """|delta(X21 c1)| + |delta R21|_2 r1 per pair, for the current and reference relative poses
    of frame 1 in frame 2, stacked (R21, R0 (K, 3, 3), p21, p0 (K, 3)), and the bounding
    spheres (c1, r1) of the pairs' patches 1."""
    lin = np.einsum("kij,kj->ki", R21 - R0, centres) + p21 - p0
    # |R21 - R0|_2 = |R0^T R21 - I|_2 = 2 sin(theta / 2) = sqrt(3 - tr(R0^T R21)).
    rot = np.sqrt(np.maximum(3.0 - np.einsum("kij,kij->k", R0, R21), 0.0))
    return np.sqrt(np.einsum("ki,ki->k", lin, lin)) + rot * radii


class FarPairs:
    """The travel bounds of a system's far pairs: ``frame_index`` (frame 1, frame 2) per pair
    and the bounding spheres of the pairs' patches 1."""

    def __init__(self, pairs, frame_index):
        self.frame_index = frame_index
        spheres = [bounding_sphere(p.patch1) for p in pairs]
        self.centres = np.array([c for c, _ in spheres]).reshape(-1, 3)
        self.radii = np.array([r for _, r in spheres])
        self.pairs = pairs
        # The frame pairs (frame 1, frame 2) and each pair's among them; each pair's reference
        # pose (`PairState.ref_X21`, a tuple replaced at every seek) stacked, by identity.
        self.frame_pairs = sorted(set(frame_index))
        self._fp = np.array([self.frame_pairs.index(ab) for ab in frame_index], dtype=np.intp)
        self._refs = [None] * len(pairs)
        self._R0 = np.zeros((len(pairs), 3, 3))
        self._p0 = np.zeros((len(pairs), 3))

    def covers(self, i):
        """The covers (`BROAD_CELLS`, `kernels.cover.patch_cover`) of pair i's two patches
        (kept on the patches)."""
        return [compiled_cover.patch_cover(p, *BROAD_CELLS[p.dim])
                for p in (self.pairs[i].patch1, self.pairs[i].patch2)]

    def cover_gap(self, i, poses, below=-math.inf):
        """The least gap of pair i's covers at ``poses``, patch 1 placed in frame 2: a lower
        bound of the pair's distance (`drake_dock.core.kernels.cover.cover_gap`); with ``below``, a
        gap below it as soon as one is found."""
        c1, c2 = self.covers(i)
        return compiled_cover.cover_gap(c1.posed(*self.reference(i, poses)), c2, below)

    def reference(self, i, poses):
        """The relative pose of pair i kept at a seek, read-only: `bounds` keeps it stacked by
        its identity, so it is replaced at the next seek, never written in place."""
        a, b = self.frame_index[i]
        R, p = relative_pose(poses[a], poses[b])
        R.flags.writeable = p.flags.writeable = False
        return R, p

    def bounds(self, idx, poses, states):
        """Travel bounds of the far pairs ``idx`` (their `PairState`s in ``states``) at
        ``poses``, at once; inf for a pair never sought."""
        out = np.full(len(idx), math.inf)
        known, ids = [], []
        for k, i in enumerate(idx):
            ref = states[i].ref_X21
            if ref is not None:
                known.append(k)
                ids.append(i)
                if self._refs[i] is not ref:
                    self._refs[i] = ref
                    self._R0[i], self._p0[i] = ref
        if known:
            out[known] = self._stacked(np.array(ids, dtype=np.intp), self._R0[ids],
                                       self._p0[ids], poses)
        return out

    def bounds_of(self, index, states, poses):
        """Travel bounds of all far pairs of the `ModesIndex` ``index`` of ``states`` (inf for
        a pair never sought), their reference poses stacked once per index."""
        refs = index.derived.get("far_refs")
        if refs is None:
            sought = index.far[index.sought]
            R0, p0 = np.zeros((len(sought), 3, 3)), np.zeros((len(sought), 3))
            for k, i in enumerate(sought.tolist()):
                R0[k], p0[k] = states[i].ref_X21
            R0.flags.writeable = p0.flags.writeable = False
            refs = index.derived["far_refs"] = (sought, R0, p0)
        out = np.full(len(index.far), math.inf)
        if len(refs[0]):
            out[index.sought] = self._stacked(*refs, poses)
        return out

    def _stacked(self, ids, R0, p0, poses):
        """`travel_bounds` of the pairs ``ids`` from their stacked reference poses."""
        fp = self._fp[ids]
        R21 = np.zeros((len(self.frame_pairs), 3, 3))
        p21 = np.zeros((len(self.frame_pairs), 3))
        for m in set(fp.tolist()):
            a, b = self.frame_pairs[m]
            R21[m], p21[m] = relative_pose(poses[a], poses[b])
        return travel_bounds(R21[fp], p21[fp], R0, p0, self.centres[ids], self.radii[ids])

    def bound(self, i, poses, state):
        """The travel bound of one far pair i in ``state``."""
        states = [None] * len(self.frame_index)
        states[i] = state
        return float(self.bounds([i], poses, states)[0])
