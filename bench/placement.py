"""What the placement (`initial_state`: the first contact of the scenario's contact set on a
straight approach, the consistent aim with a lateral velocity, and the independent check of the
path down to it) costs: the paper example, and the first ``--conditions`` conditions of
`drake-dock study conditions` (seed 2026, inside the IDSS box; 75 for all but the first), with
the contact set ``--pairs`` (`complete`, or `paper` as the IDSS campaign plan). Per placement
it prints the wall time, the first-contact searches it ran (its memo's hits not counted; those
of a bracket among some pairs, and those stopped at a height, `_among_height`, also apart) and
their time, and the path check's time; then one search alone on each final approach (the
searches' memo cleared), and, for a placement whose bracket is closed among some pairs, the
same placement with the bracket closed with the whole set; then the medians. A first placement
loads the compiled kernels and is not counted.

    python bench/placement.py [--conditions 12] [--pairs complete|paper]
"""
import argparse
import time
from unittest import mock

import numpy as np

from drake_dock.docking import path_check, scene, search
from drake_dock.docking.scenario import PAPER_EXAMPLE, load_scenario
from drake_dock.studies.conditions import ConditionsPlan, conditions, with_condition


class _Timed:
    """Wraps f: its calls and their wall time; for the memoised search, the searches it ran
    with the whole set, among some pairs (its sixth argument) and stopped at a travel (its
    seventh), its memo's hits not counted."""

    def __init__(self, f):
        self.f, self.calls, self.wall = f, 0, 0.0
        self.whole = self.among = self.stopped = 0

    def __call__(self, *args, **kwargs):
        misses = self.f.cache_info().misses if hasattr(self.f, "cache_info") else None
        t0 = time.perf_counter()
        try:
            return self.f(*args, **kwargs)
        finally:
            self.calls += 1
            self.wall += time.perf_counter() - t0
            if misses is not None and self.f.cache_info().misses > misses:
                if len(args) > 5 and args[5] is not None:
                    self.among += 1
                elif len(args) > 6 and args[6] is not None:
                    self.stopped += 1
                else:
                    self.whole += 1


def _whole_set_bracket(s):
    """The placement's wall time and searches with the bracket closed with the whole set
    (`_bracketed_height` for `_among_height`), the searches' and the path check's memos
    cleared."""
    search._first_contact.cache_clear()
    path_check._checked.cache_clear()
    timed = _Timed(search._first_contact)
    with mock.patch.object(search, "_first_contact", timed), \
            mock.patch.object(scene, "_among_height", scene._bracketed_height):
        t0 = time.perf_counter()
        scene.initial_state(s)
        wall = time.perf_counter() - t0
    return wall, timed.whole + timed.among + timed.stopped


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--conditions", type=int, default=12)
    ap.add_argument("--pairs", choices=("complete", "paper"), default="complete")
    args = ap.parse_args(argv)
    base = load_scenario(PAPER_EXAMPLE)
    base.contact.pairs = args.pairs
    plan = conditions(ConditionsPlan())
    scene.initial_state(with_condition(base, plan[0][1]))            # kernels loaded
    cases = [("paper example", base)] + [(n, with_condition(base, c))
                                         for n, c in plan[1:1 + args.conditions]]
    totals, checks, alone, counts = [], [], [], []
    for name, s in cases:
        cached = search._first_contact
        cached.cache_clear()
        timed, check = _Timed(cached), _Timed(path_check._crossing)
        with mock.patch.object(search, "_first_contact", timed), \
                mock.patch.object(path_check, "_crossing", check):
            t0 = time.perf_counter()
            scene.initial_state(s)
            total = time.perf_counter() - t0
        searches = timed.whole + timed.among + timed.stopped
        approach = scene.contact_approach(s)[0]
        search._first_contact.cache_clear()
        t0 = time.perf_counter()
        scene.first_contact_or_faces(s.geometry, approach, s.contact.pairs)
        one = time.perf_counter() - t0
        totals.append(total)
        counts.append(searches)
        checks.append(check.wall)
        alone.append(one)
        print(f"{name}: placement {1e3 * total:.0f} ms; {searches} searches ({timed.among} "
              f"among some pairs, {timed.stopped} stopped) {1e3 * timed.wall:.0f} ms; path "
              f"check {1e3 * check.wall:.0f} ms; one search alone {1e3 * one:.0f} ms",
              flush=True)
        if timed.among:
            whole, searches_whole = _whole_set_bracket(s)
            print(f"    with the whole set in the bracket: {1e3 * whole:.0f} ms, "
                  f"{searches_whole} searches ({whole / total:.2f} times the placement)")
    print(f"median over {len(cases)}: placement {1e3 * np.median(totals):.0f} ms (fastest "
          f"{1e3 * min(totals):.0f}, slowest {1e3 * max(totals):.0f}); path check "
          f"{1e3 * np.median(checks):.0f} ms; one search {1e3 * np.median(alone):.0f} ms")
    print(f"{counts.count(2)} of {len(cases)} placed in two searches; "
          f"{sum(t < 0.1 for t in totals)} under 0.1 s")


if __name__ == "__main__":
    main()
