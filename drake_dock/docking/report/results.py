"""The arrays of timeseries.npz and the numbers of summary.json, from a `RunResult`.

Field layout (C: the couples; all of the scene's in memory, those that came near in
timeseries.npz, `near_timeseries`): t[N]; body_names[3]; p_WB[N,3,3], R_WB[N,3,3,3], v_WB[N,3,3],
w_WB[N,3,3] (mass centres, world frame); apds_names[2]; p_WA[N,2,3], R_WA[N,2,3,3] (ring centre,
e3 along the axis towards the other APDS); couple_names[C]; status[N,C] (the pair's `Mode`: 0
far, 1 tracked, 2 sliding, 3 sticking); active[N,C] (tracked or in contact); gap[N,C];
lambda_n[N,C]; lambda_t[N,C,2];
u[N,C,3] (couple parameters, unused entries 0); p1_W[N,C,3], p2_W[N,C,3]; frame_W[N,C,3,3]
(columns ta, tb, n: the contact frame, n from the couple's body 2 to its body 1; the identity
for far couples); stewart_x[N,3] (m), stewart_rpy[N,3] (rad) (the Stewart element's deflection,
`drake_dock.docking.model.plant.stewart_deflection`); stewart_force_W[N,3] (N, its force on the
target APDS in the world frame); sample_kind[N]
(0 step end, 1 just before an impact, 2 just after); ring_distance[N]; energy[N,k] with
energy_names[k]; impact_t[M], impact_couples[M,C] (bool), impact_normal_impulse[M,C],
impact_tangential_impulse[M,C,2], impact_restitution[M]; thrust_force_W[N,3] (N, the
post-contact thrust on the chaser, world frame; zero without a ``thrust`` section).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from drake_dock.core.hybrid import Mode
from drake_dock.docking.geometry.pairs import CHASER_APDS
from drake_dock.docking.model.outcome import misalignment
from drake_dock.docking.model.plant import APDS_NAMES, BODY_NAMES
from drake_dock.docking.model.simulate import PRE_IMPACT
from drake_dock.docking.model.thrust import ThrustSchedule
from drake_dock.docking.report.interface_loads import peak_loads
from drake_dock.docking.scenario.loading import scenario_dict
from drake_dock.systems.contact_system import COUPLE_SLICES

IN_CONTACT = Mode.SLIDING   # status codes >= IN_CONTACT: in contact (sliding or sticking)


def timeseries(result, couples: bool = True) -> dict:
    """The run's arrays (module docstring); without ``couples`` the per-couple ones are left
    out (a campaign's row needs none of them) and ``lambda_n_max`` (N,) holds each sample's
    largest normal force."""
    dd = result.dd
    rec = result.record
    contact = dd.contact
    eng = contact.engine
    X = rec.x
    N = len(rec.t)
    nq = contact.nq
    # The bodies' and the ring frames' poses and twists from the samples' states (compiled
    # kinematics; bodies in the plant's order, frames by name).
    body_at = [next(k for k in range(eng.nb) if int(eng.model.qs[k]) ==
                    dd.dp.bodies[name].floating_positions_start()) for name in BODY_NAMES]
    frame_at = [next(f for f, fr in enumerate(eng.frames)
                     if fr.index() == dd.dp.apds_frames[name].index()) for name in APDS_NAMES]
    p_WB, R_WB = np.zeros((N, 3, 3)), np.zeros((N, 3, 3, 3))
    v_WB, w_WB = np.zeros((N, 3, 3)), np.zeros((N, 3, 3))
    p_WA, R_WA = np.zeros((N, 2, 3)), np.zeros((N, 2, 3, 3))
    for k in range(N):
        kin = eng.kinematics(X[k, :nq], X[k, nq:])
        p_WB[k], R_WB[k] = kin.pb[body_at], kin.Rb[body_at]
        v_WB[k], w_WB[k] = kin.vb[body_at], kin.wb[body_at]
        p_WA[k], R_WA[k] = kin.o[frame_at], kin.R[frame_at]
    bush = rec.bushings[:, 0]
    sx, srpy, sf = bush[:, 0:3], bush[:, 3:6], bush[:, 9:12]
    energy = np.asarray(rec.energy)
    energy_names = list(dd.contact.energy_names)
    common = dict(
        t=np.asarray(rec.t), body_names=np.array(BODY_NAMES), p_WB=p_WB, R_WB=R_WB, v_WB=v_WB,
        w_WB=w_WB, apds_names=np.array(APDS_NAMES), p_WA=p_WA, R_WA=R_WA,
        stewart_x=sx, stewart_rpy=srpy, stewart_force_W=sf,
        sample_kind=np.asarray(rec.kind, dtype=np.int8),
        ring_distance=np.asarray(rec.ring_distance), energy=energy,
        energy_names=np.array(energy_names),
        impact_t=np.array([imp.t for imp in result.impacts], dtype=float),
        impact_restitution=np.array([imp.restitution for imp in result.impacts], dtype=float),
        thrust_force_W=thrust_forces(result, np.asarray(rec.t), R_WB[:, BODY_NAMES.index(
            "chaser")]))
    if not couples:
        return dict(common, lambda_n_max=rec.derive(False)["lambda_n_max"])
    C = np.asarray(rec.couples)
    S = COUPLE_SLICES
    status = C[:, :, S["status"]][..., 0].astype(np.int8)
    names = [p.name for p in dd.contact.pairs]
    M = len(result.impacts)
    imp_c = np.zeros((M, len(names)), bool)
    imp_n = np.zeros((M, len(names)))
    imp_t = np.zeros((M, len(names), 2))
    for m, imp in enumerate(result.impacts):
        for c, pn, pt in zip(imp.couples, imp.normal_impulse, imp.tangential_impulse):
            j = names.index(c)
            imp_c[m, j], imp_n[m, j], imp_t[m, j] = True, pn, pt
    return dict(
        common, couple_names=np.array(names), status=status, active=status >= Mode.TRACKED,
        gap=C[:, :, S["gap"]][..., 0], lambda_n=C[:, :, S["lambda_n"]][..., 0],
        lambda_t=C[:, :, S["lambda_t"]], u=C[:, :, S["u"]], p1_W=C[:, :, S["p1"]],
        p2_W=C[:, :, S["p2"]], frame_W=C[:, :, S["frame"]].reshape(N, -1, 3, 3),
        impact_couples=imp_c, impact_normal_impulse=imp_n, impact_tangential_impulse=imp_t)


def first_contact_time(result) -> float:
    """The time of the run's first impact (s; every contact starts with one), inf without."""
    return float(result.impacts[0].t) if result.impacts else math.inf


def thrust_forces(result, t, R_WC) -> np.ndarray:
    """The thrust on the chaser at the samples t (N,) with its rotations R_WC (N, 3, 3): the
    force times its docking axis (the APDS frame's e3, parallel to the chaser's) where the
    schedule acts (`drake_dock.docking.model.thrust.ThrustSchedule`), else zero. At the first
    impact, the sample just before it has none."""
    schedule = ThrustSchedule.of(result.scenario.thrust)
    F = np.zeros((len(t), 3))
    tc = first_contact_time(result)
    if schedule is None or not math.isfinite(tc):
        return F
    kinds = np.asarray(result.record.kind)
    for k in range(len(t)):
        if schedule.on(t[k] - tc) and not (t[k] == tc and kinds[k] == PRE_IMPACT):
            F[k] = schedule.force * R_WC[k][:, 2]
    return F


def thrust_impulses(result, ts: dict, about) -> tuple[np.ndarray, np.ndarray]:
    """The linear impulse J[N,3] and the angular impulse H[N,3] about the fixed point
    ``about`` of the thrust from t = 0 to each sample: over each sample interval, the part in
    which the schedule acts, by the trapezoid rule on the force F e3 and the moment
    (p - about) x F e3 of the chaser's mass centre p, linear between the samples (the switch
    times are exact; the rest is second order in the step)."""
    t = ts["t"]
    N = len(t)
    J, H = np.zeros((N, 3)), np.zeros((N, 3))
    schedule = ThrustSchedule.of(result.scenario.thrust)
    tc = first_contact_time(result)
    if schedule is None or not math.isfinite(tc) or N < 2:
        return J, H
    j = ts["body_names"].tolist().index("chaser")
    f = schedule.force * ts["R_WB"][:, j, :, 2]
    tau = np.cross(ts["p_WB"][:, j] - np.asarray(about), f)
    a, b = t[:-1], t[1:]
    width = np.where(b > a, b - a, 1.0)
    dJ, dH = np.zeros((N - 1, 3)), np.zeros((N - 1, 3))
    for w0, w1 in schedule.windows:
        lo, hi = np.maximum(a, tc + w0), np.minimum(b, tc + w1)
        on = np.flatnonzero(hi > lo)
        for d, y in ((dJ, f), (dH, tau)):
            y0, y1 = y[on], y[on + 1]
            ya = y0 + (y1 - y0) * ((lo[on] - a[on]) / width[on])[:, None]
            yb = y0 + (y1 - y0) * ((hi[on] - a[on]) / width[on])[:, None]
            d[on] += 0.5 * (hi[on] - lo[on])[:, None] * (ya + yb)
    J[1:], H[1:] = np.cumsum(dJ, axis=0), np.cumsum(dH, axis=0)
    return J, H


def rigid_chaser_force(result):
    """(t, F): the net contact force on the chaser [N, 3] at the samples of a drake_dock
    `RunResult`, from the couples' lambda_n, lambda_t and frames."""
    rec = result.record
    sign = np.array([1.0 if p.body1 == CHASER_APDS else -1.0
                     for p in result.scene.pairs])
    t = np.asarray(rec.t)
    C = np.asarray(rec.couples)
    frames = C[:, :, COUPLE_SLICES["frame"]].reshape(len(t), -1, 3, 3)
    lam = np.concatenate([C[:, :, COUPLE_SLICES["lambda_t"]],
                          C[:, :, COUPLE_SLICES["lambda_n"]]], axis=2)
    return t, np.einsum("c,kcxy,kcy->kx", sign, frames, lam)


def momenta(ts: dict, masses, inertias, about):
    """Total linear momentum P[N,3] and angular momentum L[N,3] about the fixed point
    ``about``, from the sampled motion and the bodies' masses and principal inertias, and their
    scales at t = 0: sum |m v| and sum |m (p - about) x v| + |I w|."""
    m = np.asarray(masses, float)[None, :, None]
    mv = m * ts["v_WB"]
    r = ts["p_WB"] - np.asarray(about)[None, None, :]
    R = ts["R_WB"]
    Ib = np.stack([np.diag(I) for I in inertias])
    Iw = np.einsum("nbij,bjk,nblk,nbl->nbi", R, Ib, R, ts["w_WB"])
    P = mv.sum(1)
    L = (np.cross(r, mv) + Iw).sum(1)
    sP = np.linalg.norm(mv[0], axis=1).sum()
    sL = (np.linalg.norm(np.cross(r[0], mv[0]), axis=1) + np.linalg.norm(Iw[0], axis=1)).sum()
    return P, L, sP, sL


def momentum_reference_point(scenario, ts) -> np.ndarray:
    """A fixed world point off the docking axis: the target ring's rim at t = 0 (on the axis
    the initial angular momentum and its scale are both zero)."""
    return ts["p_WA"][0, 0] + scenario.geometry.R * ts["R_WA"][0, 0][:, 0]


def relative(value, scale):
    """value / scale; None (null in summary.json) when the scale is zero (a chaser so slow
    that its kinetic energy underflows): the ratio is undefined, not NaN."""
    return float(value / scale) if scale > 0 else None


ROUND_OFF = 1e-10    # a relative drift or closure below it is round-off, shown as such


def relative_text(x, spec=".2e") -> str:
    """A relative quantity of the summary as text ("undefined" for None)."""
    return "undefined" if x is None else format(x, spec)


def drift_text(x, spec=".1e") -> str:
    """A relative drift or closure for a figure's title: its value, or "< 1e-10 (round-off)"
    below `ROUND_OFF` (the digits of round-off move with any change of the arithmetic, and a
    figure should not)."""
    if x is not None and abs(x) < ROUND_OFF:
        return f"< {ROUND_OFF:g} (round-off)"
    return relative_text(x, spec)


def centre_of_mass_kinetic_energy(ts: dict, masses) -> np.ndarray:
    """|P|^2 / (2 M) [N] (J): the kinetic energy of the motion of the system's centre of mass
    (P the total linear momentum, M the total mass). Contact cannot change it; only an input
    (thrust) can."""
    m = np.asarray(masses, float)
    P = np.einsum("b,nbi->ni", m, ts["v_WB"])
    return np.einsum("ni,ni->n", P, P) / (2.0 * m.sum())


def first_contact_sample(ts: dict) -> int | None:
    """The first sample at which a couple is in contact or an impact happens (the sample just
    before it), or None for a run without contact."""
    hits = np.flatnonzero((ts["status"] >= IN_CONTACT).any(1) | (ts["sample_kind"] == 1))
    return int(hits[0]) if hits.size else None


def relative_kinetic_energy_at_contact(ts: dict, masses) -> float | None:
    """The kinetic energy in the system's centre-of-mass frame (the inertial kinetic energy
    minus `centre_of_mass_kinetic_energy`) at the first contact (`first_contact_sample`): what
    the contact, the damper and the Stewart spring can act on; 1/2 mu v^2 for two bodies
    closing at v without rotation (mu the reduced mass). None without contact."""
    k = first_contact_sample(ts)
    if k is None:
        return None
    kinetic = ts["energy"][:, ts["energy_names"].tolist().index("kinetic")]
    return float(kinetic[k] - centre_of_mass_kinetic_energy(ts, masses)[k])


def energy_ledger(ts: dict, masses=None) -> dict:
    """The ledger in the inertial (world) frame: kinetic + Stewart potential + dissipated
    (damper, friction, impacts) - input work must equal the initial total; closure is the
    largest |residual| over the run relative to it. With ``masses``, the part of the initial
    total in the motion of the centre of mass (`centre_of_mass_kinetic_energy`), which no
    contact dissipates."""
    E = dict(zip(ts["energy_names"].tolist(), ts["energy"].T))
    ke, pe = E["kinetic"], E["potential"]
    damper = -E["stewart_damper_work"]
    friction, impacts, inputs = E["friction_loss"], E["impact_loss"], E["input_work"]
    total0 = ke[0] + pe[0]
    residual = ke + pe + damper + friction + impacts - inputs - total0
    out = {"frame": "inertial (world)", "initial_total_J": float(total0)}
    if masses is not None:
        out["initial_centre_of_mass_motion_J"] = float(
            centre_of_mass_kinetic_energy(ts, masses)[0])
    out.update({"kinetic_J": float(ke[-1]),
                "stewart_potential_J": float(pe[-1]), "dissipated_damper_J": float(damper[-1]),
                "dissipated_friction_J": float(friction[-1]),
                "dissipated_impacts_J": float(impacts[-1]), "input_work_J": float(inputs[-1]),
                "closure_error_relative": relative(np.abs(residual).max(), abs(total0))})
    return out


def final_misalignment(ts: dict) -> dict:
    """The chaser ring's pose in the target ring's frame at the end: axial and lateral offset
    of its centre (m) and the tilt between the two docking axes (deg; `misalignment`)."""
    names = ts["apds_names"].tolist()
    j_t, j_c = names.index("target_apds"), names.index("chaser_apds")
    axial, lateral, tilt = misalignment(ts["R_WA"][-1, j_t], ts["p_WA"][-1, j_t],
                                        ts["R_WA"][-1, j_c], ts["p_WA"][-1, j_c])
    return {"axial_m": axial, "lateral_m": lateral, "tilt_deg": math.degrees(tilt)}


def near_couples(ts: dict) -> np.ndarray:
    """Indices of the couples that came near: tracked or in contact at some sample, or in an
    impact. The others stayed far throughout (their rows hold no contact)."""
    return np.flatnonzero((ts["status"] > Mode.FAR).any(0) | ts["impact_couples"].any(0))


# The per-couple arrays of a timeseries and the axis that runs over the couples.
PER_COUPLE = {"couple_names": 0, "status": 1, "active": 1, "gap": 1, "lambda_n": 1,
              "lambda_t": 1, "u": 1, "p1_W": 1, "p2_W": 1, "frame_W": 1, "impact_couples": 1,
              "impact_normal_impulse": 1, "impact_tangential_impulse": 1}


def near_timeseries(ts: dict) -> dict:
    """The timeseries with the per-couple arrays cut to the couples that came near
    (`near_couples`), as timeseries.npz holds it: the other couples stayed far, their rows hold
    no contact."""
    near = near_couples(ts)
    return {k: np.take(v, near, axis=PER_COUPLE[k]) if k in PER_COUPLE else v
            for k, v in ts.items()}


def couples_table(ts: dict, pairs) -> dict:
    """{couple: its description in plain words (`drake_dock.docking.geometry.pairs.describe_pair`),
    the share of samples in contact, its peak normal force, its impacts and their normal
    impulse} for the couples that came near (`near_couples`)."""
    words = {p.name: p.description for p in pairs}
    names = ts["couple_names"].tolist()
    out = {}
    for j in near_couples(ts):
        lam = ts["lambda_n"][:, j]
        out[names[j]] = {
            "description": words[names[j]],
            "in_contact_share": float((ts["status"][:, j] >= IN_CONTACT).mean()),
            "peak_normal_force_N": float(lam.max(initial=0.0)),
            "impacts": int(ts["impact_couples"][:, j].sum()),
            "normal_impulse_Ns": float(ts["impact_normal_impulse"][:, j].sum())}
    return out


def non_finite_key(node, path=""):
    """The dotted key of the first non-finite number in a summary (`summary`), or None."""
    if isinstance(node, dict):
        items = node.items()
    elif isinstance(node, (list, tuple)):
        items = enumerate(node)
    else:
        return (path or "value") if isinstance(node, float) and not np.isfinite(node) else None
    for k, v in items:
        bad = non_finite_key(v, f"{path}.{k}" if path else str(k))
        if bad is not None:
            return bad
    return None


def summary(result, ts: dict) -> dict:
    """The numbers of a run for a docking engineer (summary.json): the outcome and its reason,
    capture, the final misalignment, the peak loads
    (`drake_dock.docking.report.interface_loads.peak_loads`), the relative kinetic energy at
    contact, the energy ledger, the impacts, the momentum drift, the first contact and the
    couples that came near (`couples_table`). The solver's cost is apart
    (`drake_dock.docking.report.cost.run_cost`)."""
    s = result.scenario
    b = s.bodies
    params = [getattr(b, n) for n in ts["body_names"]]
    masses = [p.mass for p in params]
    about = momentum_reference_point(s, ts)
    P, L, sP, sL = momenta(ts, masses, [p.inertia for p in params], about)
    J, H = thrust_impulses(result, ts, about)       # the only external forces
    pairs = result.scene.pairs
    imp = ts["impact_normal_impulse"]
    return {
        "outcome": result.outcome,
        "outcome_reason": result.reason,
        "captured": bool(result.captured),
        "capture_time_s": result.capture_time,
        "end_time_s": result.end_time,
        "final_misalignment": final_misalignment(ts),
        "capture_tolerances": {"axial_m": s.simulation.capture_distance,
                               "lateral_m": s.simulation.capture_lateral,
                               "tilt_deg": s.simulation.capture_tilt_deg},
        "loads": peak_loads(ts, pairs),
        "relative_kinetic_energy_at_contact_J": relative_kinetic_energy_at_contact(ts, masses),
        "energy_ledger": energy_ledger(ts, masses),
        "number_of_impacts": len(result.impacts),
        "impact_times_s": ts["impact_t"].tolist(),
        "largest_impulse_Ns": float(imp.max()) if imp.size else 0.0,
        "momentum_drift_relative": {
            "linear": relative(np.linalg.norm(P - P[0] - J, axis=1).max(), sP),
            "angular": relative(np.linalg.norm(L - L[0] - H, axis=1).max(), sL)},
        "end_state": {
            "holding_couples": [dataclasses.asdict(h) for h in result.holding],
            "relative_kinetic_energy_J": (None if math.isnan(result.relative_kinetic_energy)
                                          else result.relative_kinetic_energy)},
        "thrust": None if s.thrust is None else {
            "force_N": s.thrust.force, "windows_after_contact_s": [
                [a, None if math.isinf(b) else b] for a, b in ThrustSchedule.of(s.thrust).windows],
            "first_contact_time_s": (first_contact_time(result) if result.impacts else None),
            "impulse_Ns": float(np.linalg.norm(J[-1]))},
        "first_contact_ring_distance_m": result.initial.d_contact,
        "first_contact_lateral_offset_m": list(result.initial.contact_offset),
        "initial_ring_distance_m": result.initial.d0,
        "first_closing_couples": list(result.initial.closing_pairs),
        "couples": couples_table(ts, pairs),
        "scenario": scenario_dict(s),
    }
