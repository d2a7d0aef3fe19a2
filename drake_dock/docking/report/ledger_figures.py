"""Run figures beyond the paper's: the forces of every couple that came into contact, the energy
ledger (stored energy, and the losses on their own axis), and the interface loads (force and
moment of the contact at the target's ring, the Stewart stroke)."""
from __future__ import annotations

import numpy as np

from drake_dock.docking.report.figure_kit import (PALETTE, Sheet, impact_lines, legend_beside,
                                                  time_axes, with_data)
from drake_dock.docking.report.interface_loads import interface_loads
from drake_dock.docking.report.results import IN_CONTACT, drift_text



def contact_couples(ts) -> list:
    """Indices of the couples that carried a contact force at some sample."""
    return np.flatnonzero(ts["lambda_n"].max(0, initial=0.0) > 0).tolist()


def impact_only_couples(ts) -> list:
    """Indices of the couples that took part in an impact but never carried a force."""
    return np.flatnonzero(ts["impact_couples"].any(0)
                          & ~(ts["lambda_n"].max(0, initial=0.0) > 0)).tolist()


def couple_forces_figure(ts, out, pairs=()):
    """The normal and friction force of every couple that carried a force, one panel each
    (titled with the couple in plain words, `drake_dock.docking.geometry.pairs.describe_pair`); the
    couples that only took impacts are named in the title. Not written for a run without
    contact force."""
    t = ts["t"]
    cn = ts["couple_names"].tolist()
    words = {p.name: p.description for p in pairs}
    idx = contact_couples(ts)
    if not idx:
        return None
    rows = int(np.ceil(len(idx) / 3))
    sh = Sheet(figsize=(13, 1.2 + 2.5 * rows))
    axs = sh.fig.subplots(rows, 3, sharex=True, squeeze=False)
    for ax, j in zip(axs.flat, idx):
        sh.line(ax, t, ts["lambda_n"][:, j], "normal", PALETTE[0], lw=2.6)
        friction = np.linalg.norm(ts["lambda_t"][:, j], axis=1)
        if friction.max(initial=0.0) > 0:
            sh.line(ax, t, friction, "friction", PALETTE[1], lw=1.2, ls="--")
        n_imp = int(ts["impact_couples"][:, j].sum())
        P = ts["impact_normal_impulse"][:, j].sum()
        ax.set_title(f"{cn[j]}: {words.get(cn[j], '')}\nin contact "
                     f"{(ts['status'][:, j] >= IN_CONTACT).mean():.0%} of samples, {n_imp} "
                     f"impacts ({P:.3g} N s)", fontsize=7)
        impact_lines(ax, ts)
    for ax in axs.flat[len(idx):]:
        ax.set_visible(False)
    for ax in axs[-1]:
        ax.set_xlabel("t [s]")
    for ax in axs[-2, len(idx) % 3:] if rows > 1 and len(idx) % 3 else ():
        ax.xaxis.set_tick_params(labelbottom=True)
        ax.set_xlabel("t [s]")
    sh.fig.legend(*axs[0, 0].get_legend_handles_labels(), loc="upper right", fontsize=8,
                  ncol=2)
    only = impact_only_couples(ts)
    sh.fig.suptitle(f"Contact forces [N] of the {len(idx)} couples that carried a force (of "
                    f"{len(cn)}); grey lines: impacts"
                    + ("\nimpacts without a force after them: " + ", ".join(
                        f"{cn[j]} ({ts['impact_normal_impulse'][:, j].sum():.3g} N s)"
                        for j in only) if only else ""))
    return sh.save(out, "couple_forces.png")


def energy_ledger_figure(ts, summary, out):
    """Left: the kinetic energy. Right, on its own axis: where the kinetic energy lost went
    (Stewart potential gained, damper, friction, impacts, stacked), against the kinetic
    energy lost plus the work of the thrust on the chaser (its inputs; black dashed, the work
    itself dotted): the ledger closes when they meet."""
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
    driven = np.ptp(E["input_work"]) > 0
    if driven:                  # post-contact thrust (and any wrench on the chaser's input)
        a_l.plot(t, E["input_work"], color="0.45", ls=":", lw=1.5, label="work of the thrust")
    a_l.plot(t, lost, "k--", lw=1.2, label="kinetic energy lost + work of the thrust"
             if driven else "kinetic energy lost")
    a_l.set_ylabel("energy [J]")
    legends = [(a_l, legend_beside(a_l))]
    for ax in (a_k, a_l):
        impact_lines(ax, ts)
        ax.set_xlabel("t [s]")
    led = summary["energy_ledger"]
    com = led.get("initial_centre_of_mass_motion_J")
    sh.fig.suptitle(f"Energy ledger (inertial frame): initial {led['initial_total_J']:.4g} J"
                    + ("" if com is None else f", of which {com:.4g} J in the motion of the "
                       f"centre of mass") + f"\nlosses on the right (closure "
                    f"{drift_text(led['closure_error_relative'])} of the initial "
                    f"energy)")
    return sh.save(out, "energy_ledger.png", legends)


def interface_loads_figure(ts, pairs, out):
    """Force and moment of the contact on the target APDS (about its ring centre, in its
    frame: z the docking axis) and the Stewart stroke (deflection of the APDS frame from its
    anchor on the target: translation and roll-pitch-yaw); panels that are zero throughout are
    not drawn, and the figure not written when all are (a run without contact)."""
    t = ts["t"]
    loads = interface_loads(ts, pairs)
    F, M = loads["F_A"], loads["M_A"]
    panels = [({f"F_{c}": F[:, k] for k, c in enumerate("xyz")}, "N",
               "contact force on the target APDS [N]"),
              ({f"M_{c}": M[:, k] for k, c in enumerate("xyz")}, "N m",
               "moment about its ring centre [N m]"),
              ({c: 1e3 * ts["stewart_x"][:, k] for k, c in enumerate("xyz")}, "mm",
               "Stewart stroke, translation [mm]"),
              ({c: np.degrees(ts["stewart_rpy"][:, k])
                for k, c in enumerate(("roll", "pitch", "yaw"))}, "deg",
               "Stewart stroke, rotation [deg]")]
    kept = with_data(panels)
    if not kept:
        return None
    rows = int(np.ceil(len(kept) / 2))
    sh = Sheet(figsize=(12, 0.5 + 3.0 * rows))
    axs = sh.fig.subplots(rows, 2, sharex=True, squeeze=False)
    for ax, (curves, unit, label) in zip(axs.flat, kept):
        sh.curves(ax, t, curves, unit)
        ax.set_ylabel(label, fontsize=9)
    for ax in axs.flat[len(kept):]:
        ax.set_visible(False)
    gone = [p[2].split(" [")[0] for p in panels if all(p is not k for k in kept)]
    if gone:
        sh.note(axs.flat[0], "zero throughout: " + "; ".join(gone))
    used = list(axs.flat[:len(kept)])
    legends = time_axes(used, ts, xlabel=False)
    for ax in used[-2:]:
        ax.set_xlabel("t [s]")
        ax.xaxis.set_tick_params(labelbottom=True)
    sh.fig.suptitle("Interface loads at the target's ring (target APDS frame, z: docking axis; "
                    "impulses not included) and the Stewart stroke")
    return sh.save(out, "interface_loads.png", legends)
