"""The contact system's witnesses as arrays, for the step control of
`drake_dock.systems.stepping.WitnessApproach`: the armed witnesses of a set of modes
(`ArmedWitnesses`), their values and rates at a context, the second rates of the gaps, and the
step-end target of the far pairs' seek at a step's start."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels import couples as C
from drake_dock.core.kernels import model as K
from drake_dock.systems import witnesses
from drake_dock.systems.witnesses import FAR_WITNESS


class ArmedWitnesses:
    """The armed witnesses of a set of modes as arrays: their names (the far pairs' first,
    when ``far``), and of the pairs' witnesses their pair, kind code and whether a gap
    witness of a tracked couple (``gap``, a mask); their places in an evaluation's witness
    values and couple rows (those of the pairs not far, by their place among them)."""

    __slots__ = ("names", "pair", "code", "far", "gap", "flat", "flat_list", "gap_flat",
                 "g_flat", "no_rates")

    def __init__(self, names, pair, code, far, gap, slot):
        self.names, self.pair, self.code, self.far, self.gap = names, pair, code, far, gap
        self.flat = slot * K.NW + code                  # into an evaluation's wv, raveled
        self.flat_list = self.flat.tolist()
        self.gap_flat = slot[gap] * C.ROW + C.VN        # the gaps' v_n in its couple rows
        self.g_flat = slot[gap] * C.ROW + C.GAP         # and the gaps
        self.no_rates = np.full(len(pair), np.nan)

    @classmethod
    def of(cls, armed, modes, pairs) -> "ArmedWitnesses":
        per = [(i, kind) for i, kind in armed if i is not None]
        names = tuple(FAR_WITNESS if i is None else
                      f"{pairs[i].name} {witnesses.WITNESSES[kind][0]}" for i, kind in armed)
        pair = np.array([i for i, _ in per], dtype=np.intp)
        code = np.array([witnesses.CODE[kind] for _, kind in per], dtype=np.intp)
        gap = np.array([kind == "impact" and modes.pairs[i].mode == Mode.TRACKED
                        for i, kind in per], dtype=bool)
        place = {i: j for j, i in enumerate(modes.index().near)}
        slot = np.array([place[i] for i, _ in per], dtype=np.intp)
        return cls(names, pair, code, any(i is None for i, _ in armed), gap, slot)


class WitnessNow(NamedTuple):
    """What a witness source gives `WitnessApproach` at a context (`drake_dock.systems.
    stepping`): its ``epoch``, the ``layout`` of its armed witnesses, their values ``w``, their
    rates ``d`` (NaN where unknown) and the step-end ``target`` (s from now, inf for none)."""

    epoch: int
    layout: tuple
    w: np.ndarray
    d: np.ndarray
    target: float


class WitnessPredictions:
    """The arrays a `RigidContactSystem` gives `WitnessApproach` (`drake_dock.systems.
    stepping` states what each method returns)."""

    def armed_witnesses(self, context) -> "ArmedWitnesses":
        """The witnesses `DoGetWitnessFunctions` returns now as arrays (`ArmedWitnesses`),
        kept on the modes' index."""
        return self._armed_of(self.get_modes(context), context)

    def _armed_of(self, modes, context) -> "ArmedWitnesses":
        derived = modes.index().derived
        hit = derived.get("armed_arrays")
        if hit is None:
            hit = derived["armed_arrays"] = ArmedWitnesses.of(self._armed(context), modes,
                                                              self.pairs)
        return hit

    def witness_now(self, context) -> WitnessNow:
        """`WitnessNow` at the context, from its one evaluation:
        - ``epoch``: the modes' mode changes (every event changes it);
        - ``layout``: the armed witnesses' names (it changes whenever their set changes);
        - ``w``: the values of the witnesses `DoGetWitnessFunctions` returns now, in the order
          of `armed_witnesses` (the far pairs' first when armed; inf when far pairs are sought
          at the step's start before their clearance is used up: ``target`` stands for it);
        - ``d``: g' = v_n for the gap witnesses of the tracked couples while the gap is
          positive, NaN elsewhere;
        - ``target``: when a far pair is due a seek at a step's start (`_on_step`) at the
          present rate of its travel bound; a step that ends there leaves the seek to the
          next step's start, and no witness needs isolating."""
        E = self._cache.Eval(context)
        modes = self.get_modes(context)
        a = self._armed_of(modes, context)
        w = E.wv.ravel().take(a.flat)
        d = a.no_rates.copy()
        if a.g_flat.size:
            # The impact witness is the gap while positive: its rate v_n; otherwise unknown.
            out = E.out.ravel()
            g, vn = out.take(a.g_flat), out.take(a.gap_flat)
            d[a.gap] = np.where(g > 0.0, vn, np.nan)
        if a.far:
            far = E.far_witness if self.options.reseek_early <= 0 else math.inf
            w, d = np.concatenate([[far], w]), np.concatenate([[np.nan], d])
        return WitnessNow(modes.mode_changes, a.names, w, d, E.far_early)

    def witness_second_rate_array(self, context, mask) -> np.ndarray:
        """Second time derivatives of the witnesses of `WitnessNow.w` in ``mask`` (gap
        witnesses of tracked couples), g'' = W^3 . v' + b_n (Eq. 52) at the evaluation's
        accelerations: a couple leaving an impact has no history in the new epoch from which
        `WitnessApproach` could predict its landing. NaN elsewhere."""
        E = self._cache.Eval(context)
        a = self.armed_witnesses(context)
        kin = self.engine.kinematics(E.q, E.v)
        out = np.full(len(mask), np.nan)
        off = 1 if a.far else 0
        for j in np.flatnonzero(mask).tolist():
            i = int(a.pair[j - off])
            row = self.engine.row(i, E.evals[i], kin)
            out[j] = float(row.Wn @ E.vdot + row.bn)
        return out

    def witness_values(self, context) -> dict:
        """The values of the witnesses `DoGetWitnessFunctions` returns now, by description."""
        now = self.witness_now(context)
        return dict(zip(now.layout, now.w.tolist()))

    def witness_rates(self, context) -> dict:
        """`WitnessNow.d` by description, the known rates only."""
        now = self.witness_now(context)
        return {n: r for n, r in zip(now.layout, now.d.tolist()) if not math.isnan(r)}

    def witness_second_rates(self, context, names) -> dict:
        """`witness_second_rate_array` by description, for the witnesses ``names``."""
        all_names = self.armed_witnesses(context).names
        mask = np.array([n in names for n in all_names])
        return {n: r for n, r, m in zip(all_names,
                                        self.witness_second_rate_array(context, mask).tolist(),
                                        mask) if m}
