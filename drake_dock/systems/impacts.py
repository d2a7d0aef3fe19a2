"""The impulsive transitions of a contact set, logged in its `ContactModes`: the LZB impact of
the couples hit (Sect. 6, with the Zeno guard) and the impact without collision at a Painleve
paradox (`drake_dock.core.iwc`). ``ev`` is the `RigidContactSystem`. Each entry of the log holds
v_plus, the velocity just after its impulse, and impact_loss_plus, the impact loss booked by
then (`Transitions.resolve` turns them into the states just before and after it)."""
from __future__ import annotations

import os

import numpy as np

from drake_dock.core import hybrid
from drake_dock.core.iwc import impact_without_collision
from drake_dock.core.lzb.solve import solve_lzb
from drake_dock.errors import NumericalError, PainleveInconsistency, ZenoError
from drake_dock.systems.contact_types import copied_states


def admit(ev, t, modes, couples):
    """The Zeno guard's last resort: an impulse of the couples named (an LZB impact or an
    impact without collision) beyond ``max_impacts`` logged raises `ZenoError`."""
    if len(modes.impacts) >= ev.options.max_impacts:
        raise ZenoError(f"more than max_impacts = {ev.options.max_impacts} impacts", time=t,
                        couples=couples)


def lzb_impact(ev, t, modes, kin, evs, S, v):
    """The LZB impact of the couples S (their couples in evs, the bodies' `Kinematics` kin),
    logged in ``modes`` (`admit`); returns (v+, the couples' v_n+, the approach speed)."""
    opt, law = ev.options, ev.law
    names = [ev.pairs[i].name for i in S]
    admit(ev, t, modes, names)
    rows = [ev.engine.row(i, evs[i], kin) for i in S]
    Wn = np.column_stack([r.Wn for r in rows])
    Wt = np.column_stack([r.Wt for r in rows])
    M = ev.engine.mass_matrix(kin)
    approach = float(-min(r.vn for r in rows))
    e = hybrid.zeno_restitution(approach, law.restitution, opt.zeno_speed)
    def solve(compiled):
        return solve_lzb(M, Wn, v, law.stiffness, law.eta, e, Wt=Wt, mu=law.mu,
                         mu_s=law.static_mu, law=law.impact_law, rtol=opt.impact_rtol,
                         compiled=compiled)
    try:
        try:
            res = solve(opt.lzb_compiled)
        except NumericalError:
            if not opt.lzb_compiled:
                raise
            # The compiled driver's steps can stall where the reference's DOP853 steps over
            # (two couples that stick and slip in turn): the impact is solved again by it.
            res = solve(False)
    except NumericalError as err:
        if os.environ.get("DRAKE_DOCK_DUMP_LZB"):
            np.savez(os.environ["DRAKE_DOCK_DUMP_LZB"], M=M, Wn=Wn, Wt=Wt, v=v, e=e)
        raise NumericalError(f"{err} (approach speed {approach:.3e} m/s)", time=t,
                             couples=names) from None
    lost = res.kinetic_energy_minus - res.kinetic_energy_plus
    modes.impact_loss += lost
    modes.impacts.append({"t": t, "couples": names, "restitution": e,
                          "normal_impulse": res.normal_impulse.tolist(),
                          "tangential_impulse": res.tangential_impulse.tolist(),
                          "energy_lost": lost, "v_plus": res.v_plus.copy(),
                          "impact_loss_plus": modes.impact_loss})
    return res.v_plus, Wn.T @ res.v_plus, approach


def without_collision(ev, t, modes, M, rows, v, paradox):
    """The impact without collision of the contact set ``rows`` (`ContactRow`s) at the
    Painleve paradox ``paradox`` (`drake_dock.core.iwc`), logged in ``modes`` like an impact
    (marked ``without_collision``, restitution 0; `admit`); returns v+. Raises the paradox,
    with the reason, when no sticking impulse is admissible."""
    admit(ev, t, modes, [r.name for r in rows])
    Wn = np.column_stack([r.Wn for r in rows])
    Wt = np.column_stack([r.Wt for r in rows])
    res = impact_without_collision(M, Wn, Wt, v, ev.law.static_mu)
    if res is None:
        raise PainleveInconsistency(
            "no consistent contact mode (Painleve inconsistency), and the impact without "
            "collision has no sticking impulse (a couple would pull or leave the friction "
            "cone)", time=t, couples=paradox.couples) from None
    modes.impact_loss += res.energy_lost
    modes.impacts.append({"t": t, "couples": [r.name for r in rows], "without_collision": True,
                          "restitution": 0.0, "normal_impulse": res.P_n.tolist(),
                          "tangential_impulse": res.P_t.tolist(),
                          "energy_lost": res.energy_lost, "v_plus": res.v_plus.copy(),
                          "impact_loss_plus": modes.impact_loss})
    return res.v_plus


def states_around(ev, modes, n, x, x_new):
    """The states just before and just after each impulse logged in ``modes`` from entry n on
    by the event that took state x to x_new, for loggers (a step-end sample is the state
    before the event; its result is not seen by any step end): x_minus, x_plus, pairs_plus
    and impact_loss_plus. An event can log two (an LZB impact, then an impact without
    collision where the modes after it have no consistent one): the first one's x_plus is the
    second's x_minus, with its pairs as the impact left them (before the modes were
    selected); the last one's is the event's result."""
    new = modes.impacts[n:]
    for j, imp in enumerate(new):
        x_plus = x_new.copy()
        if j < len(new) - 1:
            x_plus[ev.nq:ev.nq + ev.nv] = imp["v_plus"]
        else:
            imp.update(pairs_plus=copied_states(modes.pairs),
                       impact_loss_plus=modes.impact_loss)
        del imp["v_plus"]
        imp.update(x_minus=x.copy() if j == 0 else new[j - 1]["x_plus"], x_plus=x_plus)
