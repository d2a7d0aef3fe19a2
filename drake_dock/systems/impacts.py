"""The impulsive transitions of a contact set and their log: the LZB impact of the couples hit
(Sect. 6, with the Zeno guard) and the impact without collision at a Painleve paradox
(`drake_dock.core.iwc`). ``ev`` is the `RigidContactSystem`. An event solves its impulses in
turn (`EventImpulses`) and logs each, at its end, as an `Impact` in its `ContactModes`: the
only place an `Impact` is made, with the states just before and after it."""
from __future__ import annotations

import dataclasses
import os

import numpy as np

from drake_dock.core import hybrid
from drake_dock.core.iwc import impact_without_collision
from drake_dock.core.lzb.solve import solve_lzb
from drake_dock.errors import NumericalError, PainleveInconsistency, ZenoError
from drake_dock.systems.contact_types import ContactModes, copied_states


@dataclasses.dataclass(frozen=True)
class Impact:
    """One impulse of the contact set, as logged: at time ``t`` on the couples named, with the
    restitution used (0 for an impact without collision), the couples' normal and tangential
    impulses (in their order) and the kinetic energy it removed. ``x_minus`` and ``x_plus``
    are the contact system's state just before and just after it, ``pairs_plus`` the pair
    states it left and ``impact_loss_plus`` the impact loss booked by then. Never changed once
    logged."""

    t: float
    couples: list
    restitution: float
    normal_impulse: list
    tangential_impulse: list
    energy_lost: float
    without_collision: bool
    x_minus: np.ndarray
    x_plus: np.ndarray
    pairs_plus: tuple
    impact_loss_plus: float

    def modes_after(self, mode_changes: int) -> ContactModes:
        """The sealed modes just after the impulse, ``mode_changes`` the events resolved by
        then, with no impact logged (a logger's sample, not a state to go on from)."""
        return ContactModes(copied_states(self.pairs_plus), [], self.impact_loss_plus,
                            mode_changes).seal()


def enter_after(system, context, impact: Impact, mode_changes: int):
    """Puts the contact system ``system``'s ``context`` (a logger's scratch context) in the
    state just after ``impact``: its ``x_plus`` and `Impact.modes_after`."""
    context.SetContinuousState(impact.x_plus)
    system.set_modes(context, impact.modes_after(mode_changes))


@dataclasses.dataclass
class _Impulse:
    """An impulse solved by an event, before the event's end gives its state after."""
    couples: list
    restitution: float
    normal_impulse: list
    tangential_impulse: list
    energy_lost: float
    without_collision: bool
    v_plus: np.ndarray
    impact_loss_plus: float
    pairs_plus: tuple | None = None


class EventImpulses:
    """The impulses of one event at time t on the working `ContactModes` ``modes`` of the
    `RigidContactSystem` ``ev``: solved in turn (`lzb_impact`, `without_collision`), then
    logged as `Impact`s (`log`)."""

    def __init__(self, ev, t, modes):
        self.ev, self.t, self.modes = ev, t, modes
        self.solved: list[_Impulse] = []

    def admit(self, couples):
        """The Zeno guard's last resort: an impulse of the couples named (an LZB impact or an
        impact without collision) beyond ``max_impacts`` logged or solved raises `ZenoError`."""
        n, most = len(self.modes.impacts) + len(self.solved), self.ev.options.max_impacts
        if n >= most:
            raise ZenoError(f"more than max_impacts = {most} impacts", time=self.t,
                            couples=couples)

    def _add(self, couples, restitution, P_n, P_t, lost, without_collision, v_plus):
        """Books a solved impulse and its energy lost."""
        self.modes.impact_loss += lost
        self.solved.append(_Impulse(couples, restitution, P_n.tolist(), P_t.tolist(), lost,
                                    without_collision, v_plus.copy(), self.modes.impact_loss))

    def left(self, states):
        """The pair states the last impulse left (before the modes are selected again)."""
        self.solved[-1].pairs_plus = tuple(copied_states(states))

    def lzb_impact(self, kin, evs, S, v):
        """The LZB impact of the couples S (their couples in evs, the bodies' `Kinematics`
        kin; `admit`), solved by `solve_lzb`; returns (v+, the couples' v_n+, the approach
        speed)."""
        ev, t = self.ev, self.t
        opt, law = ev.options, ev.law
        names = [ev.pairs[i].name for i in S]
        self.admit(names)
        rows = [ev.engine.row(i, evs[i], kin) for i in S]
        Wn = np.column_stack([r.Wn for r in rows])
        Wt = np.column_stack([r.Wt for r in rows])
        M = ev.engine.mass_matrix(kin)
        approach = float(-min(r.vn for r in rows))
        e = hybrid.zeno_restitution(approach, law.restitution, opt.zeno_speed)
        try:
            res = solve_lzb(M, Wn, v, law.stiffness, law.eta, e, Wt=Wt, mu=law.mu,
                            mu_s=law.static_mu, law=law.impact_law, rtol=opt.impact_rtol)
        except NumericalError as err:
            if os.environ.get("DRAKE_DOCK_DUMP_LZB"):
                np.savez(os.environ["DRAKE_DOCK_DUMP_LZB"], M=M, Wn=Wn, Wt=Wt, v=v, e=e)
            raise NumericalError(f"{err} (approach speed {approach:.3e} m/s)", time=t,
                                 couples=names) from None
        self._add(names, e, res.normal_impulse, res.tangential_impulse,
                  res.kinetic_energy_minus - res.kinetic_energy_plus, False, res.v_plus)
        return res.v_plus, Wn.T @ res.v_plus, approach

    def without_collision(self, M, rows, v, paradox):
        """The impact without collision of the contact set ``rows`` (`ContactRow`s) at the
        Painleve paradox ``paradox`` (`drake_dock.core.iwc`; restitution 0, `admit`); returns
        v+. Raises the paradox, with the reason, when no sticking impulse is admissible."""
        ev = self.ev
        self.admit([r.name for r in rows])
        Wn = np.column_stack([r.Wn for r in rows])
        Wt = np.column_stack([r.Wt for r in rows])
        res = impact_without_collision(M, Wn, Wt, v, ev.law.static_mu)
        if res is None:
            raise PainleveInconsistency(
                "no consistent contact mode (Painleve inconsistency), and the impact without "
                "collision has no sticking impulse (a couple would pull or leave the friction "
                "cone)", time=self.t, couples=paradox.couples) from None
        self._add([r.name for r in rows], 0.0, res.P_n, res.P_t, res.energy_lost, True,
                  res.v_plus)
        return res.v_plus

    def log(self, x, x_new):
        """Logs each impulse as an `Impact` with the states just before and just after it, the
        event having taken state x to x_new (a step-end sample is the state before the event;
        its result is not seen by any step end); the caller seals ``modes`` next. An event can
        solve two (an LZB impact, then an impact without collision where the modes after it
        have no consistent one): the first one's x_plus is the second's x_minus, with its pairs
        as the impact left them (`left`, before the modes were selected); the last one's is the
        event's result."""
        ev, modes = self.ev, self.modes
        x_minus = x.copy()
        for j, imp in enumerate(self.solved):
            x_plus = x_new.copy()
            if j < len(self.solved) - 1:
                x_plus[ev.nq:ev.nq + ev.nv] = imp.v_plus
                pairs, loss = imp.pairs_plus, imp.impact_loss_plus
            else:
                # The states the event leaves: sealed with the modes `Transitions.resolve`
                # returns, so shared, never changed.
                pairs, loss = tuple(modes.pairs), modes.impact_loss
            modes.impacts.append(Impact(
                self.t, imp.couples, imp.restitution, imp.normal_impulse,
                imp.tangential_impulse, imp.energy_lost, imp.without_collision, x_minus, x_plus,
                pairs, loss))
            x_minus = x_plus
        self.solved = []
