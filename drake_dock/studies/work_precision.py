"""The readings of the speed-accuracy study's runs: the converged reading, the speed-ups, the
points' CSV and the work-precision chart.

A *family* is one method with fixed model and stiffness, ordered by step (SAP) or by accuracy
(continuous RK3, and drake_dock with one integration scheme at one step cap). A run is
*converged* on a metric when its error and the error of every finer run of its family are
within the tolerance (a run that does not capture is not). The converged speed-up of a metric
is the fastest converged compliant run's wall time over the fastest converged drake_dock run's. The speed-up over *any* run
within the tolerance is also given: a coarse run can land within it by chance.
"""
import csv
import dataclasses
import io
import math

from drake_dock.studies.docking_metrics import METRICS


@dataclasses.dataclass
class Point:
    method: str          # "drake_dock" | "compliant"
    role: str            # "reference" | "self-convergence" | "point"
    label: str
    model: str
    stiffness: float
    step: float          # compliant time step (0 = continuous), or drake_dock's step cap
    accuracy: float      # drake_dock or continuous compliant accuracy, or NaN
    wall_time: float
    captured: bool
    metrics: dict
    errors: dict
    note: str = ""
    scene: str = ""
    scheme: str = ""     # drake_dock's integration scheme (SimulatorConfig.integration_scheme)


@dataclasses.dataclass
class Reading:
    """A speed-up: the fastest drake_dock and compliant runs counted, and the ratio of their
    wall times (None when either side has none); ``best``, the smallest compliant error."""
    ratio: float | None
    drake_dock: Point | None
    compliant: Point | None
    best: float | None


def family(p: Point):
    """(family key, fineness): a larger fineness is a finer run of the family."""
    if p.method == "drake_dock":
        return ("drake_dock", p.scheme, p.step), -math.log10(p.accuracy)
    if p.step > 0:
        return ("compliant", p.model, p.stiffness, "SAP"), -math.log10(p.step)
    return ("compliant", p.model, p.stiffness, "RK3"), -math.log10(p.accuracy)


def within(p: Point, k: str, tol: float) -> bool:
    return p.errors[k] is not None and p.errors[k] <= tol


def converged_points(points, k, tol) -> list:
    """The points (reference and self-convergence excluded) converged on metric ``k``."""
    pts = [p for p in points if p.role == "point"]
    fam = {}
    for p in pts:
        key, fine = family(p)
        fam.setdefault(key, []).append((fine, p))
    out = []
    for p in pts:
        key, fine = family(p)
        if within(p, k, tol) and all(within(q, k, tol) for f, q in fam[key] if f > fine):
            out.append(p)
    return out


def _reading(counted, points, k) -> Reading:
    def fastest(method):
        return min((p for p in counted if p.method == method), key=lambda p: p.wall_time,
                   default=None)
    dd, cc = fastest("drake_dock"), fastest("compliant")
    best = min((p.errors[k] for p in points if p.method == "compliant"
                and p.errors[k] is not None), default=None)
    ratio = cc.wall_time / dd.wall_time if dd is not None and cc is not None else None
    return Reading(ratio, dd, cc, best)


def converged_speedups(points, tol) -> dict:
    """{metric: `Reading`} over the converged points."""
    return {k: _reading(converged_points(points, k, tol), points, k) for k in METRICS}


def any_run_speedups(points, tol) -> dict:
    """{metric: `Reading`} over every point within the tolerance."""
    return {k: _reading([p for p in points if p.role == "point" and within(p, k, tol)],
                        points, k) for k in METRICS}


CSV_FIELDS = ("scene", "method", "scheme", "role", "label", "model", "stiffness", "step",
              "accuracy", "wall_time", "captured", *METRICS,
              *(f"error_{k}" for k in METRICS), "note")


def points_csv(points) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_FIELDS)
    for p in points:
        w.writerow([p.scene, p.method, p.scheme, p.role, p.label, p.model, f"{p.stiffness:.6g}",
                    f"{p.step:.6g}", f"{p.accuracy:.6g}", f"{p.wall_time:.6f}", int(p.captured),
                    *("" if p.metrics[k] is None else repr(p.metrics[k]) for k in METRICS),
                    *("" if p.errors[k] is None else f"{p.errors[k]:.6e}" for k in METRICS),
                    p.note])
    return buf.getvalue()


SCHEME_NAMES = {"runge_kutta5": "RK5", "bogacki_shampine3": "BS3", "runge_kutta3": "RK3"}


def _group(p: Point) -> str:
    if p.method == "drake_dock":
        return f"drake_dock {SCHEME_NAMES.get(p.scheme, p.scheme)}, step <= {p.step:g} s"
    if p.step > 0:
        return f"SAP {p.model} k={p.stiffness:.0e}"
    return f"continuous RK3 {p.model} k={p.stiffness:.0e}"


def _style(key, groups, colour):
    if key.startswith("drake_dock"):
        # Per scheme (circles, diamonds): the finest step cap solid black, coarser caps dashed
        # in lighter greys.
        schemes = list(dict.fromkeys(g.split(",")[0] for g in groups
                                     if g.startswith("drake_dock")))
        scheme = key.split(",")[0]
        dd = sorted((g for g in groups if g.split(",")[0] == scheme),
                    key=lambda g: float(g.split("<= ")[1].split()[0]))
        rank = dd.index(key)
        return dict(lw=2.2, marker="oDs"[min(schemes.index(scheme), 2)],
                    color=("k", "0.4", "0.65", "0.8")[min(rank, 3)], ls="--" if rank else "-")
    return dict(lw=1, marker="s" if "SAP" in key else "^", ms=4, color=colour[key])


def work_precision_figure(scene: dict, tol: float, path):
    """Error (relative to the contact effect) against wall time, one panel per metric."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pts = scene["points"]
    fig, axs = plt.subplots(2, 3, figsize=(15, 8.5))
    floor = 1e-16
    fams = list(dict.fromkeys(_group(p) for p in pts if p.method == "compliant"))
    colour = {g: plt.cm.tab10(i % 10) for i, g in enumerate(fams)}
    for ax, k in zip(axs.ravel(), METRICS):
        conv = {id(p) for p in converged_points(pts, k, tol)}
        groups = {}
        for p in pts:
            if p.role == "reference" or p.errors[k] is None:
                continue
            groups.setdefault(_group(p), []).append(
                (p.wall_time, max(p.errors[k], floor), p.role != "point" or id(p) in conv))
        for key, xyc in groups.items():
            xyc.sort()
            x, y, c = zip(*xyc)
            style = _style(key, groups, colour)
            line, = ax.loglog(x, y, label=key, **style)
            # Runs within the tolerance by chance (a finer run of the family is not): hollow.
            lucky = [(xi, yi) for xi, yi, ci in zip(x, y, c) if yi <= tol and not ci]
            if lucky:
                ax.loglog(*zip(*lucky), ls="none", marker=style["marker"], ms=9, mfc="w",
                          mec=line.get_color(), mew=1.5)
        ax.axhline(tol, color="r", ls="--", lw=0.8)
        ax.set_title(k.replace("_", " "))
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("error / contact effect")
    axs[0, 0].legend(fontsize=7)
    fig.suptitle(f"{scene['scene']}: error relative to the contact's effect against wall time "
                 f"(red: tolerance {tol:g}; hollow: within it by chance)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
