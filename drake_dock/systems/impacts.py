"""The impulsive transitions of a contact set, logged in its `ContactModes`: the LZB impact of
the couples hit (Sect. 6, with the Zeno guard) and the impact without collision at a Painleve
paradox (`drake_dock.core.iwc`). ``ev`` is the `PlantEvaluator`."""
from __future__ import annotations

import os

import numpy as np

from drake_dock.core import hybrid
from drake_dock.core.iwc import impact_without_collision
from drake_dock.core.lzb.solve import solve_lzb
from drake_dock.errors import NumericalError, PainleveInconsistency


def lzb_impact(ev, t, modes, ctx, poses, evs, S, v):
    """The LZB impact of the couples S (their `CoupleEval`s in evs), logged in ``modes``;
    returns (v+, the couples' v_n+, the approach speed)."""
    opt, law = ev.options, ev.law
    names = [ev.pairs[i].name for i in S]
    rows = [ev.row(i, evs[i], poses, ctx) for i in S]
    Wn = np.column_stack([r.Wn for r in rows])
    Wt = np.column_stack([r.Wt for r in rows])
    M = ev.plant.CalcMassMatrix(ctx)
    approach = float(-min(r.vn for r in rows))
    e = hybrid.zeno_restitution(approach, law.restitution, opt.zeno_speed)
    try:
        res = solve_lzb(M, Wn, v, law.stiffness, law.eta, e, Wt=Wt, mu=law.mu,
                        mu_s=ev.mu_s, law=law.impact_law, rtol=opt.impact_rtol,
                        compiled=opt.lzb_compiled)
    except NumericalError as err:
        if os.environ.get("DRAKE_DOCK_DUMP_LZB"):
            np.savez(os.environ["DRAKE_DOCK_DUMP_LZB"], M=M, Wn=Wn, Wt=Wt, v=v, e=e)
        raise NumericalError(f"{err} (approach speed {approach:.3e} m/s)", time=t,
                             couples=names) from None
    lost = res.kinetic_energy_minus - res.kinetic_energy_plus
    modes.impacts.append({"t": t, "couples": names, "restitution": e,
                          "normal_impulse": res.normal_impulse.tolist(),
                          "tangential_impulse": res.tangential_impulse.tolist(),
                          "energy_lost": lost})
    modes.impact_loss += lost
    return res.v_plus, Wn.T @ res.v_plus, approach


def without_collision(ev, t, modes, M, rows, v, paradox):
    """The impact without collision of the contact set ``rows`` (`ContactRow`s) at the
    Painleve paradox ``paradox`` (`drake_dock.core.iwc`), logged in ``modes`` like an impact
    (marked ``without_collision``, restitution 0); returns v+. Raises the paradox, with the
    reason, when the sticking impulse is not admissible."""
    Wn = np.column_stack([r.Wn for r in rows])
    Wt = np.column_stack([r.Wt for r in rows])
    res = impact_without_collision(M, Wn, Wt, v, ev.mu_s)
    if res is None:
        raise PainleveInconsistency(
            "no consistent contact mode (Painleve inconsistency), and the impact without "
            "collision has no sticking impulse (a couple would pull or leave the friction "
            "cone)", time=t, couples=paradox.couples) from None
    modes.impacts.append({"t": t, "couples": [r.name for r in rows], "without_collision": True,
                          "restitution": 0.0, "normal_impulse": res.P_n.tolist(),
                          "tangential_impulse": res.P_t.tolist(),
                          "energy_lost": res.energy_lost})
    modes.impact_loss += res.energy_lost
    return res.v_plus
