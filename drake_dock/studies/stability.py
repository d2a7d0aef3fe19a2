"""Stability where methods fail (`drake-dock study stability`): five cases, each with
drake_dock's documented behaviour, a figure and the data it is drawn from.

(a) ``step_size``: the docking example's sliding phase (window [t_c / 2, t_c]). Compliant point
    contact (SAP) at several time steps and stiffnesses against drake_dock at several output
    steps (its maximum step). Sawtooth index of the net contact force on the chaser: the largest
    deviation of a sample from the line through its two neighbours, over the mean force
    (`sawtooth_index`; 0 for a straight line, O(h^2 F''/F) for a smooth force). A compliant
    configuration "shows a sawtooth" above ``SAWTOOTH`` = 5 %.
(b) ``stiffness_ratio``: LZB's stiffness-ratio effect. Three equal balls, the first hitting the
    two at rest, the two contacts' stiffness ratio K2/K1 from 1e-3 to 1e3 (elastic, Hertz
    eta = 1.5): LZB's post-impact velocities against the compliant chain integrated in time
    (`drake_dock.core.lzb.limit.continuous_limit_chain`), and the cost of each.
(c) ``high_friction``: Painleve's rod (`small_scenes.painleve_rod`, tip sliding at 1 m/s, 30 deg)
    over mu: lambda_n against the planar closed form below the critical mu_c, a
    `PainleveError` naming the couple and the time above it; and the docking example at higher
    friction (full mode).
(d) ``grazing``: a disk whose trajectory reaches the plane with a minimum gap delta
    (gravity away from the plane): no impact for delta > 0; for delta < 0 the impact at the
    closed-form crossing time with approach speed sqrt(2 g |delta|).
(e) ``zeno``: a disk bouncing with e = 0.5: the number of impacts the Zeno guard allows,
    against the closed form, over zeno_speed; and `ZenoError` at ``max_impacts`` when the guard
    is off.
"""
import copy
import dataclasses
import json
import math
import time as _time
from pathlib import Path

import numpy as np

from drake_dock.core.hybrid import Mode
from drake_dock.core.lzb.limit import continuous_limit_chain
from drake_dock.core.lzb.solve import solve_lzb
from drake_dock.docking.report.results import rigid_chaser_force
from drake_dock.errors import PainleveError, ZenoError
from drake_dock.errors import DrakeDockError, NumericalError
from drake_dock.studies.small_scenes import (G, PAINLEVE_THETA, SmallRun, disk_on_incline,
                                             painleve_closed_form, painleve_rod, painleve_state)
from drake_dock.systems.contact_system import COUPLE_SLICES, ContactOptions

SAWTOOTH = 0.05


# ------------------------------------------------------------------------------- helpers
def sawtooth_index(t, F) -> float:
    """max_k |F_k - L_k| / mean |F| over interior samples, L_k the line through the neighbours'
    (t, F) (samples at equal times are merged, the last kept)."""
    t, F = np.asarray(t, float), np.asarray(F, float)
    keep = np.r_[np.diff(t) > 0, True]
    t, F = t[keep], F[keep]
    if len(t) < 3:
        return math.nan
    a = (t[1:-1] - t[:-2]) / (t[2:] - t[:-2])
    line = F[:-2] + a * (F[2:] - F[:-2])
    return float(np.abs(F[1:-1] - line).max() / np.abs(F).mean())


# ------------------------------------------------------------------------ (a) step size
RIGID_STEP_ACCURACY = 1e-8


def step_size_case(scenario, *, output_steps, compliant_steps, stiffnesses, log=print) -> dict:
    from drake_dock.docking.model.simulate import simulate
    from drake_dock.docking.placement.place import place
    from drake_dock.studies.compliant import (CompliantConfig, hunt_crossley_dissipation,
                                              run_compliant)
    state = place(scenario)
    rigid = []
    for H in output_steps:
        sc = copy.deepcopy(scenario)
        sc.simulator_config.max_step_size = H
        # Tight enough that the integration error does not hide the curve's own shape (the
        # runs at different output steps are compared sample by sample).
        sc.simulator_config.accuracy = min(sc.simulator_config.accuracy, RIGID_STEP_ACCURACY)
        r = simulate(sc, state=state)
        t, F = rigid_chaser_force(r)
        tc = r.capture_time
        w = (t >= 0.5 * tc) & (t <= tc)
        rigid.append(dict(step=H, t=t[w].tolist(), F=np.linalg.norm(F[w], axis=1).tolist(),
                          index=sawtooth_index(t[w], np.linalg.norm(F[w], axis=1)),
                          wall_time=r.wall_time, capture_time=tc))
        log(f"  (a) drake_dock output step {H:.0e}: sawtooth {rigid[-1]['index']:.2e}, "
            f"capture {tc:.6f} s, {r.wall_time:.2f} s")
    tc_ref = rigid[0]["capture_time"]
    d_hc = hunt_crossley_dissipation(scenario.contact.restitution,
                                     scenario.initial.chaser_speed)
    compliant = []
    for k in stiffnesses:
        for h in compliant_steps:
            cfg = CompliantConfig("point", k, h, dissipation=d_hc)
            r = run_compliant(scenario, state, cfg, t_max=2 * tc_ref, wall_limit=90.0)
            tc = r.capture_time if r.captured else tc_ref
            tm = 0.5 * (r.t[1:] + r.t[:-1])
            Fn = np.linalg.norm(r.force, axis=1)
            w = (tm >= 0.5 * tc) & (tm <= tc)
            ok = r.error is None and np.all(np.isfinite(Fn))
            idx = sawtooth_index(tm[w], Fn[w]) if ok else math.inf
            compliant.append(dict(stiffness=k, step=h, t=tm[w].tolist(), F=Fn[w].tolist(),
                                  index=idx, wall_time=r.wall_time, captured=bool(r.captured),
                                  error=r.error))
            log(f"  (a) compliant point k={k:.0e} h={h:.0e}: sawtooth {idx:.2e}, "
                f"captured {r.captured}, {r.wall_time:.2f} s")
    limits = {}
    for k in stiffnesses:
        smooth = [c["step"] for c in compliant if c["stiffness"] == k and c["index"] <= SAWTOOTH]
        limits[f"{k:.0e}"] = max(smooth) if smooth else None
    return dict(rigid=rigid, compliant=compliant, threshold=SAWTOOTH,
                largest_smooth_compliant_step=limits)


# ------------------------------------------------------------------- (b) stiffness ratio
def chain_matrices(n):
    """n unit balls in a row; couple j between balls j and j + 1."""
    Wn = np.zeros((n, n - 1))
    for j in range(n - 1):
        Wn[j, j], Wn[j + 1, j] = -1.0, 1.0
    return np.eye(n), Wn


def stiffness_ratio_case(ratios, *, eta=1.5, log=print) -> dict:
    M, Wn = chain_matrices(3)
    v0 = np.array([1.0, 0.0, 0.0])
    rows = []
    for ratio in ratios:
        K = np.array([1e7, 1e7 * ratio])
        t0 = _time.perf_counter()
        res = solve_lzb(M, Wn, v0, K, eta, 1.0, rtol=1e-12)
        t_lzb = _time.perf_counter() - t0
        t0 = _time.perf_counter()
        ref = continuous_limit_chain(np.ones(3), v0, K, eta, 1.0)
        t_ref = _time.perf_counter() - t0
        rows.append(dict(ratio=ratio, lzb=res.v_plus.tolist(), compliant=ref.tolist(),
                         difference=float(np.abs(res.v_plus - ref).max()), lzb_steps=res.steps,
                         lzb_wall=t_lzb, compliant_wall=t_ref))
        log(f"  (b) K2/K1 = {ratio:.0e}: v+ = {np.round(res.v_plus, 6).tolist()}, "
            f"|LZB - compliant| {rows[-1]['difference']:.1e}")
    return dict(eta=eta, rows=rows)


# ---------------------------------------------------------------------- (c) high friction
def high_friction_case(mus, *, scenario=None, docking_mus=(), log=print) -> dict:
    rod = []
    for mu in mus:
        # The rigid model alone: stop at the paradox (the contact system would otherwise
        # resolve it by an impact without collision, `ContactOptions.painleve`).
        sc = painleve_rod(PAINLEVE_THETA, mu=mu, options=ContactOptions(painleve="error"))
        X, V = painleve_state(sc)
        lam_cf, mu_c = painleve_closed_form(mu)
        try:
            run = SmallRun(sc.system, lambda c: sc.set_state(c, X, V))
            rod.append(dict(mu=mu, lambda_n=float(run.couple("tip_plane")["lambda_n"]),
                            closed_form=lam_cf, error=None))
        except PainleveError as e:
            rod.append(dict(mu=mu, lambda_n=None, closed_form=lam_cf,
                            error=str(e).splitlines()[0], time=e.time, couples=e.couples))
    _, mu_c = painleve_closed_form(0.0)
    log(f"  (c) Painleve rod: mu_c = {mu_c:.4f}; consistent up to "
        f"{max([r['mu'] for r in rod if r['error'] is None], default=None)}")
    docking = []
    if scenario is not None:
        from drake_dock.docking.model.simulate import simulate
        from drake_dock.docking.placement.place import place
        for mu in docking_mus:
            sc = copy.deepcopy(scenario)
            sc.contact.mu = sc.contact.mu_s = mu
            try:
                r = simulate(sc, state=place(sc))
                C = np.asarray(r.record.couples)
                st = C[:, :, COUPLE_SLICES["status"]]
                docking.append(dict(mu=mu, captured=r.captured, capture_time=r.capture_time,
                                    impacts=len(r.impacts), sticking_samples=int((st == Mode.STICKING).sum()),
                                    sliding_samples=int((st == Mode.SLIDING).sum()), error=None))
            except DrakeDockError as e:
                docking.append(dict(mu=mu, captured=False, error=str(e).splitlines()[0]))
            log(f"  (c) docking mu = {mu}: {docking[-1]}")
    return dict(theta_deg=math.degrees(PAINLEVE_THETA), mu_c=mu_c, rod=rod, docking=docking)


# --------------------------------------------------------------------------- (d) grazing
def grazing_case(deltas, *, v0=0.1, vx=0.5, e=0.5, log=print) -> dict:
    """Disk under gravity g away from the plane (incline angle pi), launched towards it at
    v0 with its lowest point h0 = delta + v0^2 / (2 g) above it: gap(t) = h0 - v0 t + g t^2/2,
    minimum delta at t = v0 / g."""
    T = 2 * v0 / G
    rows = []
    for delta in deltas:
        if not delta > -v0 * v0 / (2 * G):
            from drake_dock.errors import InputError
            raise InputError("grazing delta", delta,
                             f"> -v0^2 / (2 g) = {-v0 * v0 / (2 * G):.4g} m",
                             "the disk would start inside the plane")
        sc = disk_on_incline(math.pi, mu=0.3, restitution=e)
        r = sc.params["radius"]
        h0 = delta + v0 * v0 / (2 * G)
        run = SmallRun(sc.system, lambda c: sc.set_state(
            c, (np.eye(3), np.array([0, 0, r + h0])), (np.zeros(3), np.array([vx, 0, -v0]))))
        run.sim.AdvanceTo(T)
        imp = run.impacts
        x = run.ctx.get_continuous_state_vector().CopyToVector()
        t_cf = (v0 - math.sqrt(v0 * v0 - 2 * G * h0)) / G if delta < 0 else None
        va = math.sqrt(2 * G * -delta) if delta < 0 else 0.0
        opt = sc.system.options
        e_used = e if va >= opt.zeno_speed else 0.0
        vz_cf = (e_used * va + G * (T - t_cf)) if delta < 0 else (-v0 + G * T)
        gaps = np.array([s[1] for s in run.samples])
        rows.append(dict(delta=delta, impacts=len(imp),
                         impact_time=imp[0]["t"] if imp else None, closed_form_time=t_cf,
                         approach_speed=va, vz_end=float(x[12]), vz_closed_form=vz_cf,
                         min_gap=float(gaps.min()), t=[s[0] for s in run.samples],
                         gap=gaps.tolist()))
        log(f"  (d) delta {delta:+.0e}: impacts {len(imp)}, min gap {gaps.min():+.2e}, "
            f"vz end {x[12]:.9f} (closed form {vz_cf:.9f})")
    return dict(v0=v0, restitution=e, rows=rows)


# ------------------------------------------------------------------------------ (e) Zeno
def zeno_case(zeno_speeds, *, h=0.05, e=0.5, max_impacts_off=10, log=print) -> dict:
    v1 = math.sqrt(2 * G * h)
    t1 = math.sqrt(2 * h / G)
    rows = []
    for zs in zeno_speeds:
        sc = disk_on_incline(0.0, mu=0.3, restitution=e, options=ContactOptions(zeno_speed=zs))
        r = sc.params["radius"]
        run = SmallRun(sc.system, lambda c: sc.set_state(
            c, (np.eye(3), np.array([0, 0, r + h])), (np.zeros(3), np.zeros(3))))
        T = t1 + 2 * e * v1 / G / (1 - e) + 0.02
        n0 = sc.system.evaluations
        w0 = _time.perf_counter()
        run.sim.AdvanceTo(T)
        n_cf = math.floor(math.log(zs / v1) / math.log(e)) + 2
        t_last = t1 + sum(2 * v1 * e ** k / G for k in range(1, n_cf))
        imp = run.impacts
        c = run.couple("rim_plane")
        rows.append(dict(zeno_speed=zs, impacts=len(imp), closed_form_impacts=n_cf,
                         last_impact=imp[-1]["t"], closed_form_last_impact=t_last,
                         resting_lambda_n=float(c["lambda_n"]), weight=sc.params["mass"] * G,
                         evaluations=sc.system.evaluations - n0,
                         wall_time=_time.perf_counter() - w0,
                         t=[s[0] for s in run.samples], z=[s[2][6] - r for s in run.samples]))
        log(f"  (e) zeno_speed {zs:.0e}: impacts {len(imp)} (closed form {n_cf}), "
            f"{rows[-1]['evaluations']} evaluations")
    sc = disk_on_incline(0.0, mu=0.3, restitution=e,
                         options=ContactOptions(zeno_speed=0.0, max_impacts=max_impacts_off))
    r = sc.params["radius"]
    run = SmallRun(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r + h])), (np.zeros(3), np.zeros(3))))
    try:
        run.sim.AdvanceTo(t1 + 2 * e * v1 / G / (1 - e) + 0.02)
        off = dict(error=None)
    except ZenoError as err:
        off = dict(error=str(err).splitlines()[0], time=err.time, couples=list(err.couples))
    except NumericalError as err:   # reported, whatever the failure
        off = dict(error=str(err).splitlines()[0], time=err.time, couples=list(err.couples),
                   kind=type(err).__name__)
    log(f"  (e) guard off (zeno_speed 0, max_impacts {max_impacts_off}): {off}")
    return dict(h=h, restitution=e, v1=v1, rows=rows, guard_off=off,
                max_impacts_off=max_impacts_off)


# ------------------------------------------------------------------------------- plan, run
@dataclasses.dataclass
class StabilityPlan:
    output_steps: tuple
    compliant_steps: tuple
    stiffnesses: tuple
    ratios: tuple
    mus: tuple
    docking_mus: tuple
    deltas: tuple
    zeno_speeds: tuple

    @staticmethod
    def quick():
        return StabilityPlan((2e-3, 5e-3), (1e-3, 1e-4), (1e7,), (1e-2, 1.0, 1e2),
                             (0.5, 2.0, 3.0), (), (1e-5, 1e-7, -1e-7, -1e-5), (0.1,))

    @staticmethod
    def full():
        return StabilityPlan((1e-3, 2e-3, 5e-3, 1e-2), (1e-3, 3e-4, 1e-4, 3e-5),
                             (1e6, 1e7, 1e8), tuple(10.0 ** np.arange(-3, 3.5, 0.5)),
                             tuple(np.round(np.arange(0.1, 3.01, 0.1), 2)), (0.1, 0.3, 0.6, 1.0),
                             (1e-3, 1e-5, 1e-7, 1e-9, -1e-9, -1e-7, -1e-5, -4e-4),
                             (0.3, 0.1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4))


def run_stability(scenario, plan: StabilityPlan, log=print) -> dict:
    log("(a) step size")
    a = step_size_case(scenario, output_steps=plan.output_steps,
                       compliant_steps=plan.compliant_steps, stiffnesses=plan.stiffnesses,
                       log=log)
    log("(b) stiffness ratio")
    b = stiffness_ratio_case(plan.ratios, log=log)
    log("(c) high friction")
    c = high_friction_case(plan.mus, scenario=scenario, docking_mus=plan.docking_mus, log=log)
    log("(d) grazing")
    d = grazing_case(plan.deltas, log=log)
    log("(e) Zeno")
    e = zeno_case(plan.zeno_speeds, log=log)
    return dict(step_size=a, stiffness_ratio=b, high_friction=c, grazing=d, zeno=e)


def summary_lines(res) -> list:
    a, b, c, d, e = (res[k] for k in ("step_size", "stiffness_ratio", "high_friction",
                                      "grazing", "zeno"))
    lim = ", ".join(f"k={k}: {'none' if v is None else f'{v:.0e} s'}"
                    for k, v in a["largest_smooth_compliant_step"].items())
    worst = max(r["index"] for r in a["rigid"])
    lines = [f"(a) sawtooth above {a['threshold']:.0%}: drake_dock at most {worst:.1e} at output "
             f"steps up to {max(r['step'] for r in a['rigid']):.0e} s; compliant point contact "
             f"smooth up to step {lim}",
             f"(b) stiffness ratio {min(r['ratio'] for r in b['rows']):.0e}-"
             f"{max(r['ratio'] for r in b['rows']):.0e}: LZB within "
             f"{max(r['difference'] for r in b['rows']):.1e} of the compliant chain",
             f"(c) Painleve rod: mu_c = {c['mu_c']:.4f}; PainleveError for mu > mu_c "
             f"({sum(r['error'] is not None for r in c['rod'])} of {len(c['rod'])} values)"]
    lines += [f"(c) docking at mu = {r['mu']}: " + (f"captured at {r['capture_time']:.6f} s"
              if r.get("captured") else f"{r['error'] or 'no capture'}") for r in c["docking"]]
    lines += [f"(d) grazing: impacts detected for delta < 0 only: "
              f"{all((r['impacts'] > 0) == (r['delta'] < 0) for r in d['rows'])}",
              f"(e) Zeno guard: impact counts equal the closed form: "
              f"{all(r['impacts'] == r['closed_form_impacts'] for r in e['rows'])}; guard off: "
              f"{e['guard_off'].get('error')}"]
    return lines


def write_stability(res, out_dir):
    """stability.json, summary.txt and one figure per case, atomically."""
    from drake_dock.docking.report.out_dir import atomic_directory
    from drake_dock.studies.stability_figures import stability_figures
    with atomic_directory(out_dir, kind="study stability") as tmp:
        (tmp / "stability.json").write_text(json.dumps(res, indent=1, default=_json))
        (tmp / "summary.txt").write_text("\n".join(summary_lines(res)) + "\n")
        stability_figures(res, tmp)
    return Path(out_dir)


def _json(x):
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, tuple):
        return list(x)
    raise TypeError(type(x))
