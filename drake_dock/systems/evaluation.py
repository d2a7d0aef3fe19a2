"""One evaluation of the contact system (`Engine.evaluate`) as views of its result buffer, and
the bodies' and frames' kinematics that the events' calculators take."""
from __future__ import annotations

import functools
import math

import numpy as np

from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels import model as E
from drake_dock.core.kernels.couple_row import CoupleRow
from drake_dock.core.kernels.witness_values import due_far, far_witness
from drake_dock.systems.couple_ports import couple_rows


class Kinematics:
    """The bodies' (Rb, pb, wb, vb) and the frames' (R, o, w, v) world poses and twists; as
    (poses, twists) lists of (R, o) and (w, v) per frame by `poses` and `twists`."""

    __slots__ = ("Rb", "pb", "wb", "vb", "R", "o", "w", "v")

    def __init__(self, Rb, pb, wb, vb, R, o, w, v):
        self.Rb, self.pb, self.wb, self.vb, self.R, self.o, self.w, self.v = \
            Rb, pb, wb, vb, R, o, w, v

    @property
    def poses(self):
        return [(self.R[f], self.o[f]) for f in range(len(self.R))]

    @property
    def twists(self):
        return [(self.w[f], self.v[f]) for f in range(len(self.R))]

    @classmethod
    def at_rest(cls, poses) -> "Kinematics":
        """The frames at the poses [(R, o)], at rest (for couples at a seek)."""
        R = np.array([X[0] for X in poses], dtype=float).reshape(-1, 3, 3)
        o = np.array([X[1] for X in poses], dtype=float).reshape(-1, 3)
        return cls(None, None, None, None, R, o, np.zeros_like(o), np.zeros_like(o))

    @classmethod
    def of_frames(cls, R, o, w, v) -> "Kinematics":
        """The frames' poses and twists only (for the seeks)."""
        return cls(None, None, None, None, R, o, w, v)

    def still(self) -> "Kinematics":
        """The same poses with the bodies and frames at rest."""
        z = np.zeros_like
        return Kinematics(self.Rb, self.pb, None if self.wb is None else z(self.wb),
                          None if self.vb is None else z(self.vb), self.R, self.o, z(self.w),
                          z(self.v))


# The sections of the result buffer, in the order of the offsets `model.layout` returns.
(XDOT, OUT, LAMBDA_N, LAMBDA_T, CONTACT_FORCE, WITNESS, BOUND, FRAME_R, FRAME_O, FRAME_W,
 FRAME_V, SCALARS, BUSHINGS, END) = range(14)


class Evaluation:
    """One evaluation (`Engine.evaluate`): views of its result buffer (`engine.layout`), made
    when asked (a derivative evaluation reads only xdot)."""

    def __init__(self, engine, t, x, modes, buf, layout):
        self.engine, self.t, self.x, self.modes, self.buf = engine, t, x, modes, buf
        self.layout = layout
        self.xdot = buf[:engine.nx]
        self._far = False

    def _section(self, a):
        """The buffer's section ``a`` (`OUT` ... `BUSHINGS`)."""
        L = self.layout
        return self.buf[L[a]:L[a + 1]]

    @property
    def needs_report(self) -> bool:
        """Whether the kernel flagged this evaluation (a mode status other than OK, a
        bushing out of range): `check_evaluation` says what."""
        return bool(self.buf[self.layout[SCALARS] + E.S_REPORT])

    @functools.cached_property
    def out(self):
        """The couple rows of the pairs not far (n_near, couples.ROW), by `slot`."""
        return self._section(OUT).reshape(-1, K.ROW)

    @functools.cached_property
    def slot(self) -> np.ndarray:
        """Each pair's place among the pairs not far (-1 for a far one)."""
        return self.engine.slot_of(self.modes)

    def row(self, i) -> np.ndarray:
        """Pair i's couple row (a pair not far)."""
        return self.out[self.slot[i]]

    @functools.cached_property
    def lam_n(self):
        return self._section(LAMBDA_N)

    @functools.cached_property
    def lam_t(self):
        return self._section(LAMBDA_T).reshape(self.engine.k, 2)

    @functools.cached_property
    def contact_force(self):
        return self._section(CONTACT_FORCE)

    @functools.cached_property
    def wv(self):
        """Witness values (n_near, engine.NW) of the pairs that are not far, by `slot`."""
        return self._section(WITNESS).reshape(-1, E.NW)

    @functools.cached_property
    def witness_table(self) -> list:
        """`wv` as a list over all pairs (None for a far pair) of lists by kind: Drake asks for
        each witness function's value on its own, at both ends of every step."""
        rows = self.wv.tolist()
        return [None if j < 0 else rows[j] for j in self.slot.tolist()]

    def least_witness(self, armed, rest=None) -> float:
        """The least value of the `ArmedWitnesses` ``armed`` of this evaluation's modes (the far
        pairs' witness among them when armed; inf for none), computed once; with ``rest``
        (places in ``armed.flat_list``, whether the far pairs' witness counts), of those only."""
        key = "_least" if rest is None else ("_least", rest)
        least = self.__dict__.get(key)
        if least is None:
            values = self._section(WITNESS).tolist()
            flat = armed.flat_list
            if rest is None:
                least = min((values[j] for j in flat), default=math.inf)
                far = armed.far
            else:
                least = min((values[flat[j]] for j in rest[0]), default=math.inf)
                far = rest[1]
            if far:
                least = min(least, self.far_witness)
            self.__dict__[key] = least
        return least

    @property
    def bound(self):
        """The far pairs' travel bounds (NaN for the others)."""
        self._far_pass()
        return self._section(BOUND)

    @functools.cached_property
    def R(self):
        return self._section(FRAME_R).reshape(-1, 3, 3)

    @functools.cached_property
    def o(self):
        return self._section(FRAME_O).reshape(-1, 3)

    @functools.cached_property
    def w(self):
        return self._section(FRAME_W).reshape(-1, 3)

    @functools.cached_property
    def vf(self):
        return self._section(FRAME_V).reshape(-1, 3)

    @functools.cached_property
    def sc(self):
        return self._section(SCALARS)

    @functools.cached_property
    def bushings(self):
        """Per bushing: deflection (3), roll-pitch-yaw (3), spatial force on frame C (6,
        world)."""
        return self._section(BUSHINGS).reshape(-1, E.BUSH_ROW)

    @functools.cached_property
    def q(self):
        return self.x[:self.engine.nq]

    @functools.cached_property
    def v(self):
        return self.x[self.engine.nq:self.engine.nq + self.engine.nv]

    @functools.cached_property
    def evals(self) -> list:
        """`CoupleRow` per pair not far, None per far pair."""
        eng, out = self.engine, self.out
        ev = [None] * eng.k
        for j, i in enumerate(self.modes.index().near):
            ev[i] = CoupleRow(out[j], int(eng.uoff[i + 1] - eng.uoff[i]))
        return ev

    @functools.cached_property
    def couple_table(self) -> np.ndarray:
        """The couple output ports' values, all pairs at once (`couple_ports.couple_rows`),
        kept: outputs and loggers ask for them at the same context."""
        self._far_pass()
        return couple_rows(self.engine, self)

    def _far_pass(self):
        if not self._far:
            far_witness(self.engine.packed, self.engine.mode_arrays(self.modes), self.buf)
            self._far = True

    @property
    def poses(self):
        return [(self.R[f], self.o[f]) for f in range(len(self.R))]

    @property
    def twists(self):
        return [(self.w[f], self.vf[f]) for f in range(len(self.R))]

    @property
    def vdot(self):
        return self.xdot[self.engine.nq:self.engine.nq + self.engine.nv]

    @property
    def friction_power(self):
        return float(self.sc[E.S_FRICTION])

    @property
    def applied_power(self):
        return float(self.sc[E.S_P_EL])

    @property
    def external_power(self):
        return float(self.sc[E.S_P_IN])

    @property
    def kinetic_energy(self):
        return float(self.sc[E.S_KE])

    @property
    def potential_energy(self):
        return float(self.sc[E.S_PE])

    @property
    def damper_power(self):
        return self.sc[E.S_DAMP:]

    @property
    def far_witness(self) -> float:
        """The far pairs' witness: their smallest clearance left."""
        self._far_pass()
        return float(self.sc[E.S_FAR])

    @property
    def far_early(self) -> float:
        """The time before the next far pair not `due` now is due a seek at a step's start, at
        the present rate of its travel bound, inf without one."""
        self._far_pass()
        return float(self.sc[E.S_FAR_EARLY])

    @property
    def due(self) -> bool:
        """A far pair's travel bound has used ``reseek_early`` of its clearance, or will within
        ``reseek_horizon`` (`witness_values.due_in`)."""
        self._far_pass()
        return bool(self.sc[E.S_DUE])

    @property
    def due_pairs(self) -> np.ndarray:
        """The far pairs (ascending) that `due` finds due."""
        self._far_pass()
        return due_far(self.engine.packed, self.engine.mode_arrays(self.modes), self.buf)

    @property
    def drifting(self) -> int:
        """The first couple not far that projected by more than ``drift_tol`` of its span,
        or -1."""
        return int(self.sc[E.S_DRIFTING])
