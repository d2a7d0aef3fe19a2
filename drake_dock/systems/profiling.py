"""Where a run's wall time goes: the contact system's parts, measured by a context manager."""
from __future__ import annotations

import contextlib
import dataclasses
from time import perf_counter

import numpy as np

PARTS = ("seeking", "contact_dynamics", "impacts")


@dataclasses.dataclass
class Timing:
    """Cumulative wall time (s) of the contact system's parts (reset with `reset`): seeking
    (Sect. 5.1, the hierarchical grid and Newton, per pair with the number of seeks, and the
    broad phase's cover gaps), contact
    dynamics (every derivative evaluation: couple tracking, Eq. 47, the constraint forces) and
    impacts (LZB and the mode selection at events). Only the declared pairs are ever searched."""

    pairs: list
    seeking: float = 0.0
    contact_dynamics: float = 0.0
    impacts: float = 0.0
    seeks: dict = dataclasses.field(default_factory=dict)
    screens: dict = dataclasses.field(default_factory=dict)   # far pairs the broad phase kept
    seek_time: dict = dataclasses.field(default_factory=dict)  # s per pair: seeks, screens
    tracked: dict = dataclasses.field(default_factory=dict)    # evaluations with the pair tracked

    _tracked: object = None
    _epochs: list = dataclasses.field(default_factory=list)   # [near pairs, evaluations]
    _last_index: object = None

    def reset(self):
        self.seeking = self.contact_dynamics = self.impacts = 0.0
        self.seeks, self.screens, self.seek_time, self.tracked = {}, {}, {}, {}
        self._tracked = None
        self._epochs = []
        self._last_index = None

    def tracked_counts(self) -> dict:
        """Per pair, the evaluations in which it was tracked."""
        counts = {n: self.tracked.get(n, 0) for n in self.pairs}
        for near, n in self._epochs:
            for i in near:
                counts[self.pairs[i]] += n
        if self._tracked is not None:
            for n, c in zip(self.pairs, self._tracked.tolist()):
                counts[n] += c
        return counts

    @contextlib.contextmanager
    def measure(self, part: str, pair: str | None = None):
        """Adds the wall time of the ``with`` block to ``part`` (one of `PARTS`), and to the
        pair's seeking time when ``pair`` names one."""
        t0 = perf_counter()
        try:
            yield
        finally:
            dt = perf_counter() - t0
            setattr(self, part, getattr(self, part) + dt)
            if pair is not None:
                self.seek_time[pair] = self.seek_time.get(pair, 0.0) + dt

    def count_tracked(self, names):
        """One evaluation with the pairs ``names`` tracked (their couples evaluated, Eq. 47)."""
        for n in names:
            self.tracked[n] = self.tracked.get(n, 0) + 1

    def count_tracked_epoch(self, index):
        """One evaluation with the pairs not far of the `ModesIndex` ``index`` tracked
        (counted per index; summed over the pairs when asked, `tracked_counts`). Only the
        last index is kept, and of the others their near pairs: an index holds what the
        engine derived of it."""
        if self._epochs and self._last_index is index:
            self._epochs[-1][1] += 1
        else:
            self._last_index = index
            self._epochs.append([tuple(int(i) for i in index.near), 1])

    def count_tracked_indices(self, index):
        """One evaluation with the pairs at the positions ``index`` (an array into ``pairs``)
        tracked."""
        if self._tracked is None or len(self._tracked) != len(self.pairs):
            self._tracked = np.zeros(len(self.pairs), dtype=np.int64)
        self._tracked[index] += 1

    def count_seek(self, pair: str):
        self.seeks[pair] = self.seeks.get(pair, 0) + 1

    def count_screen(self, pair: str):
        self.screens[pair] = self.screens.get(pair, 0) + 1

    def shares(self, wall_time: float) -> dict:
        """The three parts and the rest (Drake's integrator, witnesses, logging) as fractions of
        ``wall_time``, with the pairs declared, the seeks per pair, the broad phase's
        screenings per pair (far pairs not sought: their covers were apart), the wall time of
        each pair's seeks and screenings, and the evaluations in which it was tracked."""
        out = {k: getattr(self, k) / wall_time for k in PARTS}
        out["other"] = max(0.0, 1.0 - sum(out.values()))
        return {"wall_time": wall_time, "shares": out, "pairs_declared": len(self.pairs),
                "seeks_per_pair": {n: self.seeks.get(n, 0) for n in self.pairs},
                "screens_per_pair": {n: self.screens.get(n, 0) for n in self.pairs},
                "seek_time_per_pair": {n: self.seek_time.get(n, 0.0) for n in self.pairs},
                "tracked_evaluations_per_pair": self.tracked_counts()}
