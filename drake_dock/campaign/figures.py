"""The campaign's figures: capture probability over two inputs, histograms of the peak loads and
of the capture time."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drake_dock.campaign.progress import ORDER  # noqa: E402

BINS = 8
_MARKERS = {"captured": ("o", "tab:green"), "missed": ("v", "tab:brown"),
            "rebound": ("^", "tab:orange"), "jammed": ("s", "tab:purple"),
            "timeout": ("D", "tab:gray"), "error": ("x", "k")}


def axis_values(columns: dict, path: str) -> np.ndarray:
    """A varied input per row: its value, or the magnitude of its components (a vector)."""
    if path in columns:
        return np.asarray(columns[path], float)
    comps = [np.asarray(columns[c], float) for c in sorted(columns) if c.startswith(path + "[")]
    return np.sqrt(np.sum(np.square(comps), axis=0))


def _label(path, columns):
    return f"|{path}|" if path not in columns else path


def capture_probability_figure(columns: dict, axes: list[str], path):
    """Binned capture probability (samples with a named outcome; errors are marked, not
    counted) over the two inputs, with every sample drawn by its outcome."""
    x, y = (axis_values(columns, a) for a in axes)
    outcome = np.asarray(columns["outcome"])
    named = outcome != "error"
    fig, ax = plt.subplots(figsize=(7.0, 5.6))
    if named.any():
        xe = np.linspace(x.min(), x.max(), BINS + 1) if x.max() > x.min() else \
            np.array([x.min() - 0.5, x.min() + 0.5])
        ye = np.linspace(y.min(), y.max(), BINS + 1) if y.max() > y.min() else \
            np.array([y.min() - 0.5, y.min() + 0.5])
        n, _, _ = np.histogram2d(x[named], y[named], [xe, ye])
        c, _, _ = np.histogram2d(x[named & (outcome == "captured")],
                                 y[named & (outcome == "captured")], [xe, ye])
        with np.errstate(invalid="ignore", divide="ignore"):
            p = np.where(n > 0, c / n, np.nan)
        mesh = ax.pcolormesh(xe, ye, p.T, cmap="RdYlGn", vmin=0.0, vmax=1.0, alpha=0.55)
        fig.colorbar(mesh, ax=ax, label="capture probability (per cell)")
    for name in ORDER:
        sel = outcome == name
        if sel.any():
            m, color = _MARKERS[name]
            ax.scatter(x[sel], y[sel], marker=m, s=14, color=color,
                       label=f"{name} ({int(sel.sum())})")
    ax.set_xlabel(_label(axes[0], columns))
    ax.set_ylabel(_label(axes[1], columns))
    ax.set_title(f"capture over {len(outcome)} samples")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _histogram(ax, values, label):
    v = np.asarray([np.nan if x is None else x for x in values], float)
    v = v[np.isfinite(v)]
    if v.size:
        ax.hist(v, bins=min(40, max(5, v.size // 5)), color="tab:blue")
    else:
        ax.text(0.5, 0.5, "no sample", ha="center", va="center", transform=ax.transAxes)
    ax.set_xlabel(label)
    ax.set_ylabel("samples")


def histograms_figure(columns: dict, path):
    """Peak contact force, peak Stewart force and stroke, capture time: one panel each."""
    fig, axs = plt.subplots(2, 2, figsize=(9.0, 6.4))
    _histogram(axs[0, 0], columns["peak_contact_force"], "peak contact force (N)")
    _histogram(axs[0, 1], columns["peak_stewart_force"], "peak Stewart force (N)")
    _histogram(axs[1, 0], [None if v is None else 1e3 * v for v in columns["peak_stewart_stroke"]],
               "peak Stewart stroke (mm)")
    captured = [t for t, o in zip(columns["capture_time"], columns["outcome"]) if o == "captured"]
    _histogram(axs[1, 1], captured, "capture time (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
