"""The tracked couples of a set of pairs, evaluated by one compiled call per evaluation
(`drake_dock.core.kernels.couples`), returned as records with the fields of the `CoupleEval`
of `drake_dock.core.couple.evaluate_couple`, the pure-Python reference they equal."""
from __future__ import annotations

import numpy as np

from drake_dock.core.couple import CoupleEval
from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels.jets import N_PARAMS, patch_spec


class TrackedCouples:
    """Pairs given as (kind "CC"/"CS"/"PC"/"PS", patch1, patch2, (frame index 1, frame index 2)).
    `supported` is False when a patch has no kernel description (`patch_spec`; a "PC" pair's
    point is described by its coordinates and radius); the caller then evaluates the couples
    in Python. ``python`` lists the pairs the caller evaluates in Python even so: the
    point-surface ("PS") pairs, which have no kernel."""

    def __init__(self, pairs):
        k = len(pairs)
        self.cc = np.zeros(k, dtype=np.bool_)
        self.kind1, self.kind2 = np.zeros(k, dtype=np.int64), np.zeros(k, dtype=np.int64)
        self.prm1, self.prm2 = np.zeros((k, N_PARAMS)), np.zeros((k, N_PARAMS))
        self.fidx = np.zeros((k, 2), dtype=np.int64)
        self.spans = np.ones((k, 3))
        self.dims = np.zeros(k, dtype=np.int64)
        self.supported = True
        self.python = []
        self.pc = np.array([i for i, (kind, *_) in enumerate(pairs) if kind == "PC"],
                           dtype=np.int64)
        for i, (kind, p1, p2, (a, b)) in enumerate(pairs):
            if kind == "PS":
                # No kernel: the caller evaluates the couple in Python (its two parameters
                # keep their place in the layout of u).
                self.python.append(i)
                self.dims[i] = 2
                continue
            if kind == "PC":
                s2 = patch_spec(p2)
                if p1.dim != 0 or s2 is None or p2.dim != 1:
                    self.supported = False
                    continue
                self.prm1[i, :4] = (*p1.p, p1.radius)
                self.kind2[i], self.prm2[i] = s2
                self.fidx[i] = a, b
                self.spans[i, 0] = p2.span[0]
                self.dims[i] = 1
                continue
            s1, s2 = patch_spec(p1), patch_spec(p2)
            if s1 is None or s2 is None or p1.dim != 1 or p2.dim != (1 if kind == "CC" else 2):
                self.supported = False
                continue
            self.cc[i] = kind == "CC"
            (self.kind1[i], self.prm1[i]), (self.kind2[i], self.prm2[i]) = s1, s2
            self.fidx[i] = a, b
            span = np.concatenate([p1.span, p2.span])
            self.spans[i, :len(span)] = span
            self.dims[i] = len(span)
        self.uoff = np.concatenate([[0], np.cumsum(self.dims)]).astype(np.int64)

    def evaluate(self, R, o, w, v, u, sigma, active, *, project=True, drift_feedback=0.0):
        """(rows (k, ROW) of the active pairs, u*' (the layout of u)) by
        `couples.evaluate_couples`, for the frames' world rotations R (F, 3, 3), origins o,
        twists w, v (F, 3) and the couples u (concatenated)."""
        out = np.zeros((len(self.cc), K.ROW))
        rate = np.zeros(len(u))
        if len(self.pc):
            K.evaluate_point_curves(self.pc, self.kind2, self.prm1, self.prm2, self.fidx,
                                    self.uoff, self.spans, R, o, w, v, u, sigma, active,
                                    project, drift_feedback, out, rate)
            active = active.copy()
            active[self.pc] = False
        K.evaluate_couples(self.cc, self.kind1, self.prm1, self.kind2, self.prm2, self.fidx,
                           self.uoff, self.spans, R, o, w, v, u, sigma, active, project,
                           drift_feedback, out, rate)
        return out, rate

    def couple_eval(self, out, i) -> CoupleRow:
        """Pair i's row as a record with the fields of `CoupleEval`."""
        return CoupleRow(out[i], int(self.dims[i]))


def _vector(start, size):
    return property(lambda self: self.row[start:start + size])


def _scalar(at):
    return property(lambda self: float(self.row[at]))


def _couple(start):
    return property(lambda self: self.row[start:start + self.m])


class CoupleRow:
    """One couple evaluated by the kernel: the fields of `CoupleEval`, read from its row (views
    and floats, made when asked; a derivative evaluation reads a few of them)."""

    __slots__ = ("row", "m")

    def __init__(self, row, m):
        self.row, self.m = row, m

    u, drift, udot = _couple(K.U), _couple(K.DRIFT), _couple(K.UDOT)
    residual, conditioning, gap, vn, bias_n = (_scalar(K.RESIDUAL), _scalar(K.COND),
                                               _scalar(K.GAP), _scalar(K.VN), _scalar(K.BIAS_N))
    p1, p2, n, ta, tb, v_rel = (_vector(K.P1, 3), _vector(K.P2, 3), _vector(K.N, 3),
                                _vector(K.TA, 3), _vector(K.TB, 3), _vector(K.VREL, 3))
    vt, bias_t = _vector(K.VT, 2), _vector(K.BIAS_T, 2)
    frame = CoupleEval.frame


def warm():
    """Compiles or loads the kernels: one CC, one CS and one PC couple of small patches."""
    from drake_dock.core.patches import Circle, PlaneRect, Point, Segment
    seg = Segment((0.0, 0.0, 0.1), (1.0, 0.0, 0.1))
    tc = TrackedCouples([("CC", seg, Segment((0.5, -1.0, 0.0), (0.5, 1.0, 0.0)), (0, 1)),
                         ("CS", Circle(0.3, 0.1), PlaneRect((-1, -1, 0), (2, 0, 0), (0, 2, 0)),
                          (0, 1)),
                         ("PC", Point((0.1, 0.2, 0.3), 0.01), Circle(0.3), (0, 1))])
    R = np.array([np.eye(3), np.eye(3)])
    z = np.zeros((2, 3))
    tc.evaluate(R, z, z, z, np.array([0.5, 0.5, 0.0, 0.5, 0.5, 1.0]), np.ones(3),
                np.ones(3, dtype=np.bool_))
