"""The contact system's witnesses as arrays, for the step control of
`drake_dock.systems.stepping.WitnessApproach`: the armed witnesses of a set of modes
(`ArmedWitnesses`), their values and rates at a context, the second rates of the gaps, and the
step-end target of the far pairs' seek at a step's start."""
from __future__ import annotations

import math
import weakref
from typing import NamedTuple

import numpy as np

from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels import couples as C
from drake_dock.core.kernels import model as K
from drake_dock.core.kernels import witness_values as WV
from drake_dock.systems import witnesses
from drake_dock.systems.witnesses import FAR_WITNESS


class ArmedWitnesses:
    """The armed witnesses of a set of modes as arrays: their names (the far pairs' first,
    when ``far``), and of the pairs' witnesses their pair, kind code and whether a gap
    witness of a tracked couple (``gap``, a mask); their places in an evaluation's witness
    values and couple rows (those of the pairs not far, by their place among them)."""

    __slots__ = ("names", "pair", "code", "far", "gap", "flat", "flat_list", "gap_flat",
                 "g_flat", "gap_pos", "regular", "regular_pos", "regular_pair",
                 "regular_slot", "pair_gap_flat")

    def __init__(self, names, pair, code, far, gap, slot):
        self.names, self.pair, self.code, self.far, self.gap = names, pair, code, far, gap
        self.flat = slot * K.NW + code                  # into an evaluation's wv, raveled
        self.flat_list = self.flat.tolist()
        self.gap_flat = slot[gap] * C.ROW + C.VN        # the gaps' v_n in its couple rows
        self.g_flat = slot[gap] * C.ROW + C.GAP         # and the gaps
        self.gap_pos = np.flatnonzero(gap)              # the gap witnesses' places
        # per witness of a pair: its gap's place in the couple rows (raveled), -1 but for gaps
        self.pair_gap_flat = np.where(gap, slot * C.ROW + C.GAP, -1)
        self.regular = code == K.W_REGULAR              # the domain-end witnesses
        self.regular_pos = np.flatnonzero(self.regular)
        self.regular_pair = pair[self.regular].astype(np.int64)
        self.regular_slot = slot[self.regular].astype(np.int64)

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
        return self._armed_modes(self.get_modes(context))

    def _armed_modes(self, modes) -> "ArmedWitnesses":
        derived = modes.index().derived
        hit = derived.get("armed_arrays")
        if hit is None:
            hit = derived["armed_arrays"] = ArmedWitnesses.of(self._armed_list(modes), modes,
                                                              self.pairs)
        return hit

    def add_event_listener(self, listener):
        """``listener(source, context, t, x, modes)`` is called after each event with the
        state it leaves (the context still holds the one it found: Drake applies the event
        after its handler returns), once per handler call (Drake calls the handler once per
        triggered witness). ``listener`` must be a bound method: it is kept by a weak
        reference, so that a `WitnessApproach` no longer used drops out (`remove_event_listener`
        takes it out at once, as `simulate` does at a run's end)."""
        self.__dict__.setdefault("_event_listeners", []).append(weakref.WeakMethod(listener))

    def remove_event_listener(self, listener):
        self._event_listeners = [r for r in getattr(self, "_event_listeners", [])
                                 if r() is not None and r() != listener]

    def tell_event(self, context, t, x, modes):
        """Calls the event listeners (`add_event_listener`) with the state an event leaves."""
        for ref in getattr(self, "_event_listeners", ()):
            listener = ref()
            if listener is not None:
                listener(self, context, t, x, modes)

    def witness_now_after(self, context, t, x, modes) -> tuple:
        """(`WitnessNow`, its second rates as ``f(mask)``, `witness_second_rate_array`) at
        the state (t, x, modes) that an event handled at ``context`` leaves, from the
        evaluation Drake asks for there next (kept in the memo). The inputs are read at
        ``context``: an input that depends on the state (a controller) gives the value before
        the event, and this evaluation is then not the one Drake reuses."""
        E = self._evaluation_at(t, x, modes, self.input_force(context, x, modes))
        a = self._armed_modes(modes)
        return self._witness_now_of(E, modes, a), lambda mask: self._second_rates_of(E, a,
                                                                                     mask)

    def witness_now(self, context) -> WitnessNow:
        """`WitnessNow` at the context, from its one evaluation:
        - ``epoch``: the modes' mode changes (every event changes it), with the gap
          witnesses whose gap is not positive (their witness is v_n, not the gap);
        - ``layout``: the armed witnesses' names (it changes whenever their set changes);
        - ``w``: the values of the witnesses `DoGetWitnessFunctions` returns now, in the order
          of `armed_witnesses` (the far pairs' first when armed; inf when far pairs are sought
          at the step's start before their clearance is used up: ``target`` stands for it);
        - ``d``: for the gap witnesses of the tracked couples g' = v_n while the gap is
          positive, and g'' = W^3 . v' + b_n while it is not (the witness is then v_n); the
          domain-end margin's rate for the regular witnesses where the margin is the least
          (`witness_values.regular_rates`); NaN elsewhere;
        - ``target``: when a far pair is due a seek at a step's start (`_on_step`) at the
          present rate of its travel bound; a step that ends there leaves the seek to the
          next step's start, and no witness needs isolating."""
        modes = self.get_modes(context)
        return self._witness_now_of(self._cache.Eval(context), modes,
                                    self._armed_modes(modes))

    def _witness_now_of(self, E, modes, a) -> WitnessNow:
        # The impact witness is the gap while positive, its rate v_n; the regular witnesses'
        # rates where the end margin is the least (compiled, `witness_values.witness_now`).
        w, d, turning = WV.witness_now(self.engine.packed, E.wv.ravel(), E.out, a.flat,
                                       a.gap_pos, a.g_flat, a.gap_flat, a.regular_pos,
                                       a.regular_pair, a.regular_slot)
        epoch = modes.mode_changes
        if turning.size:
            # While the gap is not positive (just after an impact) the witness is v_n, its
            # rate g'' (a couple turning back within a few microseconds is predicted from
            # the first point after the impact). The witness changes meaning (m/s to m) where
            # the gap turns positive: a new epoch, so that no secant joins the two.
            d[turning] = self._gap_second_rates(E, a, turning.tolist())
            epoch = (epoch, turning.tobytes())
        if a.far:
            far = E.far_witness if self.options.reseek_early <= 0 else math.inf
            w, d = np.concatenate([[far], w]), np.concatenate([[np.nan], d])
        return WitnessNow(epoch, a.names, w, d, E.far_early)

    def witness_second_rate_array(self, context, mask) -> np.ndarray:
        """Second time derivatives of the witnesses of `WitnessNow.w` in ``mask`` (gap
        witnesses of tracked couples while the gap is positive), g'' = W^3 . v' + b_n
        (Eq. 52) at the evaluation's accelerations: a couple leaving an impact has no history
        in the new epoch from which `WitnessApproach` could predict its landing. NaN elsewhere
        (the other witnesses with rates, the gap witnesses in their v_n form)."""
        return self._second_rates_of(self._cache.Eval(context), self.armed_witnesses(context),
                                     mask)

    def _second_rates_of(self, E, a, mask) -> np.ndarray:
        out = np.full(len(mask), np.nan)
        off = 1 if a.far else 0
        gap = E.out.ravel()
        js = [j - off for j in np.flatnonzero(mask).tolist()
              if a.gap[j - off] and gap[a.pair_gap_flat[j - off]] > 0.0]
        if js:
            out[np.array(js) + off] = self._gap_second_rates(E, a, js)
        return out

    def _gap_second_rates(self, E, a, js) -> np.ndarray:
        """g'' = W^3 . v' + b_n (Eq. 52) of the gap witnesses at the places ``js`` among the
        pairs' armed witnesses (`ArmedWitnesses.pair`), at the evaluation E."""
        kin = self.engine.kinematics(E.q, E.v)
        out = np.empty(len(js))
        for k, j in enumerate(js):
            i = int(a.pair[j])
            row = self.engine.row(i, E.evals[i], kin)
            out[k] = float(row.Wn @ E.vdot + row.bn)
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
