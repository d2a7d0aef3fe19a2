"""The values of the contact system's couple output ports (layout `COUPLE_SLICES`), all pairs
at once from one evaluation."""
from __future__ import annotations

import numpy as np

from drake_dock.core.kernels import calculators as KE
from drake_dock.systems.contact_types import COUPLE_OUTPUT_SIZE, COUPLE_SLICES

_S = COUPLE_SLICES


_COLS = np.array([_S[name].start for name in ("status", "gap", "vn", "lambda_n", "lambda_t",
                                              "vt", "u", "p1", "p2", "frame")], dtype=np.int64)


def couple_rows(engine, E) -> np.ndarray:
    """The couple table of the evaluation ``E`` of ``engine``, row i the value of port
    ``couple_<pairs[i].name>`` (`engine.couple_table`); the far pass of E done
    (`Evaluation.couple_table` keeps it)."""
    Y = np.empty((engine.k, COUPLE_OUTPUT_SIZE))
    KE.couple_table(engine.packed, engine.mode_arrays(E.modes), E.x, E.buf, _COLS, Y)
    return Y
