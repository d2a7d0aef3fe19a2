"""`CoupleRow`: one couple's row of the couple kernels (`drake_dock.core.kernels.couples`) read
as a record with the fields of `drake_dock.core.couple.CoupleEval`."""
from __future__ import annotations

import numpy as np

from drake_dock.core.kernels import couples as K


def _vector(start, size):
    return property(lambda self: self.row[start:start + size])


def _scalar(at):
    return property(lambda self: float(self.row[at]))


def _couple(start):
    return property(lambda self: self.row[start:start + self.m])


class CoupleRow:
    """One couple evaluated by a couple kernel: the fields of `CoupleEval`, read from its row
    (views and floats, made when asked; a derivative evaluation reads a few of them); ``m`` is
    the couple's dimension (the length of u)."""

    __slots__ = ("row", "m")

    def __init__(self, row, m):
        self.row, self.m = row, m

    u, drift, udot = _couple(K.U), _couple(K.DRIFT), _couple(K.UDOT)
    residual, conditioning, gap, vn, bias_n = (_scalar(K.RESIDUAL), _scalar(K.COND),
                                               _scalar(K.GAP), _scalar(K.VN), _scalar(K.BIAS_N))
    p1, p2, n, ta, tb, v_rel = (_vector(K.P1, 3), _vector(K.P2, 3), _vector(K.N, 3),
                                _vector(K.TA, 3), _vector(K.TB, 3), _vector(K.VREL, 3))
    vt, bias_t = _vector(K.VT, 2), _vector(K.BIAS_T, 2)

    @property
    def frame(self):
        """3x3 rotation whose columns are (ta, tb, n) (Definition 2)."""
        return np.column_stack([self.ta, self.tb, self.n])
