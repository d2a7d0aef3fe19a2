"""What every run figure shares (matplotlib, Agg backend): a `Sheet` that draws each series in
its own colour and records it, leaves round-off out of the data (a note gives its magnitude
instead), puts legends beside the axes, and saves the PNG with a `FigureRecord`: for each axes
its pixel box in the PNG and the series drawn in it (label and colour), so that a reader of the
file can check that every listed series is on the image.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import to_rgb  # noqa: E402

DPI = 100
# Distinct saturated colours for the series of one axes (none near a grey: impacts are grey
# lines, text is black and anti-aliased into greys).
PALETTE = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:olive",
           "tab:cyan", "tab:pink")
IMPACT_GREY = "0.8"
# A curve whose largest magnitude is below ROUND_OFF times the scale of its panel lies under
# the zero line (an axis of a few hundred pixels resolves about 1e-3 of it): it is not drawn,
# its magnitude is written in a note.
ROUND_OFF = 1e-6


@dataclasses.dataclass
class Series:
    label: str
    color: tuple          # RGB in [0, 1]


@dataclasses.dataclass
class AxesRecord:
    box: tuple            # (left, top, right, bottom) pixel columns and rows in the PNG
    series: list
    notes: list
    legend_boxes: list    # pixel boxes of legends drawn inside this axes' box (none expected)
    limits: dict = dataclasses.field(default_factory=dict)   # {"x": (lo, hi, scale), "y": ...}


@dataclasses.dataclass
class FigureRecord:
    name: str
    axes: list


def negligible(y, scale) -> bool:
    """True when ``y`` is below `ROUND_OFF` of ``scale`` (exact zeros included)."""
    return float(np.max(np.abs(y), initial=0.0)) <= ROUND_OFF * float(scale)


def largest(curves: dict) -> float:
    """The largest magnitude among the curves (label -> values)."""
    return max((float(np.max(np.abs(y), initial=0.0)) for y in curves.values()), default=0.0)


def with_data(panels: list, scale=None) -> list:
    """The panels [(curves, ...)] that have a curve above round-off (`negligible`) relative to
    ``scale`` (default: each panel's own largest magnitude, so that only all-zero panels go);
    a figure draws these only, and names the others in a note."""
    return [p for p in panels
            if any(not negligible(y, largest(p[0]) if scale is None else scale)
                   for y in p[0].values()) and largest(p[0]) > 0]


def decades(lo: float, hi: float, scale: str) -> float:
    """How many decades an axis spans: log10(hi / lo) on a log axis; on a linear one, the
    decades between its largest value and its span (12 means a span of 1e-12 of the values
    shown: round-off drawn as data, matplotlib's offset notation)."""
    lo, hi = sorted((float(lo), float(hi)))
    if scale == "log":
        return float(np.log10(hi / lo))
    top = max(abs(lo), abs(hi))
    return float(np.log10(top / (hi - lo))) if top > 0 and hi > lo else 0.0

class Sheet:
    """One figure being drawn; ``series`` per axes in drawing order."""

    def __init__(self, *args, **kwargs):
        self.fig = plt.figure(*args, dpi=DPI, **kwargs)
        self.drawn = {}
        self.notes = {}
        self.titles = {}

    def add(self, ax, label, color, alpha=1.0):
        """Records a series; its colour as drawn on white (``alpha`` blended)."""
        rgb = alpha * np.array(to_rgb(color)) + (1.0 - alpha)
        self.drawn.setdefault(ax, []).append(Series(label, tuple(rgb.tolist())))

    def line(self, ax, t, y, label, color, **kw):
        ax.plot(t, y, color=color, label=label, **kw)
        self.add(ax, label, color, kw.get("alpha", 1.0))

    def note(self, ax, text, inside=False):
        """A line of text kept in the record: above the axes (left), off the data, or in the
        middle of an axes that shows no data (``inside``)."""
        self.notes.setdefault(ax, []).append(text)
        if inside:
            ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center",
                    fontsize=9)
        else:
            above = self.titles.setdefault(ax, [])
            above.append(text)
            ax.set_title("\n".join(above), loc="left", fontsize=8, color="0.15")

    def curves(self, ax, t, curves: dict, unit: str, scale=None, what="", **kw):
        """Draws the curves (label -> y) that are not zero to precision (`negligible`)
        relative to ``scale`` (default: the largest magnitude among them); the others are named
        in a note with their size."""
        if scale is None:
            scale = max((float(np.max(np.abs(y), initial=0.0)) for y in curves.values()),
                        default=0.0)
        small, drawn = [], 0
        for k, (label, y) in enumerate(curves.items()):
            if negligible(y, scale):
                small.append((label, float(np.max(np.abs(y), initial=0.0))))
            else:
                self.line(ax, t, y, label, PALETTE[k % len(PALETTE)], **kw)
                drawn += 1
        if small:
            names = ", ".join(s[0] for s in small)
            top = max(s[1] for s in small)
            self.note(ax, f"{what}{names}: zero throughout" if top == 0.0 else
                      f"{what}{names} not plotted, zero at this scale:\n"
                      f"|.| <= {top:.1e} {unit}, below {ROUND_OFF:g} of the scale "
                      f"{scale:.3g} {unit}", inside=not drawn)
            if not drawn:
                ax.set_xlim(t[0], t[-1])
                ax.set_yticks([])
        return [s[0] for s in small]

    def save(self, out_dir, name, legends=()) -> FigureRecord:
        """Saves ``name`` into ``out_dir``; ``legends``: (axes, legend) pairs drawn beside
        axes, whose boxes the record keeps when they overlap the axes (they should not)."""
        fig = self.fig
        fig.tight_layout()
        # Saved at the figure's own dpi: the boxes below are those of the file's drawing.
        fig.savefig(Path(out_dir) / name, dpi=DPI)
        height = fig.bbox.height
        records = []
        for ax in fig.axes:
            if not ax.get_visible() or ax.get_label() == "<colorbar>":
                continue
            box = _pixels(ax.get_window_extent(), height)
            overlaps = [_pixels(lg.get_window_extent(), height) for a, lg in legends
                        if a is ax and lg is not None
                        and _overlap(_pixels(lg.get_window_extent(), height), box)]
            limits = {"x": (*ax.get_xlim(), ax.get_xscale()),
                      "y": (*ax.get_ylim(), ax.get_yscale())}
            records.append(AxesRecord(box, self.drawn.get(ax, []), self.notes.get(ax, []),
                                      overlaps, limits))
        plt.close(fig)
        return FigureRecord(name, records)


def _pixels(bbox, height):
    return (int(bbox.x0), int(height - bbox.y1), int(np.ceil(bbox.x1)),
            int(np.ceil(height - bbox.y0)))


def _overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def legend_beside(ax, **kw):
    """A legend to the right of the axes, outside the data (None when nothing is labelled)."""
    if not ax.get_legend_handles_labels()[0]:
        return None
    return ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                     fontsize=kw.pop("fontsize", 8), **kw)


def impact_lines(ax, ts):
    for t in ts["impact_t"]:
        ax.axvline(t, color=IMPACT_GREY, lw=0.6, zorder=0)


def time_axes(axs, ts, xlabel=True) -> list:
    """Impact lines, the time label and a legend beside each axes; returns the (axes, legend)
    pairs for `Sheet.save`."""
    legends = []
    for ax in axs:
        impact_lines(ax, ts)
        if xlabel:
            ax.set_xlabel("t [s]")
        legends.append((ax, legend_beside(ax)))
    return legends
