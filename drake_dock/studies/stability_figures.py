"""One figure per case of `drake_dock.studies.stability` (PNG, matplotlib Agg)."""
import math

import numpy as np

from drake_dock.studies.small_scenes import painleve_closed_form


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _labels(ax, xlabel, ylabel, title=None):
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=7)
    if title:
        ax.set_title(title)


def _save(plt, fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def step_size_figure(a, path):
    plt = _plt()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    k_show = sorted({c["stiffness"] for c in a["compliant"]})[len({c["stiffness"]
                                                                for c in a["compliant"]}) // 2]
    for c in a["compliant"]:
        if c["stiffness"] == k_show and c["t"]:
            ax.plot(c["t"], c["F"], lw=0.8, label=f"compliant SAP k={k_show:.0e} h={c['step']:.0e}")
    for r in a["rigid"]:
        ax.plot(r["t"], r["F"], "k.-", lw=1.5, ms=4 + 6 * (r is a["rigid"][-1]),
                label=f"drake_dock output step {r['step']:.0e}")
    ax.set_yscale("log")
    ax.set_ylim(bottom=1.0)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("|net contact force on the chaser| [N] (log)")
    ax.set_title("sliding phase [t_c/2, t_c]")
    ax.legend(fontsize=7)
    floor = 1e-12
    for k in sorted({c["stiffness"] for c in a["compliant"]}):
        pts = sorted((c["step"], c["index"]) for c in a["compliant"] if c["stiffness"] == k)
        x = [p[0] for p in pts]
        y = [max(p[1], floor) if math.isfinite(p[1]) else 10.0 for p in pts]
        bx.loglog(x, y, "s-", label=f"compliant SAP point k={k:.0e}")
    x = [r["step"] for r in a["rigid"]]
    bx.loglog(x, [max(r["index"], floor) for r in a["rigid"]], "ko-", lw=2,
              label="drake_dock (output step)")
    bx.axhline(a["threshold"], color="r", ls="--", lw=0.8, label="sawtooth threshold")
    _labels(bx, "time step / output step [s]", "sawtooth index")
    fig.suptitle("(a) step size: compliant sawtooth against drake_dock at the same output steps")
    _save(plt, fig, path)


def stiffness_ratio_figure(b, path):
    plt = _plt()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    r = np.array([row["ratio"] for row in b["rows"]])
    L = np.array([row["lzb"] for row in b["rows"]])
    C = np.array([row["compliant"] for row in b["rows"]])
    for j in range(L.shape[1]):
        ax.semilogx(r, L[:, j], "o-", label=f"ball {j + 1}: LZB")
        ax.semilogx(r, C[:, j], "k+", ms=10, label="compliant chain" if j == 0 else None)
    _labels(ax, "stiffness ratio K2 / K1", "post-impact velocity [m/s]",
            "three balls, elastic, eta = 1.5")
    bx.loglog(r, [row["lzb_wall"] for row in b["rows"]], "ko-", label="LZB")
    bx.loglog(r, [row["compliant_wall"] for row in b["rows"]], "s-", label="compliant chain")
    _labels(bx, "stiffness ratio K2 / K1", "wall time [s]")
    fig.suptitle("(b) unequal stiffness: LZB's stiffness-ratio effect")
    _save(plt, fig, path)


def high_friction_figure(c, path):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ok = [r for r in c["rod"] if r["error"] is None]
    bad = [r for r in c["rod"] if r["error"] is not None]
    mu = np.linspace(0, max(r["mu"] for r in c["rod"]), 400)
    lam = [painleve_closed_form(m)[0] for m in mu]
    ax.plot(mu, lam, "b-", lw=1, label="closed form (planar)")
    ax.plot([r["mu"] for r in ok], [r["lambda_n"] for r in ok], "ko", label="drake_dock")
    top = np.nanmax(lam[: int(0.95 * np.sum(mu < c["mu_c"]))]) if ok else 10
    ax.plot([r["mu"] for r in bad], [top] * len(bad), "rx", ms=9,
            label="PainleveError (no consistent mode)")
    ax.axvline(c["mu_c"], color="r", ls="--", lw=0.8, label=f"mu_c = {c['mu_c']:.3f}")
    ax.set_ylim(0, 1.1 * top)
    ax.set_xlabel("mu")
    ax.set_ylabel("lambda_n [N]")
    ax.legend(fontsize=7)
    ax.set_title(f"(c) Painleve's rod sliding at {c['theta_deg']:.0f} deg")
    _save(plt, fig, path)


def grazing_figure(d, path):
    plt = _plt()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    for r in d["rows"]:
        ax.plot(r["t"], r["gap"], ".-", ms=3, label=f"delta = {r['delta']:+.0e} m")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_ylim(-2e-5, 4e-5)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("gap at the step ends [m]")
    ax.legend(fontsize=7)
    ax.set_title("gap near the graze")
    neg = [r for r in d["rows"] if r["delta"] < 0 and r["impact_time"] is not None]
    bx.loglog([-r["delta"] for r in neg],
              [max(abs(r["impact_time"] - r["closed_form_time"]), 1e-16) for r in neg], "ko-",
              label="|impact time - closed form| [s]")
    bx.loglog([-r["delta"] for r in neg],
              [max(abs(r["vz_end"] - r["vz_closed_form"]), 1e-16) for r in neg], "s-",
              label="|final v_z - closed form| [m/s]")
    bx.set_xlabel("penetration depth of the free trajectory, -delta [m]")
    bx.legend(fontsize=7)
    bx.set_title("impacts found (delta < 0)")
    fig.suptitle("(d) grazing first contact")
    _save(plt, fig, path)


def zeno_figure(e, path):
    plt = _plt()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    r = min(e["rows"], key=lambda r: r["zeno_speed"])
    ax.plot(r["t"], r["z"], "k.-", ms=3)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("height of the lowest point [m]")
    ax.set_title(f"e = {e['restitution']}, zeno_speed = {r['zeno_speed']:g} m/s")
    zs = [r["zeno_speed"] for r in e["rows"]]
    bx.semilogx(zs, [r["impacts"] for r in e["rows"]], "ko", label="drake_dock")
    bx.semilogx(zs, [r["closed_form_impacts"] for r in e["rows"]], "r+", ms=12,
                label="closed form")
    bx2 = bx.twinx()
    bx2.semilogx(zs, [r["evaluations"] for r in e["rows"]], "s--", color="gray")
    bx2.set_ylabel("derivative evaluations", color="gray")
    bx.set_xlabel("zeno_speed [m/s]")
    bx.set_ylabel("number of impacts")
    bx.legend(fontsize=7)
    fig.suptitle("(e) decaying bounce sequence and the Zeno guard")
    _save(plt, fig, path)


def stability_figures(res, out_dir):
    step_size_figure(res["step_size"], out_dir / "stability_a_step_size.png")
    stiffness_ratio_figure(res["stiffness_ratio"], out_dir / "stability_b_stiffness_ratio.png")
    high_friction_figure(res["high_friction"], out_dir / "stability_c_high_friction.png")
    grazing_figure(res["grazing"], out_dir / "stability_d_grazing.png")
    zeno_figure(res["zeno"], out_dir / "stability_e_zeno.png")
