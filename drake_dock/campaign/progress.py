"""The campaign's progress bar on a stream (stderr): samples done, rate, outcome counts and time
left; redrawn in place on a terminal, otherwise a line at every tenth of the campaign."""
from __future__ import annotations

import collections
import sys
import time

from drake_dock.docking.model.outcome import OUTCOMES

ORDER = OUTCOMES + ("error",)


def duration_text(seconds: float) -> str:
    s = int(round(seconds))
    if s >= 3600:
        return f"{s // 3600}h{s % 3600 // 60:02d}m"
    return f"{s // 60}m{s % 60:02d}s" if s >= 60 else f"{s}s"


class CampaignProgress:
    """``start(total, saved)`` once, then ``update(rows)`` for each finished batch; ``close``
    at the end. The rate counts the samples run by this invocation only."""

    def __init__(self, stream=None, width=30):
        self.stream, self.width = stream or sys.stderr, width
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.counts = collections.Counter()
        self.total = self.saved = self.run = 0
        self.t0 = time.perf_counter()
        self.last = -1

    def start(self, total: int, saved: int):
        self.total, self.saved = total, saved
        self.t0 = time.perf_counter()
        if saved == total:
            self.note(f"all {total} samples already saved; writing the summary")
        elif saved:
            self.note(f"{saved} of {total} samples already saved; running the other "
                      f"{total - saved}")

    def update(self, rows):
        self.run += len(rows)
        self.counts.update(r["outcome"] for r in rows)
        done = self.saved + self.run
        frac = done / self.total if self.total else 1.0
        step = int(frac * (1000 if self.tty else 10))
        if step == self.last:
            return
        self.last = step
        elapsed = time.perf_counter() - self.t0
        rate = self.run / elapsed * 60.0 if elapsed > 0 else 0.0
        left = (self.total - done) / (rate / 60.0) if rate > 0 else float("nan")
        n = int(frac * self.width)
        counts = ", ".join(f"{k} {self.counts[k]}" for k in ORDER if self.counts[k])
        line = (f"[{'#' * n}{'.' * (self.width - n)}] {done}/{self.total} samples, "
                f"{rate:.1f}/min, {counts}"
                + (f"; {duration_text(left)} left" if left == left else ""))
        self._write(("\r" + line + "\033[K") if self.tty else line + "\n")

    def _write(self, text: str):
        self.stream.write(text)
        self.stream.flush()

    def note(self, text: str):
        """A line of its own (below the bar on a terminal)."""
        self.close()
        self._write(text + "\n")

    def close(self):
        """Ends the bar's line on a terminal."""
        if self.tty and self.last >= 0:
            self._write("\n")
        self.last = -1
