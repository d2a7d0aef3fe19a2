"""The values of the contact system's couple output ports (layout `COUPLE_SLICES`), all pairs
at once from one evaluation."""
from __future__ import annotations

import numpy as np

from drake_dock.core.kernels import calculators as KE
from drake_dock.systems.contact_types import COUPLE_OUTPUT_SIZE, COUPLE_SLICES

_S = COUPLE_SLICES


_COLS = np.array([_S[name].start for name in ("status", "gap", "vn", "lambda_n", "lambda_t",
                                              "vt", "u", "p1", "p2", "frame")], dtype=np.int64)


class CoupleRows:
    """The couple table of a `RigidContactSystem` ``system``: row i the value of port
    ``couple_<pairs[i].name>`` (`engine.couple_table`)."""

    def __init__(self, system):
        self.system = system

    def table(self, E) -> np.ndarray:
        """The table at the evaluation E (kept on E: outputs and loggers ask for it at the
        same context)."""
        Y = getattr(E, "_table", None)
        if Y is None:
            eng = self.system.engine
            E._far_pass()
            Y = E._table = np.empty((eng.k, COUPLE_OUTPUT_SIZE))
            KE.couple_table(eng.packed, eng.mode_arrays(E.modes), E.x, E.buf, _COLS, Y)
        return Y
