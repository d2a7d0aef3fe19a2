"""Run figures beyond the paper's: the forces of every couple that came into contact, the energy
ledger (stored energy, and the losses on their own axis), and the interface loads (force and
moment of the contact at the target's ring, the Stewart stroke)."""
from __future__ import annotations

import numpy as np

from drake_dock.docking.figure_kit import (PALETTE, Sheet, impact_lines, legend_beside,
                                           time_axes)
from drake_dock.docking.loads import interface_loads
from drake_dock.docking.results import IN_CONTACT, relative_text



def contact_couples(ts) -> list:
    """Indices of the couples ever in contact or taking part in an impact."""
    ever = (ts["status"] >= IN_CONTACT).any(0) | ts["impact_couples"].any(0)
    return np.flatnonzero(ever).tolist()


def couple_forces_figure(ts, out):
    t = ts["t"]
    cn = ts["couple_names"].tolist()
    idx = contact_couples(ts)
    rows = max(1, int(np.ceil(len(idx) / 3)))
    sh = Sheet(figsize=(12, 1.0 + 2.3 * rows))
    axs = sh.fig.subplots(rows, 3 if idx else 1, sharex=True, squeeze=False)
    if not idx:
        sh.note(axs[0, 0], "no couple came into contact")
        axs[0, 0].set_xlabel("t [s]")
        return sh.save(out, "couple_forces.png")
    for ax, j in zip(axs.flat, idx):
        sh.line(ax, t, ts["lambda_n"][:, j], "lambda_n", PALETTE[0], lw=2.6)
        sh.line(ax, t, np.linalg.norm(ts["lambda_t"][:, j], axis=1), "|lambda_t|", PALETTE[1],
                lw=1.2, ls="--")
        n_imp = int(ts["impact_couples"][:, j].sum())
        P = ts["impact_normal_impulse"][:, j].sum()
        ax.set_title(f"{cn[j]}: in contact {(ts['status'][:, j] >= IN_CONTACT).mean():.0%} of "
                     f"samples, {n_imp} impacts ({P:.3g} N s)", fontsize=8)
        impact_lines(ax, ts)
    for ax in axs.flat[len(idx):]:
        ax.set_visible(False)
    for ax in axs[-1]:
        ax.set_xlabel("t [s]")
    sh.fig.legend(*axs[0, 0].get_legend_handles_labels(), loc="upper right", fontsize=8,
                  ncol=2)
    sh.fig.suptitle(f"Contact forces [N] of the {len(idx)} couples that came into contact "
                    f"(of {len(cn)}); grey lines: impacts")
    return sh.save(out, "couple_forces.png")


def energy_ledger_figure(ts, summary, out):
    """Left: the kinetic energy. Right, on its own axis: where the kinetic energy lost went
    (Stewart potential gained, damper, friction, impacts, stacked), against the kinetic
    energy lost plus the input work (black dashed): the ledger closes when they meet."""
    t = ts["t"]
    E = dict(zip(ts["energy_names"].tolist(), ts["energy"].T))
    sinks = {"Stewart potential": E["potential"] - E["potential"][0],
             "damper": -E["stewart_damper_work"], "friction": E["friction_loss"],
             "impacts": E["impact_loss"]}
    sh = Sheet(figsize=(12, 4.2))
    a_k, a_l = sh.fig.subplots(1, 2)
    sh.line(a_k, t, E["kinetic"], "kinetic", PALETTE[0])
    a_k.set_ylabel("kinetic energy [J]")
    cols = PALETTE[1:1 + len(sinks)]
    a_l.stackplot(t, *sinks.values(), labels=list(sinks), colors=cols)
    for label, col in zip(sinks, cols):
        if np.ptp(sinks[label]) > 0:
            sh.add(a_l, label, col)
    lost = E["kinetic"][0] - E["kinetic"] + E["input_work"]
    a_l.plot(t, lost, "k--", lw=1.2, label="kinetic energy lost + input work")
    a_l.set_ylabel("energy [J]")
    legends = [(a_l, legend_beside(a_l))]
    for ax in (a_k, a_l):
        impact_lines(ax, ts)
        ax.set_xlabel("t [s]")
    led = summary["energy_ledger"]
    sh.fig.suptitle(f"Energy ledger: initial {led['initial_total_J']:.4g} J; losses on the "
                    f"right (closure {relative_text(led['closure_error_relative'], '.1e')} of "
                    f"the initial energy)")
    return sh.save(out, "energy_ledger.png", legends)


def interface_loads_figure(ts, pairs, out):
    """Force and moment of the contact on the target APDS (about its ring centre, in its
    frame: z the docking axis) and the Stewart stroke (deflection of the APDS frame from its
    anchor on the target: translation and roll-pitch-yaw)."""
    t = ts["t"]
    loads = interface_loads(ts, pairs)
    F, M = loads["F_A"], loads["M_A"]
    sh = Sheet(figsize=(12, 6.5))
    axs = sh.fig.subplots(2, 2, sharex=True)
    sh.curves(axs[0, 0], t, {f"F_{c}": F[:, k] for k, c in enumerate("xyz")}, "N")
    sh.curves(axs[0, 1], t, {f"M_{c}": M[:, k] for k, c in enumerate("xyz")}, "N m")
    sh.curves(axs[1, 0], t, {c: 1e3 * ts["stewart_x"][:, k] for k, c in enumerate("xyz")},
              "mm")
    sh.curves(axs[1, 1], t, {c: np.degrees(ts["stewart_rpy"][:, k])
                             for k, c in enumerate(("roll", "pitch", "yaw"))}, "deg")
    labels = (("contact force on the target APDS [N]", "moment about its ring centre [N m]"),
              ("Stewart stroke, translation [mm]", "Stewart stroke, rotation [deg]"))
    for ax, label in zip(axs.flat, sum(labels, ())):
        ax.set_ylabel(label, fontsize=9)
    legends = time_axes(axs.flat, ts, xlabel=False)
    for ax in axs[1]:
        ax.set_xlabel("t [s]")
    sh.fig.suptitle("Interface loads at the target's ring (target APDS frame, z: docking axis; "
                    "impulses not included) and the Stewart stroke")
    return sh.save(out, "interface_loads.png", legends)
